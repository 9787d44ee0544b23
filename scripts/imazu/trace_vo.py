"""Trace velocity-obstacle decisions in one Imazu run (in process, scripts/imazu/runner.py).

    .venv/bin/python scripts/trace_vo.py --case 13 --ship mariner [--every 10]
        [--from 0] [--to 2000]
    .venv/bin/python scripts/trace_vo.py --scenario runs/failure_search/failures/uniform/uniform_0071.yaml

Prints, per decision while a target is a threat: the mode, the threats' latched situations,
whether Rule 17 acting is in force, the admissible course offsets (deg) at each speed
multiplier, the chosen scenario and its predicted minimum distance to each target over the
horizon (own-ship model) and straight-line closest approach (the held command); then each
target's actual closest approach in the run. ``--scenario`` traces a scenario file written by
the runner's ``write_scenario`` (a failure the search found) instead of an Imazu case.
"""
import argparse
import tempfile
from pathlib import Path

import numpy as np

from imazu.cases import load_cases
from imazu.runner import case_scenario, run_scenario, write_scenario

from ship_guidance import colregs
from ship_guidance.cpa import cpa, velocity
from ship_guidance.velocity_obstacles import VelocityObstacles


def _deg(values):
    return ','.join(f'{v:+.0f}' for v in np.rad2deg(values))


def trace(case, ship, every=1, t_from=0.0, t_to=np.inf, out=print, scenario=None):
    """RunResult of the case, or of the ``scenario`` file when given; prints the decisions
    (see the module docstring)."""
    records = []
    original = VelocityObstacles._choose

    def recording(self, sc):
        k, cost = original(self, sc)
        ok, first = self.admissible(sc)
        records.append((sc, ok, first, k))
        return k, cost

    VelocityObstacles._choose = recording
    try:
        if scenario is not None:
            result = run_scenario(scenario)
        else:
            doc, route = case_scenario(case, load_cases()[case], ship, 'vo')
            with tempfile.TemporaryDirectory() as tmp:
                result = run_scenario(write_scenario(doc, route, tmp))
    finally:
        VelocityObstacles._choose = original
    names = sorted(result.targets)
    it = iter(records)
    n = 0
    for t, mode, off, mult in result.decisions:
        if mode in ('nominal', 'stand-on'):
            if t_from <= t <= t_to and mode == 'stand-on' and n % every == 0:
                out(f't={t:6.0f} stand-on (held)')
            n += 1
            continue
        sc, ok, first, k = next(it)
        n += 1
        if not (t_from <= t <= t_to) or (n - 1) % every:
            continue
        sit = ' '.join(f'{nm}:{colregs.SITUATIONS[c]}' for nm, c, th in
                       zip(names, sc.codes, sc.threat) if th)
        adm = '; '.join(f'x{m:g}: {_deg(sc.offsets[ok & (sc.multipliers == m)]) or "-"}'
                        for m in np.unique(sc.multipliers)[::-1])
        v_c = velocity(sc.chi_c[k], sc.u_c[k])
        _, dcpa = cpa(sc.p_own0, v_c, sc.p_tgt0, sc.v_tgt)
        d_pred = sc.dist[k].min(axis=1)
        out(f't={t:6.0f} {mode:11s} act17={int(sc.acting_stand_on)} [{sit}] admissible {adm} '
            f'| chose {np.rad2deg(sc.offsets[k]):+.0f} x{sc.multipliers[k]:g} '
            f'({"admissible" if ok[k] else f"none admissible, first entry {first[k]:.0f} s"}) '
            f'pred. min ' + ' '.join(f'{nm} {d:.0f}' for nm, d in zip(names, d_pred))
            + ' | held dcpa ' + ' '.join(f'{nm} {d:.0f}' for nm, d in zip(names, dcpa)))
    for nm in names:
        d = np.hypot(*(result.targets[nm][:, :2] - result.own[:, :2]).T)
        i = int(d.argmin())
        out(f'{nm}: closest {d[i]:.0f} m at t = {result.t[i]:.0f} s')
    return result


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split('\n')[0])
    which = ap.add_mutually_exclusive_group(required=True)
    which.add_argument('--case', type=int, help='Imazu case')
    which.add_argument('--scenario', type=Path, help='a scenario file with a VO own ship')
    ap.add_argument('--ship', default='mariner')
    ap.add_argument('--every', type=int, default=1, help='print every n-th decision')
    ap.add_argument('--from', dest='t_from', type=float, default=0.0)
    ap.add_argument('--to', dest='t_to', type=float, default=np.inf)
    a = ap.parse_args(argv)
    trace(a.case, a.ship, a.every, a.t_from, a.t_to, scenario=a.scenario)
    return 0

