"""Write ship_sim's RAO package data (ship_sim/environment/data/rao_<vessel>.npz) from the MSS
reference JSON files (vessel_<vessel>_RAO_zero_speed.json: the zero-speed slices of MSS
HYDRO/vessels_shipx s175.mat / supply.mat, read in GNU Octave).

    .venv/bin/python scripts/make_rao_tables.py REFERENCE_DIR

The arrays are stored bit for bit (float64); amp/phase are DOF x frequency x heading.
"""
import argparse
from pathlib import Path

import numpy as np

from ship_sim.safe_load import load_json_file

OUT = Path(__file__).resolve().parents[1] / 'ros_ws/src/ship_sim/ship_sim/environment/data'


def convert(src, vessel):
    d = load_json_file(src / f'vessel_{vessel}_RAO_zero_speed.json')
    arrays = {'headings': np.array(d['headings'], dtype=float), 'g': np.float64(d['main']['g']),
              'Lpp': np.float64(d['main']['Lpp']), 'B': np.float64(d['main']['B']),
              'T': np.float64(d['main']['T']), 'm': np.float64(d['main']['m']),
              'rho': np.float64(d['main']['rho'])}
    for kind in ('force', 'motion'):
        rao = d[f'{kind}RAO']
        arrays[f'{kind}_w'] = np.array(rao['w'], dtype=float)
        arrays[f'{kind}_amp'] = np.array(rao['amp'], dtype=float)
        arrays[f'{kind}_phase'] = np.array(rao['phase'], dtype=float)
    OUT.mkdir(parents=True, exist_ok=True)
    np.savez_compressed(OUT / f'rao_{vessel}.npz', **arrays)
    print(f'wrote {OUT / f"rao_{vessel}.npz"}: ' + ', '.join(f'{k} {v.shape}' for k, v in
                                                            arrays.items()))


def main():
    parser = argparse.ArgumentParser(description=__doc__.split('\n')[0])
    parser.add_argument('reference', type=Path, help='folder with vessel_*_RAO_zero_speed.json')
    args = parser.parse_args()
    for vessel in ('s175', 'supply'):
        convert(args.reference, vessel)


if __name__ == '__main__':
    main()
