#!/usr/bin/env python3
"""Identify first-order Nomoto K, T for ship_sim models and derive their autopilot gains.

    scripts/identify_nomoto.py [--models mariner tanker ...] [--rudder-deg 10]
        [--switch-deg 10] [--h 0.1] [--out-dir ros_ws/src/ship_autopilot/ship_autopilot/data] [--dry-run]
        [--results runs/nomoto/nomoto.json]

For each model: a zig-zag (rudder/switch heading, first to starboard) from straight-running
trim at the model's default speed, then an equation-error least-squares fit of
r_dot = a r + b delta + c (ship_autopilot.identification); K = b/a, T = -1/a (unified rudder
sign: positive turns to port, so K > 0 for a normal ship). Prints a table and writes
<out-dir>/nomoto_gains.yaml (identified models, manoeuvre, fit quality) and
<out-dir>/autopilot_gains.yaml (PD and fuzzy PID gains designed from them by
ship_autopilot.gains). Exit codes: 0 done, 1 a model failed.

``--results FILE`` writes a results file (JSON, with provenance) instead of the two YAML files,
which stay as they are: the identified models and gains, and for context the linear
second-order Mariner (Lee 2004 Table 2.2, ``nomoto2``) fitted on its own zig-zag and the
Mariner at other zig-zag amplitudes. doc/results/nomoto.md renders from its committed copy,
doc/results/data/nomoto.json.
"""
import argparse
import json
import sys
from pathlib import Path

import numpy as np
import yaml
from results_pages.provenance import provenance

from ship_autopilot import gains as design
from ship_autopilot.identification import heading_prediction_rms, identify_nomoto
from ship_sim.models import cards, make_model

ROOT = Path(__file__).resolve().parents[1]


def default_models():
    """The models whose cards ask for an identification (``identify``) and keep their gains
    in the package data (a card with its own ``gain_tables`` is identified with --models and
    --out-dir naming that folder)."""
    return [c.name for c in cards() if c.identify and c.gain_tables is None]
#: --results context: the linear model whose low-frequency K, T a zig-zag fit is compared with,
#: and the model and zig-zag amplitudes (rudder = switch heading, deg) of the amplitude study
LINEAR_REFERENCE = 'nomoto2'
AMPLITUDE_MODEL, AMPLITUDES_DEG = 'mariner', (5.0, 10.0, 20.0)


def identify(name, rudder, switch, h):
    model = make_model(name)
    fit, man = identify_nomoto(model, rudder=rudder, switch_heading=switch, h=h)
    speed, length = float(man.speed[0]), float(model.length)
    entry = {
        'K': fit.K, 'T': fit.T, 'a': fit.a, 'b': fit.b, 'c': fit.c,
        'K_nd': fit.K * length / speed, 'T_nd': fit.T * speed / length,
        'rudder_trim_deg': float(np.rad2deg(fit.rudder_trim)),
        'speed_mps': speed, 'length_m': length,
        'rudder_max_deg': float(np.rad2deg(model.rudder_max)),
        'rudder_rate_max_deg_s': float(np.rad2deg(model.rudder_rate_max)),
        'manoeuvre': man.description,
        'r_squared': fit.r_squared,
        'heading_rms_deg': float(np.rad2deg(heading_prediction_rms(fit, man))),
        'n_samples': fit.n_samples,
    }
    if hasattr(model, 'nomoto_ab'):  # the model's own linear reduction, for comparison
        a, b = model.nomoto_ab()
        entry['model_K'], entry['model_T'] = float(b / a), float(-1.0 / a)
    return entry


def write_results(args, nomoto, gains):
    rudder, switch = np.deg2rad(args.rudder_deg), np.deg2rad(args.switch_deg)
    ref = make_model(LINEAR_REFERENCE)
    linear = identify(LINEAR_REFERENCE, rudder, switch, args.h)
    linear['low_frequency'] = {'K': ref.K, 'T': ref.T1 + ref.T2 - ref.T3,
                               'T1': ref.T1, 'T2': ref.T2, 'T3': ref.T3}
    amplitudes = {f'{a:g}/{a:g}': identify(AMPLITUDE_MODEL, np.deg2rad(a), np.deg2rad(a), args.h)
                  for a in AMPLITUDES_DEG}
    args.results.parent.mkdir(parents=True, exist_ok=True)
    args.results.write_text(json.dumps({
        'provenance': provenance(),
        'settings': {'rudder_deg': args.rudder_deg, 'switch_deg': args.switch_deg, 'h_s': args.h},
        'models': nomoto, 'gains': gains,
        'linear_reference': {'model': LINEAR_REFERENCE, 'fit': linear},
        'amplitudes': {'model': AMPLITUDE_MODEL, 'fits': amplitudes},
    }, indent=1))
    print(f'wrote {args.results} (the YAML files are unchanged)')


