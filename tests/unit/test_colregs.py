"""CPA/TCPA against closed forms and the Imazu reference encounters; the COLREGs situation at
and around every sector boundary (ship_guidance.cpa, ship_guidance.colregs)."""
import json
import math
from pathlib import Path

import numpy as np
import pytest

from ship_guidance import colregs
from ship_guidance.cpa import cpa, range_and_bearing, velocity

DATA = Path(__file__).resolve().parents[1] / 'data' / 'imazu22_encounters.json'
U = 6.0   # m/s


def test_head_on_closed_form():
    # two ships on one line, closing at 2U from 4000 m: they meet after 4000 / (2U), dead on
    tcpa, dcpa = cpa([0.0, 0.0], velocity(0.0, U), [4000.0, 0.0], velocity(math.pi, U))
    assert tcpa == pytest.approx(4000.0 / (2 * U), rel=1e-15)
    assert dcpa == pytest.approx(0.0, abs=1e-9)


def test_offset_crossing_closed_form():
    # target 3000 m east moving west at U, own ship north at U: relative velocity (-U, -U),
    # relative position (0, 3000); the perpendicular from the origin to that line gives both
    tcpa, dcpa = cpa([0.0, 0.0], velocity(0.0, U), [0.0, 3000.0], velocity(-math.pi / 2, U))
    assert tcpa == pytest.approx(3000.0 / (2 * U), rel=1e-14)
    assert dcpa == pytest.approx(3000.0 / math.sqrt(2.0), rel=1e-14)


def test_opening_ships_have_negative_tcpa_and_still_ones_keep_their_range():
    tcpa, dcpa = cpa([0.0, 0.0], velocity(math.pi, U), [1000.0, 0.0], velocity(0.0, U))
    assert tcpa < 0.0 and dcpa == pytest.approx(0.0, abs=1e-9)   # closest was in the past
    tcpa, dcpa = cpa([0.0, 0.0], velocity(0.3, U), [500.0, 1200.0], velocity(0.3, U))
    assert tcpa == 0.0 and dcpa == pytest.approx(1300.0)


def test_cpa_broadcasts_over_targets():
    p_t = np.array([[4000.0, 0.0], [0.0, 3000.0], [1000.0, 0.0]])
    v_t = velocity(np.array([math.pi, -math.pi / 2, 0.0]), U)
    tcpa, dcpa = cpa([0.0, 0.0], velocity(0.0, U), p_t, v_t)
    for i in range(3):
        assert (tcpa[i], dcpa[i]) == cpa([0.0, 0.0], velocity(0.0, U), p_t[i], v_t[i])


@pytest.fixture(scope='module')
def imazu():
    return json.loads(DATA.read_text())


def _states(enc):
    o, t = enc['own'], enc['target_state']
    p_o, p_t = np.array([o['north_m'], o['east_m']]), np.array([t['north_m'], t['east_m']])
    psi_o, psi_t = math.radians(o['course_deg']), math.radians(t['course_deg'])
    return p_o, psi_o, velocity(psi_o, o['speed_mps']), p_t, psi_t, velocity(psi_t, t['speed_mps'])


def test_imazu_encounters_cpa_bearings_and_situations(imazu):
    encounters = imazu['encounters']
    assert len(encounters) > 300      # every case and every source's variant of it
    seen = set()
    for enc in encounters:
        p_o, psi_o, v_o, p_t, psi_t, v_t = _states(enc)
        want = enc['expected']
        tcpa, dcpa = cpa(p_o, v_o, p_t, v_t)
        # the reference rounds its derived numbers (to 0.1 s, 0.1 m and 0.01 deg at most)
        assert tcpa == pytest.approx(want['tcpa_s'], abs=0.1), enc['case']
        assert dcpa == pytest.approx(want['dcpa_m'], abs=0.1), enc['case']
        beta = math.degrees(colregs.relative_bearing(p_o, psi_o, p_t))
        beta_t = math.degrees(colregs.relative_bearing(p_t, psi_t, p_o))
        for ours, ref in ((beta, want['relative_bearing_deg']),
                          (beta_t, want['bearing_of_own_from_target_deg'])):
            assert abs((ours - ref + 180.0) % 360.0 - 180.0) < 0.01, enc['case']
        code = colregs.classify(p_o, psi_o, v_o, p_t, psi_t, v_t)
        assert colregs.SITUATIONS[code] == want['colregs'], (enc['case'], enc['variant'])
        seen.add(want['colregs'])
    assert seen == {'overtaking', 'head-on', 'crossing-give-way', 'crossing-stand-on'}


def _target_at(beta_deg, target_bow_to_own_deg, rng=3000.0):
    """Own ship at the origin heading north; a target at relative bearing ``beta_deg``, heading
    so that the own ship bears ``target_bow_to_own_deg`` from its bow."""
    b = math.radians(beta_deg)
    p_t = rng * np.array([math.cos(b), math.sin(b)])
    bearing_to_own = math.atan2(-p_t[1], -p_t[0])
    return p_t, bearing_to_own - math.radians(target_bow_to_own_deg)


