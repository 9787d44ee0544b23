"""The wave ports (ship_sim.environment) against the MSS functions run under GNU Octave.

Reference: tests/data/mss_env/shared_*.json.gz (MSS commit 736a3d1, LIBRARY/environment/,
provenance in tests/data/README.md). Tolerance: relative 1e-12 of the largest magnitude of
the compared vector plus an absolute floor of 1e-300 (Octave's interp1 and our interpolation
round differently, about 1e-17 of a coefficient; values that underflow agree only absolutely).
"""
import gzip
import json
import warnings
from pathlib import Path

import numpy as np
import pytest

from ship_sim.environment.closed_form_wave_response import wave_response_345
from ship_sim.environment.wave_directional import wave_directional_spectrum
from mss_accuracy import wave_response
from ship_sim.environment.wave_rao import load_rao_table, spheroid_rao
from ship_sim.environment.wave_spectra import (WaveSpectrumWarning, torset_spectrum,
                                               wave_spectrum)

# provenance: tests/data/README.md
DATA = Path(__file__).resolve().parents[1] / 'data' / 'mss_env'
RTOL, ATOL = 1e-12, 1e-300


def _load(name):
    with gzip.open(DATA / f'shared_{name}.json.gz', 'rt') as f:
        return json.load(f)


def _close(ours, ref):
    ours, ref = np.ravel(np.asarray(ours, dtype=float)), np.ravel(np.asarray(ref, dtype=float))
    assert ours.shape == ref.shape
    tol = RTOL * np.max(np.abs(ref), initial=0.0) + ATOL
    err = np.max(np.abs(ours - ref), initial=0.0)
    assert err <= tol, f'max error {err:.3g} > {tol:.3g}'


def _with_warnings(fn):
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter('always')
        out = fn()
    assert all(issubclass(w.category, WaveSpectrumWarning) for w in caught)
    return out, [str(w.message) for w in caught]


SPECTRUM = _load('waveSpectrum')['cases']


@pytest.mark.parametrize('case', SPECTRUM, ids=[str(c['id']) for c in SPECTRUM])
def test_wave_spectrum_equals_mss(case):
    i = case['inputs']
    S, msgs = _with_warnings(lambda: wave_spectrum(i['spectrumType'], i['Parameter'], i['W']))
    _close(S, case['outputs']['S'])
    # Every message MSS printed is warned, and nothing else.
    assert [m for m in msgs if m in case['stdout']] == msgs
    assert bool(msgs) == bool(case['stdout'].strip())


TORSET = _load('torsetSpectrum')['cases']


@pytest.mark.parametrize('case', TORSET, ids=[str(c['id']) for c in TORSET])
def test_torset_spectrum_equals_mss(case):
    i = case['inputs']
    S, msgs = _with_warnings(lambda: torset_spectrum(i['Hs'], i['wo'], i['W']))
    _close(S, case['outputs']['S'])
    assert bool(msgs) == bool(case['stdout'].strip())


DIRECTIONAL = _load('waveDirectionalSpectrum')['cases']


@pytest.mark.parametrize('case', DIRECTIONAL, ids=[str(c['id']) for c in DIRECTIONAL])
def test_wave_directional_spectrum_equals_mss(case):
    i, d = case['inputs'], case.get('random_draws', {})
    args = (i['spectrumType'], i['Parameters'], i['numFreqIntervals'], i['omegaMax'])
    kw = {'spreading': bool(i.get('spreadingFlag', False)), 'n_dir': i.get('numDirections', 16),
          'u_mu': d.get('u_mu'), 'u_omega': d.get('u_omega'),
          'rng': np.random.default_rng(0)}
    if 'error' in case['outputs']:
        with pytest.raises(ValueError, match='1.75'):
            wave_directional_spectrum(*args, **kw)
        return
    out, _ = _with_warnings(lambda: wave_directional_spectrum(*args, **kw))
    ref = case['outputs']
    for key in ('S_M', 'Omega', 'Amp', 'S', 'M', 'mu'):
        _close(getattr(out, key), ref[key])


# wave_response (scripts/mss_accuracy.py) builds the MSS scenario's table; it refuses a table
# whose g differs from the scenario's
def _scenarios(name):
    doc = _load(name)
    return doc, doc['cases']


FORCE_DOC, FORCE = _scenarios('waveForceRAO')
MOTION_DOC, MOTION = _scenarios('waveMotionRAO')


@pytest.mark.parametrize('case', FORCE, ids=[str(c['id']) for c in FORCE])
def test_wave_force_rao_equals_mss(case):
    resp = wave_response(FORCE_DOC['scenarios'][case['scenario']], 'force')
    i = case['inputs']
    call = (i['t'], i['U'], i['psi'], i['beta_wave'])
    _close(resp.force(*call), case['outputs']['tau_wave1'])
    _close(resp.elevation(*call), case['outputs']['waveElevation'])