def _rounded(obj, digits=7):
    """Floats to ``digits`` significant digits (readable, stable YAML), recursively."""
    if isinstance(obj, dict):
        return {k: _rounded(v, digits) for k, v in obj.items()}
    if isinstance(obj, float):
        return float(f'{obj:.{digits}g}')
    return obj


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    p.add_argument('--models', nargs='+', default=default_models(),
                   help='ship_sim registry names (default: %(default)s)')
    p.add_argument('--rudder-deg', type=float, default=10.0, help='zig-zag rudder (deg)')
    p.add_argument('--switch-deg', type=float, default=10.0, help='zig-zag switch heading (deg)')
    p.add_argument('--h', type=float, default=0.1, help='RK4 step and sample time (s)')
    p.add_argument('--out-dir', type=Path, default=design.DATA_DIR,
                   help='where the two YAML files go (default: the package data dir)')
    p.add_argument('--dry-run', action='store_true', help='print the table, write nothing')
    p.add_argument('--results', type=Path, metavar='FILE',
                   help='write a results file (JSON) instead of the YAML files')
    args = p.parse_args(argv)
    for key in ('rudder_deg', 'switch_deg', 'h'):
        if not getattr(args, key) > 0:
            p.error(f'--{key.replace("_", "-")} must be > 0, got {getattr(args, key)}')

    rudder, switch = np.deg2rad(args.rudder_deg), np.deg2rad(args.switch_deg)
    nomoto, gains, failed = {}, {}, []
    head = (f"{'model':10s} {'K 1/s':>9s} {'T s':>8s} {'a 1/s':>10s} {'b 1/s2':>11s} "
            f"{'trim deg':>8s} {'R2':>6s} {'psi rms':>7s} | {'wn':>7s} {'k1':>7s} {'k2':>8s}")
    print(head)
    print('-' * len(head))
    for name in args.models:
        try:
            e = identify(name, rudder, switch, args.h)
            g = design.design_gains(e['K'], e['T'], e['speed_mps'], e['length_m'],
                                    omega_n_nd=design.omega_n_nd(name))
        except Exception as exc:  # noqa: BLE001 (report and go on with the other models)
            print(f'{name:10s} FAILED: {exc}')
            failed.append(name)
            continue
        nomoto[name], gains[name] = e, g
        print(f"{name:10s} {e['K']:9.5f} {e['T']:8.2f} {e['a']:10.6f} {e['b']:11.3e} "
              f"{e['rudder_trim_deg']:8.3f} {e['r_squared']:6.3f} {e['heading_rms_deg']:7.3f} | "
              f"{g['omega_n']:7.4f} {g['pd']['k1']:7.3f} {g['pd']['k2']:8.3f}")

    if args.dry_run or not nomoto:
        return 1 if failed else 0
    if args.results:
        write_results(args, nomoto, gains)
        return 1 if failed else 0
    cmd = 'scripts/identify_nomoto.py ' + ' '.join(argv if argv is not None else sys.argv[1:])
    nomoto, gains = _rounded(nomoto), _rounded(gains)
    common = (f'# Generated by {cmd.strip()}; do not edit by hand, rerun the script.\n'
              '# Units: K 1/s, T s, a 1/s, b 1/s^2, c rad/s^2; *_nd nondimensional (L, U);\n'
              '# unified rudder sign (positive turns to port): r_dot = a r + b delta + c.\n')
    args.out_dir.mkdir(parents=True, exist_ok=True)
    with open(args.out_dir / 'nomoto_gains.yaml', 'w', encoding='utf-8') as f:
        f.write(common)
        yaml.safe_dump({
            'method': ('equation-error least squares of r_dot = a r + b delta + c on a zig-zag '
                       '(ship_autopilot.identification); delta = actual rudder; '
                       'heading_rms_deg: heading predicted by the fit from the same rudder'),
            'models': nomoto}, f, sort_keys=False)
    with open(args.out_dir / 'autopilot_gains.yaml', 'w', encoding='utf-8') as f:
        f.write(common)
        yaml.safe_dump({
            'method': ('PD: k1 = -wn^2/b, k2 = -(a + 2 zeta wn)/b (Angelopoulos 2011 eq. 20); '
                       'wn = omega_n_nd U/L; fuzzy PID (Lee 2004 Ch. 5) linearised at the '
                       'origin to kp = k1, kd = k2, ki = k1 wn KI_FACTOR, scaled by e_sat '
                       '(ship_autopilot.gains)'),
            'zeta': design.ZETA, 'ki_factor': design.KI_FACTOR, 'e_sat_deg': design.E_SAT_DEG,
            'integration_band_deg': design.INTEGRATION_BAND_DEG,
            'models': gains}, f, sort_keys=False)
    print(f'wrote {args.out_dir / "nomoto_gains.yaml"} and {args.out_dir / "autopilot_gains.yaml"}')
    return 1 if failed else 0


if __name__ == '__main__':
    sys.exit(main())
