#!/usr/bin/env python3
"""How closely the MSS ports reproduce MSS run under Octave, as a results file.

    .venv/bin/python scripts/mss_accuracy.py [--out runs/mss_accuracy]

Writes <out>/mss_accuracy.json (doc/results/mss_models.md and the wave ports in
doc/results/wind_waves.md render from its committed copy, doc/results/data/mss_accuracy.json):

- golden derivatives (tests/data/mss_golden/golden_<model>.json): per model the worst relative
  error of the derivative over the nonzero reference components, for the vector and the float
  path, and the worst absolute error where MSS gives exactly 0;
- manoeuvres (tests/data/mss_golden/maneuvers.json, RK4, h = 0.1 s, 700 s): every turning circle
  and the Mariner zig-zags, our figures next to MSS's and the worst relative difference;
- the NPS AUV II reduction to Nomoto (Simakis 1992 eq. 2.11) and the PD gains designed from it
  at omega_n 3, zeta 0.8 (time in L/U);
- wave ports (tests/data/mss_env/shared_*.json.gz): per function and output, the worst error
  relative to the largest reference value of the case.

The tests (tests/unit/test_mss_golden.py, test_maneuvers.py, test_wave_ports.py) assert the
tolerances; this script measures what the tolerances leave. Exit code 0.
"""
import argparse
import gzip
import json
import math
import sys
import warnings
from pathlib import Path

import numpy as np
from results_pages.provenance import provenance

from ship_guidance.heading_loop import pd_gains
from ship_sim.environment.closed_form_wave_response import wave_response_345
from ship_sim.environment.wave_directional import wave_directional_spectrum
from ship_sim.environment.wave_rao import RaoTable, WaveResponse, load_rao_table, spheroid_rao
from ship_sim.environment.wave_spectra import torset_spectrum, wave_spectrum
from ship_sim.maneuvers import turning_circle, zigzag
from ship_sim.models import make_model

ROOT = Path(__file__).resolve().parents[1]
GOLDEN = ROOT / 'tests' / 'data' / 'mss_golden'
MSS_ENV = ROOT / 'tests' / 'data' / 'mss_env'
MODELS = ('mariner', 'tanker', 'container')

#: turning-circle scenario of maneuvers.json -> (model, constructor params, native rudder
#: command (deg), shaft (rpm)); the native sign is converted through the model's RUDDER_SIGN
TURNS = {
    'mariner_turn_ui+35': ('mariner', {}, 35.0, None),
    'mariner_turn_ui-35': ('mariner', {}, -35.0, None),
    'tanker_turn_dc+10_h1000': ('tanker', {'h': 1000.0}, 10.0, 80.0),
    'tanker_turn_dc-10_h1000': ('tanker', {'h': 1000.0}, -10.0, 80.0),
    'tanker_turn_dc-10_h30': ('tanker', {'h': 30.0}, -10.0, 80.0),
    'container_turn_dc+10_n70': ('container', {}, 10.0, 70.0),
    'container_turn_dc-10_n70': ('container', {}, -10.0, 70.0),
    'container_turn_dc+10_n80': ('container', {}, 10.0, 80.0),
}
#: our TurningCircle field -> maneuvers.json field
TURN_MEASURES = {
    'advance_m': 'advance_at_90deg_m',
    'transfer_m': 'transfer_at_90deg_m',
    'tactical_diameter_m': 'tactical_diameter_at_180deg_m',
    'steady_radius_m': 'steady_turning_radius_U_over_r_m',
    'final_speed_mps': 'final_speed_U_mps',
    'time_to_90deg_s': 'time_to_90deg_s',
    'max_transfer_m': 'max_transfer_m',
}
ZIGZAGS = (10, 20)
#: The force file's AUV scenario: spheroidRAO(vessel, 1.2, 0.3, 5, false) (its vessel_files).
SPHEROID = {'spheroid_a1.2_b0.3_zn5': (1.2, 0.3, 5.0)}
NPS_DESIGN = {'omega_n': 3.0, 'zeta': 0.8}


def golden_model(name, case):
    """The model a golden case was run with (the Mariner's U0 is a constructor parameter)."""
    return make_model(name, U0=case['U0']) if name == 'mariner' else make_model(name)


def load_golden(name):
    return json.loads((GOLDEN / f'golden_{name}.json').read_text())


def load_maneuvers():
    return json.loads((GOLDEN / 'maneuvers.json').read_text())


def load_shared(name):
    with gzip.open(MSS_ENV / f'shared_{name}.json.gz', 'rt') as f:
        return json.load(f)


def run_turn(key):
    """(model, TurningCircle, t, states) of a maneuvers.json turning-circle scenario."""
    name, params, native_deg, shaft = TURNS[key]
    model = make_model(name, **params)
    rudder = math.radians(native_deg) / model.RUDDER_SIGN
    return (model,) + turning_circle(model, rudder, shaft, h=0.1, t_end=700.0)