def _classify_at(beta_deg, target_bow_to_own_deg, own_speed=U, target_speed=U / 2):
    p_t, psi_t = _target_at(beta_deg, target_bow_to_own_deg)
    v_o, v_t = velocity(0.0, own_speed), velocity(psi_t, target_speed)
    assert cpa([0.0, 0.0], v_o, p_t, v_t)[0] > 0.0, 'the test geometry must be closing'
    return colregs.SITUATIONS[colregs.classify([0.0, 0.0], 0.0, v_o, p_t, psi_t, v_t)]


EPS = 1e-6   # deg: either side of a boundary (exactly on it, trigonometry decides the last bit)


@pytest.mark.parametrize('edge', [112.5, 247.5])
def test_stern_sector_boundaries(edge):
    inside, outside = (edge + EPS, edge - EPS) if edge < 180 else (edge - EPS, edge + EPS)
    side = 'crossing-give-way' if edge < 180 else 'crossing-stand-on'
    # the target abaft the own beam, bow on the own ship, faster: it overtakes the own ship
    assert _classify_at(inside, 0.0, own_speed=U / 2, target_speed=U) == 'being-overtaken'
    assert _classify_at(outside, 0.0, own_speed=U / 2, target_speed=U) == side
    # the own ship abaft the target's beam and faster: the own ship overtakes
    assert _classify_at(10.0, inside) == 'overtaking'
    assert _classify_at(10.0, outside) == 'crossing-give-way'


@pytest.mark.parametrize('beta', [0.0, 6.0 - EPS, 360.0 - 6.0 + EPS])
def test_head_on_sector_is_six_degrees_either_side(beta):
    for bow in (0.0, 6.0 - EPS, 360.0 - 6.0 + EPS):
        assert _classify_at(beta, bow) == 'head-on'
    # the own ship just outside 6 deg of the target's bow: crossing, on the side the target bears
    side = 'crossing-stand-on' if beta > 180.0 else 'crossing-give-way'
    assert _classify_at(beta, 6.0 + EPS) == side
    assert _classify_at(beta, 360.0 - 6.0 - EPS) == side
    # and the target just outside 6 deg of the own bow, with the own ship dead ahead of it
    assert _classify_at(6.0 + EPS, 0.0) == 'crossing-give-way'
    assert _classify_at(360.0 - 6.0 - EPS, 0.0) == 'crossing-stand-on'


def test_crossing_side_is_the_bearing_half_plane():
    # dead ahead and dead astern split starboard [0, 180) from port [180, 360)
    assert _classify_at(90.0, 45.0) == 'crossing-give-way'
    assert _classify_at(270.0, 315.0) == 'crossing-stand-on'
    for beta, side in ((112.5 - EPS, 'crossing-give-way'), (247.5 + EPS, 'crossing-stand-on')):
        assert _classify_at(beta, 45.0 if beta < 180 else 315.0, own_speed=U / 4, target_speed=U) == side


def test_opening_targets_have_no_situation():
    # ahead and moving away faster than the own ship (it would be "overtaking" were it closing)
    code = colregs.classify([0.0, 0.0], 0.0, velocity(0.0, U), [1000.0, 0.0], 0.0, velocity(0.0, 2 * U))
    assert colregs.SITUATIONS[code] == 'none'
    # abeam to starboard and steaming away from the own track
    p_t, psi_t = _target_at(90.0, 180.0)
    code = colregs.classify([0.0, 0.0], 0.0, velocity(0.0, U), p_t, psi_t, velocity(psi_t, U))
    assert cpa([0.0, 0.0], velocity(0.0, U), p_t, velocity(psi_t, U))[0] < 0.0
    assert colregs.SITUATIONS[code] == 'none'


def test_roles_and_vectorised_classification_agree():
    assert [colregs.role(c) for c in range(6)] == ['none', 'give-way', 'stand-on', 'give-way',
                                                   'give-way', 'stand-on']
    cases = [(0.0, 0.0), (45.0, 45.0), (315.0, 315.0), (10.0, 180.0)]
    targets = [_target_at(b, t) for b, t in cases]
    p_t = np.array([p for p, _ in targets])
    psi_t = np.array([psi for _, psi in targets])
    codes = colregs.classify([0.0, 0.0], 0.0, velocity(0.0, U), p_t, psi_t, velocity(psi_t, U / 2))
    assert [colregs.SITUATIONS[c] for c in codes] == [_classify_at(b, t) for b, t in cases]
    rng_, brg = range_and_bearing([0.0, 0.0], p_t)
    np.testing.assert_allclose(rng_, 3000.0)
    np.testing.assert_allclose(np.degrees(brg), [0.0, 45.0, 315.0, 10.0], atol=1e-9)
