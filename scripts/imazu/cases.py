"""The 22 Imazu (1987) encounters at the project's scale (imazu22_cases.json, beside this file).

Each case: the own ship at (0, 0) NED on course 000 at 12 kn and one to three targets holding
course and speed; left alone, every ship reaches the point 4 NM ahead after 20 min. The file is
the chosen variant of each case from the project's reference set (its source string says which;
geometry after Sawada et al. 2021, scaled 2/3).
"""
from pathlib import Path

from ship_sim.safe_load import load_json_file

FILE = Path(__file__).with_name('imazu22_cases.json')
#: The single-target cases (head-on, crossing give-way, overtaking, crossing stand-on).
SINGLE = (1, 2, 3, 4)


def load_cases():
    """{case number: {'own': {...}, 'targets': [{name, north_m, east_m, course_deg, speed_mps,
    colregs}, ...]}} with target names in lower case (ts1, ts2, ...: scenario namespaces)."""
    data = load_json_file(FILE)
    out = {}
    for c in data['cases']:
        targets = [{**t, 'name': t['name'].lower()} for t in c['targets']]
        out[int(c['case'])] = {'own': c['own'], 'targets': targets}
    return out



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