def wave_response(scenario, kind):
    """The WaveResponse of an MSS wave scenario (vessel table cut to its n_w frequencies,
    its directions, amplitudes and phases)."""
    name = scenario['vessel']
    table = spheroid_rao(*SPHEROID[name]) if name in SPHEROID else load_rao_table(name, kind)
    n_w = scenario['n_w']
    table = RaoTable(w=table.w[:n_w], headings=table.headings, amp=table.amp[:, :n_w],
                     phase=table.phase[:, :n_w], g=table.g, length=table.length, kind=kind,
                     vessel=table.vessel)
    if table.g != scenario['g']:
        raise ValueError(f"{name}: table g {table.g} differs from the scenario's {scenario['g']}")
    return WaveResponse(table, scenario['Omega'], scenario['mu'], scenario['Amp'],
                        scenario['randomPhases'])


def _golden_errors(model, case, xdot):
    ref = np.asarray(case['xdot'], dtype=float)
    err = np.abs(np.asarray(xdot, dtype=float) - ref)
    nz = ref != 0.0
    rel = float(np.max(err[nz] / np.abs(ref[nz]), initial=0.0))
    return rel, float(np.max(err[~nz], initial=0.0)), int(np.count_nonzero(~nz))


def golden():
    out = {}
    for name in MODELS:
        doc = load_golden(name)
        rows = {'vector': [], 'float': []}
        zeros = 0
        for case in doc['cases']:
            model = golden_model(name, case)
            x, ui = np.array(case['x']), np.array(case['ui'])
            vec = _golden_errors(model, case, model.rhs(x, ui))
            flt = _golden_errors(model, case, model.rhs_scalar(case['x'], case['ui']))
            rows['vector'].append(vec)
            rows['float'].append(flt)
            zeros += vec[2]
        out[name] = {
            'cases': len(doc['cases']),
            'zero_reference_components': zeros,
            **{f'{path}_worst_relative_error': max(r[0] for r in rs) for path, rs in rows.items()},
            **{f'{path}_worst_absolute_error_at_zero': max(r[1] for r in rs)
               for path, rs in rows.items()},
        }
    return out


def manoeuvres():
    ref = load_maneuvers()
    turns = {}
    for key in TURNS:
        _, res, _, _ = run_turn(key)
        theirs = ref['turning_circle'][key]['rk4_h0.1']
        ours = {m: float(getattr(res, m)) for m in TURN_MEASURES}
        mss = {m: theirs[f] for m, f in TURN_MEASURES.items()}
        turns[key] = {
            'model': TURNS[key][0], 'native_rudder_deg': TURNS[key][2], 'shaft_rpm': TURNS[key][3],
            'params': TURNS[key][1], 'direction': res.direction,
            'mss_direction': 1 if theirs['turn_direction'].startswith('starboard') else -1,
            'ours': ours, 'mss': mss,
            'worst_relative_difference': max(abs(ours[m] - mss[m]) / abs(mss[m]) for m in ours),
        }
    zigs = {}
    for size in ZIGZAGS:
        model = make_model('mariner')
        res, _, _, _ = zigzag(model, math.radians(size), math.radians(size), h=0.1, t_end=700.0)
        theirs = ref['zigzag'][f'mariner_zigzag_{size}_{size}']['rk4_h0.1']
        zigs[f'{size}/{size}'] = {
            'ours_overshoots_deg': [float(v) for v in np.degrees(res.overshoots_rad[:2])],
            'mss_overshoots_deg': [theirs['first_overshoot_angle_deg'],
                                   theirs['second_overshoot_angle_deg']],
        }
    return {'method': 'RK4, h = 0.1 s, 700 s', 'turning_circle': turns, 'zigzag_mariner': zigs}


def nps_auv2():
    a, b = make_model('nps_auv2').nondimensional_nomoto_ab()
    k1, k2 = pd_gains(a, b, **NPS_DESIGN)
    return {'a_prime': float(a), 'b_prime': float(b), **NPS_DESIGN, 'k1': k1, 'k2': k2}


def _rel(ours, ref):
    """Largest error relative to the largest reference magnitude (0 for an all-zero case)."""
    ours, ref = np.ravel(np.asarray(ours, dtype=float)), np.ravel(np.asarray(ref, dtype=float))
    scale = np.max(np.abs(ref), initial=0.0)
    err = np.max(np.abs(ours - ref), initial=0.0)
    return float(err / scale) if scale > 0 else float(err)


def _worst(pairs):
    """{output: worst relative error} over (output, ours, ref) of all cases."""
    out = {}
    for key, ours, ref in pairs:
        out[key] = max(out.get(key, 0.0), _rel(ours, ref))
    return out


