"""Trace SB-MPC's decisions in one Imazu or DNV run (in process, scripts/imazu/runner.py): why
it chose what it chose.

    .venv/bin/python scripts/trace_sbmpc.py --set dnv --case 16 --ship mariner
        --at 467,600,860 [--top 8]
    .venv/bin/python scripts/trace_sbmpc.py --case 4 --every 60

At each traced decision (``--at`` times, or every n-th decision that scored scenarios) it
prints the mode and the situations, then the ``--top`` cheapest scenarios: course offset from
the anchor, speed multiplier, total cost and its parts (SBMPC.cost_terms: risk, port-turn and
not-apparent penalties, deviation; grounding only with land), and the predicted minimum
distance to each target (over the horizon, or the straight-line closest approach after it
when that is closer). ``<`` marks the scenario the decision took; a decision of the stand-on
hold is marked ``held``, as it does not take the cheapest. Then each target's actual closest
approach in the run.
"""
import argparse
import copy
import tempfile

import numpy as np

from imazu.cases import SETS, load_set
from imazu.runner import LIMIT_S, RunEnd, SHIPS, case_scenario, run_scenario, write_scenario

from ship_guidance import colregs
from ship_guidance.sbmpc import SBMPC

TERMS = ('risk', 'port_turn', 'not_apparent', 'deviation')


def _times(text):
    return sorted(float(v) for v in text.split(',') if v.strip())


def trace(set_name, case, ship, at=(), every=0, top=8, limit_s=LIMIT_S, out=print):
    """The RunResult of the case with SB-MPC; prints the traced decisions (module docstring).
    ``at``: decision times (s) to trace; ``every``: also every n-th decision that scored
    scenarios (0: none)."""
    at = set(at)
    scored = []
    original = SBMPC.decide

    def recording(self, t, own, targets, nominal_course, nominal_speed_factor):
        before = copy.copy(self)              # the state the decision starts from
        before._latched = dict(self._latched)
        decision = original(self, t, own, targets, nominal_course, nominal_speed_factor)
        if decision.mode != 'nominal':
            scored.append(t)
            if t in at or (every and (len(scored) - 1) % every == 0):
                # the scenarios and costs as this decision saw them
                base = nominal_course if before.anchor is None else before.anchor
                sc = before.scenarios(own, tuple(targets), base, nominal_speed_factor,
                                      nominal_course)
                _print(out, t, decision, sc, before.cost_terms(sc), top)
        return decision

    cases = load_set(set_name)
    scenario, route = case_scenario(case, cases[case], ship, 'sbmpc', limit_s)
    SBMPC.decide = recording
    try:
        with tempfile.TemporaryDirectory() as tmp:
            result = run_scenario(write_scenario(scenario, route, tmp),
                                  end=RunEnd.of_case(cases[case]))
    finally:
        SBMPC.decide = original
    for name in sorted(result.targets):
        d = np.hypot(*(result.targets[name][:, :2] - result.own[:, :2]).T)
        i = int(d.argmin())
        out(f'{name}: closest {d[i]:.0f} m at t = {result.t[i]:.0f} s')
    return result


def _print(out, t, decision, sc, terms, top):
    cost = sum(np.broadcast_to(terms[k], sc.offsets.shape) for k in
               ('risk', 'grounding', 'port_turn', 'not_apparent', 'deviation'))
    d_min = np.minimum(sc.dist.min(axis=2), sc.dcpa_beyond)
    sit = ' '.join(f'{colregs.SITUATIONS[c]}' + ('' if th else '(no threat)')
                   for c, th in zip(sc.codes, sc.threat))
    held = decision.mode == 'stand-on'
    out(f't={t:.0f} {decision.mode} offset {np.rad2deg(decision.scenario_offset):+.0f} '
        f'x{decision.speed_multiplier:g} [{sit}]' + (' held' if held else ''))
    out('   offset  mult        cost ' + ' '.join(f'{k:>12s}' for k in TERMS)
        + '  predicted min distance per target (m)')
    for k in np.argsort(cost, kind='stable')[:top]:
        mark = '<' if (np.isclose(sc.offsets[k], decision.scenario_offset)
                       and sc.multipliers[k] == decision.speed_multiplier) else ' '
        parts = ' '.join(f'{float(np.broadcast_to(terms[n], cost.shape)[k]):12.3f}'
                         for n in TERMS)
        out(f' {mark} {np.rad2deg(sc.offsets[k]):+5.0f} {sc.multipliers[k]:5.2f} '
            f'{cost[k]:11.3f} {parts}  ' + ' '.join(f'{d:.0f}' for d in d_min[k]))


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split('\n')[0])
    ap.add_argument('--set', choices=SETS, default='imazu', help='encounter set (default imazu)')
    ap.add_argument('--case', type=int, required=True)
    ap.add_argument('--ship', choices=SHIPS, default='mariner')
    ap.add_argument('--at', type=_times, default=[], help='decision times (s), comma-separated')
    ap.add_argument('--every', type=int, default=0,
                    help='also every n-th decision that scored scenarios (default 0: none)')
    ap.add_argument('--top', type=int, default=8, help='scenarios per decision (default 8)')
    a = ap.parse_args(argv)
    if a.case not in load_set(a.set):
        ap.error(f'no {a.set} case {a.case}')
    if not a.at and not a.every:
        ap.error('give --at times or --every n')
    trace(a.set, a.case, a.ship, a.at, a.every, a.top)
    return 0

