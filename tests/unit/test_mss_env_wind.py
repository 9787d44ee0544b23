"""Wind-coefficient and sea-state ports against the MSS environment functions run in Octave.

Reference: tests/data/mss_env/shared_*.json (cybergalactic/MSS commit 736a3d1,
LIBRARY/environment/, GNU Octave 7.3.0; provenance in tests/data/README.md). Every case of each
file is checked. Tolerance: relative 1e-12 plus an absolute floor scaled to the size of the
output (numpy.interp and Octave's interp1 differ by ~1e-17 in an interpolated coefficient, which
leaves e.g. ~1e-9 N m of yaw moment where MSS's own value is ~1e-9 instead of 0 at 180 deg).
"""
import json
import math
from pathlib import Path

import numpy as np
import pytest

from ship_sim.environment.sea_state_relations import encounter, hs2vw, vw2hs
from ship_sim.environment.wind_coefficients import (BLENDERMANN_TYPES, blendermann94,
                                                    isherwood72)

DATA = Path(__file__).resolve().parents[1] / 'data' / 'mss_env'
RTOL = 1e-12
# Absolute floor: 1e-15 of the load scale (q ALw Loa) of a case, or of 1 for coefficients.
ATOL = 1e-15


def _load(name):
    return json.loads((DATA / f'shared_{name}.json').read_text())


def _close(ours, ref, scale):
    np.testing.assert_allclose(ours, np.asarray(ref, dtype=float), rtol=RTOL,
                               atol=ATOL * scale)


def _cases(name):
    doc = _load(name)
    assert doc['mss_commit'] == '736a3d128ccd5ecb3736eba231bbf046de7bdafa'
    assert len(doc['cases']) == doc['n_cases']
    return [pytest.param(c, id=str(c['id'])) for c in doc['cases']]


@pytest.mark.parametrize('case', _cases('isherwood72'))
def test_isherwood72_matches_mss(case):
    i = case['inputs']
    args = [i[k] for k in ('Loa', 'B', 'ALw', 'AFw', 'A_SS', 'S', 'C', 'M')]
    tau, CX, CY, CN = isherwood72(np.asarray(i['gamma_r']), i['V_r'], *args)
    o = case['outputs']
    scale = 0.5 * 1.224 * i['V_r'] ** 2 * i['ALw'] * i['Loa']
    # MSS returns tau as 3 x N (rows X, Y, N); ours has the components last.
    _close(np.moveaxis(tau, -1, 0), o['tau_w'], scale)
    for ours, key in ((CX, 'CX'), (CY, 'CY'), (CN, 'CN')):
        _close(ours, o[key], 1.0)


@pytest.mark.parametrize('case', _cases('blendermann94'))
def test_blendermann94_matches_mss(case):
    i = case['inputs']
    tau, CX, CY, CK, CN = blendermann94(np.asarray(i['gamma_r']), i['V_r'], i['AFw'], i['ALw'],
                                        i['sH'], i['sL'], i['Loa'], i['vessel_no'])
    o = case['outputs']
    scale = 0.5 * 1.224 * i['V_r'] ** 2 * i['ALw'] * i['Loa']
    _close(np.moveaxis(tau, -1, 0), o['tau_w'], scale)
    for ours, key in ((CX, 'CX'), (CY, 'CY'), (CK, 'CK'), (CN, 'CN')):
        _close(ours, o[key], 1.0)


def test_blendermann94_covers_all_17_types():
    doc = _load('blendermann94')
    assert {c['inputs']['vessel_no'] for c in doc['cases']} == set(range(1, 18))
    assert len(BLENDERMANN_TYPES) == 17


@pytest.mark.parametrize('bad', [0, 18, 2.0])
def test_blendermann94_refuses_unknown_type(bad):
    with pytest.raises(ValueError, match='vessel_no'):
        blendermann94(0.3, 10.0, 100.0, 400.0, 5.0, 1.0, 50.0, bad)


@pytest.mark.parametrize('case', _cases('encounter'))
def test_encounter_matches_mss(case):
    i = case['inputs']
    ours = encounter(i['chi'], i['U'], np.asarray(i['Omega']))
    _close(ours, case['outputs']['Omega_e'], 1.0)


@pytest.mark.parametrize('case', _cases('hs2vw'))
def test_hs2vw_matches_mss(case):
    _close(hs2vw(case['inputs']['Hs']), case['outputs']['Vw'], 1.0)


@pytest.mark.parametrize('case', _cases('vw2hs'))
def test_vw2hs_matches_mss(case):
    _close(vw2hs(case['inputs']['Vw']), case['outputs']['Hs'], 1.0)


# --- quirks: reproduced or fixed, as the module docstrings say ---------------------------------
VESSEL = dict(Loa=100.0, B=30.0, ALw=900.0, AFw=300.0, A_SS=100.0, S=100.0, C=50.0, M=2)


def test_isherwood72_sign_quirk_reproduced():
    # 270 deg gives the sway force of +90 deg (sign of the raw angle), -90 deg the mirrored one.
    args = list(VESSEL.values())
    t90 = isherwood72(math.pi / 2, 10.0, *args)[0]
    t270 = isherwood72(3 * math.pi / 2, 10.0, *args)[0]
    tm90 = isherwood72(-math.pi / 2, 10.0, *args)[0]
    np.testing.assert_allclose(t270, t90, rtol=1e-12)
    np.testing.assert_allclose(tm90, t90 * [1, -1, -1], rtol=1e-12)


def test_isherwood72_mixed_vector_is_folded_per_element():
    # MSS gives NaN for the 200 deg element of this vector; we fold it like a scalar call.
    args = list(VESSEL.values())
    g = np.radians([10.0, 200.0])
    vec = isherwood72(g, 10.0, *args)[0]
    assert np.all(np.isfinite(vec))
    np.testing.assert_array_equal(vec[1], isherwood72(g[1], 10.0, *args)[0])


def test_vw2hs_takes_arrays_and_inverts_hs2vw():
    hs = np.linspace(0.0, 15.0, 31)
    np.testing.assert_allclose(vw2hs(hs2vw(hs)), hs, rtol=1e-14, atol=1e-14)
    # 0.21 V^2 / g at 10 m/s (Fossen 2021), element-wise on a vector (MSS errors on one).
    assert vw2hs(np.array([10.0, 20.0]))[0] == pytest.approx(2.1 / 0.981, rel=1e-15)


def test_encounter_can_be_negative_as_coded():
    # Following sea (chi = 0), fast ship: omega - omega^2 U / g < 0 (no abs in MSS).
    assert encounter(0.0, 15.0, 2.9) == pytest.approx(2.9 - 2.9 ** 2 * 15.0 / 9.81, rel=1e-15)
    assert encounter(0.0, 15.0, 2.9) < 0