def _quiet(fn):
    # MSS prints warnings for some cases; the ports warn the same (the test checks them)
    with warnings.catch_warnings():
        warnings.simplefilter('ignore')
        return fn()


def _spectrum_pairs(cases):
    for c in cases:
        i = c['inputs']
        yield 'S', _quiet(lambda: wave_spectrum(i['spectrumType'], i['Parameter'], i['W'])), \
            c['outputs']['S']


def _torset_pairs(cases):
    for c in cases:
        i = c['inputs']
        yield 'S', _quiet(lambda: torset_spectrum(i['Hs'], i['wo'], i['W'])), c['outputs']['S']


def _directional_pairs(cases):
    for c in cases:
        if 'error' in c['outputs']:
            continue          # MSS errors there (JONSWAP's w0 sqrt(Hs) limit), as do we
        i, d = c['inputs'], c.get('random_draws', {})
        out = _quiet(lambda: wave_directional_spectrum(
            i['spectrumType'], i['Parameters'], i['numFreqIntervals'], i['omegaMax'],
            spreading=bool(i.get('spreadingFlag', False)), n_dir=i.get('numDirections', 16),
            u_mu=d.get('u_mu'), u_omega=d.get('u_omega'), rng=np.random.default_rng(0)))
        for key in ('S_M', 'Omega', 'Amp', 'S', 'M', 'mu'):
            yield key, getattr(out, key), c['outputs'][key]


def _force_pairs(doc):
    for c in doc['cases']:
        resp = wave_response(doc['scenarios'][c['scenario']], 'force')
        i = c['inputs']
        call = (i['t'], i['U'], i['psi'], i['beta_wave'])
        yield 'tau_wave', resp.force(*call), c['outputs']['tau_wave1']
        yield 'waveElevation', resp.elevation(*call), c['outputs']['waveElevation']


def _motion_pairs(doc):
    for c in doc['cases']:
        resp = wave_response(doc['scenarios'][c['scenario']], 'motion')
        i = c['inputs']
        eta, nu, nudot = resp.motion(i['t'], i['U'], i['psi'], i['beta_wave'])
        for ours, key in ((eta, 'eta_WF'), (nu, 'nu_WF'), (nudot, 'nudot_WF')):
            yield key, ours, c['outputs'][key]


def _spheroid_pairs(cases):
    for c in cases:
        i, ref = c['inputs'], c['outputs']
        table = spheroid_rao(i['a'], i['b'], i['zn'])
        yield 'w', table.w, ref['w']
        yield 'amp', table.amp, ref['amp']
        signed = spheroid_rao(i['a'], i['b'], i['zn'], signed=True)
        yield 'Re (signed=True)', signed.amp * np.cos(signed.phase), ref['Re']


def _response345_pairs(cases):
    for c in cases:
        i = {k: v for k, v in c['inputs'].items() if not k.endswith('_nominal')}
        t, z, phi, theta = wave_response_345(**i)
        ref = c['outputs']
        yield 't', t, ref['t']
        yield 'z', z, ref['z']
        yield 'phi', np.rad2deg(phi), ref['phi']          # MSS plots degrees
        yield 'theta', np.rad2deg(theta), ref['theta']


#: MSS function -> (shared file, pairs from its loaded document)
WAVE_PORTS = {
    'waveSpectrum': lambda d: _spectrum_pairs(d['cases']),
    'torsetSpectrum': lambda d: _torset_pairs(d['cases']),
    'waveDirectionalSpectrum': lambda d: _directional_pairs(d['cases']),
    'waveForceRAO': _force_pairs,
    'waveMotionRAO': _motion_pairs,
    'spheroidRAO': lambda d: _spheroid_pairs(d['cases']),
    'waveresponse345': lambda d: _response345_pairs(d['cases']),
}


def wave_ports():
    out = {}
    for fn, pairs in WAVE_PORTS.items():
        doc = load_shared(fn)
        worst = _worst(pairs(doc))
        out[fn] = {'cases': len(doc['cases']), 'worst_relative_error': worst,
                   'overall': max(worst.values())}
    return out


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split('\n')[0])
    ap.add_argument('--out', type=Path, default=ROOT / 'runs' / 'mss_accuracy',
                    help='folder for mss_accuracy.json (default runs/mss_accuracy)')
    args = ap.parse_args(argv)
    result = {'golden': golden(), 'manoeuvres': manoeuvres(), 'nps_auv2': nps_auv2(),
              'wave_ports': wave_ports()}
    args.out.mkdir(parents=True, exist_ok=True)
    result = {'provenance': provenance(), 'mss_commit': load_golden('mariner')['source_commit'],
              **result}
    path = args.out / 'mss_accuracy.json'
    path.write_text(json.dumps(result, indent=1))
    print(f'wrote {path}', file=sys.stderr)
    return 0


if __name__ == '__main__':
    sys.exit(main())