@pytest.mark.parametrize('case', MOTION, ids=[str(c['id']) for c in MOTION])
def test_wave_motion_rao_equals_mss(case):
    resp = wave_response(MOTION_DOC['scenarios'][case['scenario']], 'motion')
    i = case['inputs']
    eta, nu, nudot = resp.motion(i['t'], i['U'], i['psi'], i['beta_wave'])
    for ours, key in ((eta, 'eta_WF'), (nu, 'nu_WF'), (nudot, 'nudot_WF')):
        _close(ours, case['outputs'][key])


SPHEROID_CASES = _load('spheroidRAO')['cases']


@pytest.mark.parametrize('case', SPHEROID_CASES, ids=[str(c['id']) for c in SPHEROID_CASES])
def test_spheroid_rao_equals_mss(case):
    i, ref = case['inputs'], case['outputs']
    table = spheroid_rao(i['a'], i['b'], i['zn'])
    _close(table.w, ref['w'])
    _close(table.headings, ref['headings'])
    for dof in range(6):
        _close(table.amp[dof], ref['amp'][dof])
        _close(table.amp[dof] * np.cos(table.phase[dof]), np.abs(ref['Re'][dof]))  # as coded
    assert ref['phase_all_zero'] and not table.phase.any()
    signed = spheroid_rao(i['a'], i['b'], i['zn'], signed=True)
    for dof in range(6):
        _close(signed.amp[dof] * np.cos(signed.phase[dof]), ref['Re'][dof])


def test_spheroid_rao_physics():
    # Froude-Krylov heave force per metre of wave amplitude: rho g pi b^2 (MSS's section
    # area), decaying with depth as exp(-k zn), k = w^2 / g in deep water; a beam sea has no
    # surge force, and the signed table's sway force changes sign from 90 to 270 deg.
    t = spheroid_rao(2.0, 1.0, 5.0, signed=True)
    re = t.amp * np.cos(t.phase)
    k = t.w ** 2 / 9.81
    assert re[2, :, 0] == pytest.approx(1025.0 * 9.81 * np.pi * np.exp(-k * 5.0), rel=1e-12)
    i90, i270 = 9, 27
    assert re[0, :, i90] == pytest.approx(np.zeros(t.w.size), abs=1e-9 * re[2, 0, 0])
    assert re[1, :, i270] == pytest.approx(-re[1, :, i90], rel=1e-12)
    with pytest.raises(ValueError, match='submerged'):
        spheroid_rao(1.0, 0.5, 0.0)


RESPONSE345 = _load('waveresponse345')['cases']


@pytest.mark.parametrize('case', RESPONSE345, ids=[str(c['id']) for c in RESPONSE345])
def test_wave_response_345_equals_mss(case):
    i = {k: v for k, v in case['inputs'].items() if not k.endswith('_nominal')}
    ref = case['outputs']
    t, z, phi, theta = wave_response_345(**i)
    _close(t, ref['t'])
    _close(z, ref['z'])
    _close(np.rad2deg(phi), ref['phi'])       # MSS plots degrees
    _close(np.rad2deg(theta), ref['theta'])


def test_wave_response_345_physics():
    # Following sea (beta = 0) has no roll moment; the heave of a very long wave on a short
    # box at rest tends to the wave itself (Jensen et al. 2004: F -> 1, far below resonance).
    hull = dict(zeta4=0.2, T4=6.0, GMT=1.0, Cb=0.65, L=82.8, B=19.2, T=6.0)
    _, z, phi, _ = wave_response_345(2.0, 0.0, 10.0, U=5.0, **hull)
    assert not np.any(phi)
    _, z, _, _ = wave_response_345(1.0, np.pi, 200.0, U=0.0, **hull)
    assert np.max(np.abs(z)) == pytest.approx(1.0, rel=0.02)
    with pytest.raises(ValueError, match='encounter frequency'):
        wave_response_345(1.0, 0.0, 5.0, U=20.0, **hull)


def test_every_shared_case_is_used():
    assert len(SPECTRUM) == 28 and len(TORSET) == 47 and len(DIRECTIONAL) == 7
    assert len(MOTION) == 30 and len(FORCE) == 35
    assert len(SPHEROID_CASES) == 2 and len(RESPONSE345) == 5


def test_packaged_tables_are_the_mss_tables():
    t = load_rao_table('s175', 'motion')
    assert t.amp.shape == (6, 36, 36) and t.length == 175.0
    assert np.allclose(np.rad2deg(t.headings), np.arange(0, 360, 10))
    with pytest.raises(ValueError, match='vessels'):
        load_rao_table('titanic')
