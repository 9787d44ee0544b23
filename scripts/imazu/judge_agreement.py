"""Our evaluator's verdicts against the CommonOcean rule monitor's, per rule and per set (pure).

Pairs are (run, target). Our verdict on a rule is the target's: compliant when our evaluator
(ship_guidance.colav_evaluation) gives it no penalty; theirs is the verdict of the monitor's
rule for that target (scripts/commonocean_monitor.py). Each row of RULES pairs a COLREGs rule
as our evaluator reads it, for the targets of one situation (the case file's, the own ship's
view at t = 0), with the monitor's rule for the same duty:

    Rule 14 head-on                    R_G4 (head-on)
    Rules 15/16 crossing, give way     R_G3 (crossing)
    Rule 13 overtaking                 R_G5 (overtaking)
    Rule 17 stand-on, crossing         R_G6 (stand-on)
    Rule 17 stand-on, being overtaken  R_G6
    safe passing, every target         R_G1 (safe distance): ours compliant = no near miss
                                       (no centre inside a ship domain, no hull contact)

Each pair falls in one class (CLASSES): both compliant, both violating, ours only (we flag,
they pass) split by whether their situation predicate for the rule held at any sample (if not,
their rule was never triggered for this target: the encounter was not, in their reading, that
situation), or theirs only (they flag, we pass).
"""
#: (row id, title, our situation or None for every target, their rule, their situation
#: predicate or None)
RULES = (
    ('head_on', 'Rule 14 head-on', 'head-on', 'R_G4', 'head_on__x_ego_x_o'),
    ('crossing_give_way', 'Rules 15/16 crossing, give way', 'crossing-give-way', 'R_G3',
     'crossing__x_ego_x_o'),
    ('overtaking', 'Rule 13 overtaking', 'overtaking', 'R_G5', 'overtake__x_ego_x_o'),
    ('stand_on_crossing', 'Rule 17 stand-on, crossing', 'crossing-stand-on', 'R_G6',
     'keep__x_ego_x_o'),
    ('stand_on_overtaken', 'Rule 17 stand-on, being overtaken', 'being-overtaken', 'R_G6',
     'keep__x_ego_x_o'),
    ('safe_passing', 'safe passing (ours: no near miss; theirs: R_G1 safe distance)', None,
     'R_G1', 'collision_possible_soon__x_ego_x_o'),
)
CLASSES = ('both_compliant', 'both_violating', 'ours_only_not_triggered', 'ours_only_triggered',
           'theirs_only')


def our_verdict(row, target_eval):
    """True (compliant) / False of our evaluator on ``row`` for one target's evaluate_target
    dict; None if the row does not apply to the target."""
    rid, _, situation = row[:3]
    if situation is None:
        return not target_eval['near_miss']
    if target_eval['situation'] != situation:
        return None
    return not target_eval['penalties']


def pair_class(ours, theirs, triggered):
    if ours == theirs:
        return 'both_compliant' if ours else 'both_violating'
    if not ours:
        return 'ours_only_triggered' if triggered else 'ours_only_not_triggered'
    return 'theirs_only'


def pairs(run_key, our_run, their_run, reading):
    """One dict per (row, target) that applies: run key, target, row id, both verdicts, the
    class, our penalties and how many samples their situation predicate held."""
    out = []
    verdicts = their_run['verdicts'][reading]
    for name, tev in our_run['targets'].items():
        preds = their_run['predicates'].get(name, {})
        for row in RULES:
            ours = our_verdict(row, tev)
            if ours is None:
                continue
            rid, _, _, rule, pred = row
            theirs = bool(verdicts[rule][name])
            held = len(preds.get(pred, []))
            out.append({'run': run_key, 'target': name, 'row': rid, 'ours': ours,
                        'theirs': theirs, 'class': pair_class(ours, theirs, held > 0),
                        'situation': tev['situation'], 'penalties': sorted(tev['penalties']),
                        'near_miss': bool(tev['near_miss']), 'their_situation_samples': held,
                        'their_other_violations': sorted(
                            r for r, v in verdicts.items() if r != rule and name in v
                            and not v[name])})
    return out


def agreement_table(all_pairs):
    """{row id: {'n', 'agree', 'agreement', and a count per class}} over ``all_pairs``."""
    table = {}
    for row in RULES:
        rows = [p for p in all_pairs if p['row'] == row[0]]
        counts = {c: sum(p['class'] == c for p in rows) for c in CLASSES}
        agree = counts['both_compliant'] + counts['both_violating']
        table[row[0]] = {'n': len(rows), 'agree': agree,
                         'agreement': agree / len(rows) if rows else None, **counts}
    return table
