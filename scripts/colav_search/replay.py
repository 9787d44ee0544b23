"""Replay of a written failure through the node graph: ``scripts/run_mission.py`` (every node
its own process, lockstep, a bag recorded), and the bag's own-target minimum distance (the
launcher's metrics: ship_mission.encounter.min_distance over the recorded light targets)
against the in-process one the search wrote into the scenario's header."""
import json
import re
import subprocess
import sys
from pathlib import Path

#: Largest difference (m) between the replayed and the in-process minimum distance.
TOLERANCE_M = 1.0
_HEADER = re.compile(r'^# in-process min distance ([0-9.]+) m', re.M)
REPO = Path(__file__).resolve().parents[2]


def in_process_min_distance(path):
    """The in-process minimum distance in a failure scenario's header."""
    m = _HEADER.search(Path(path).read_text())
    if m is None:
        raise ValueError(f'{path}: no "in-process min distance" header (not written by the search)')
    return float(m.group(1))


def run_min_distance(run_dir):
    """Smallest own-target distance of a run folder (metrics.json: each target's closest
    approach to each vessel)."""
    metrics = json.loads((Path(run_dir) / 'metrics.json').read_text())
    return min(c['min_distance_m'] for m in metrics['traffic'].values()
               for c in m['closest_approach'].values())


def scenarios(target):
    """The failure scenarios of a file or folder (route.yaml excluded)."""
    target = Path(target)
    if target.is_file():
        return [target]
    return sorted(p for p in target.rglob('*.yaml') if p.name != 'route.yaml')


def replay(path, runs, wall_timeout_s=3600.0):
    """(in-process, replayed) minimum distance of one failure scenario run by run_mission."""
    runs = Path(runs)
    runs.mkdir(parents=True, exist_ok=True)
    before = set(runs.iterdir())
    subprocess.run([sys.executable, str(REPO / 'scripts' / 'run_mission.py'), str(path),
                    '--runs', str(runs), '--wall-timeout', str(wall_timeout_s)], check=True)
    new = [p for p in runs.iterdir() if p not in before and not p.is_symlink()   # runs/latest
           and (p / 'metrics.json').exists()]
    if len(new) != 1:
        raise RuntimeError(f'{path}: expected one new run folder in {runs}, found {len(new)}')
    return in_process_min_distance(path), run_min_distance(new[0])
