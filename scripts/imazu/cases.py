"""Encounter sets: the 22 Imazu (1987) encounters at the project's scale (imazu22_cases.json,
beside this file), and DNV ship-traffic-generator's 55 baseline situations (trafficgen_baseline/).

Each case: the own ship at (0, 0) NED on course 000 at 12 kn and one to three targets holding
course and speed; left alone, every ship reaches the point 4 NM ahead after 20 min. The file is
the chosen variant of each case from the project's reference set (its source string says which;
geometry after Sawada et al. 2021, scaled 2/3).

A DNV situation is read as trafficgen wrote it (imazu.trafficgen_situations): the own ship at
(0, 0) at 10 kn, targets on their straight legs at their own speeds, each target with its
length from the file (the evaluator's hull and domain for it).
"""
from pathlib import Path

from ship_sim.safe_load import load_json_file

FILE = Path(__file__).with_name('imazu22_cases.json')
DNV_DIR = Path(__file__).with_name('trafficgen_baseline')
#: The single-target cases (head-on, crossing give-way, overtaking, crossing stand-on).
SINGLE = (1, 2, 3, 4)
#: Encounter sets by name: what ``load_set`` reads.
SETS = ('imazu', 'dnv')


def load_cases():
    """{case number: {'own': {...}, 'targets': [{name, north_m, east_m, course_deg, speed_mps,
    colregs}, ...]}} with target names in lower case (ts1, ts2, ...: scenario namespaces)."""
    data = load_json_file(FILE)
    out = {}
    for c in data['cases']:
        targets = [{**t, 'name': t['name'].lower()} for t in c['targets']]
        out[int(c['case'])] = {'own': c['own'], 'targets': targets}
    return out


def load_dnv_cases():
    """{situation number: case} of the 55 DNV baseline situations, as ``load_cases`` gives the
    Imazu cases (targets ts1, ts2, ... in the file's order, each with its ``length_m``)."""
    from imazu.trafficgen_situations import read_situation
    out = {}
    for path in sorted(DNV_DIR.glob('traffic_situation_*.json')):
        _, case = read_situation(path)
        out[int(path.stem.rsplit('_', 1)[1])] = case
    return out


def load_set(name):
    """The cases of encounter set ``name`` (``SETS``)."""
    if name not in SETS:
        raise ValueError(f'encounter set {name!r}; allowed: {", ".join(SETS)}')
    return load_cases() if name == 'imazu' else load_dnv_cases()


def single_target(cases):
    """Numbers of the cases with one target (Imazu: ``SINGLE``)."""
    return tuple(n for n, c in sorted(cases.items()) if len(c['targets']) == 1)


def turn_back_case():
    """The turn-back encounter (the tanker near-miss mechanism: give way to one ship, then turn
    back towards the route while another is still closing): ts2 crosses from starboard close
    ahead (closest point about 11 min in), so the own ship gives way early and far to
    starboard; ts1 crosses from port towards the route point 4 NM ahead, so it is still closing
    when the own ship, its give-way done, turns back to port towards its route and towards ts1.
    This is Imazu case 11's geometry (taken from the case file, not copied): built variants
    with ts1 crossing the route later, or with case 2's starboard crosser as the first ship,
    left the MSS tanker outside both ships' domains."""
    return load_cases()[11]
