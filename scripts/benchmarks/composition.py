"""Section ``composition``: several nodes per process (ship_mission.composition) against one
process per node, on a platoon that grows and on the flagship against the relay floor.

Rows, all measured in this one run (the machine's 1-minute load beside each):

- ``platoon N, <mode>``: the first N (1, 3, 5) Mariners of scenarios/platoon_mariner_5.yaml in
  lockstep, started by the mission launcher (ship_mission.launcher.run_scenario, no recorder,
  no analysis) with compose ``none`` (a process per node), ``vessel`` (a container per vessel)
  and ``all`` (one container), for STEPS steps. Wall ms per step: the own stepping span of the
  simulator that starts last ("lockstep: publishing step 0" to "max_steps N reached" in its log
  lines) / steps: it steps with every other vessel already running and gated to it, so the
  staggered starts before it are not in it. CPU ms per step: the CPU (utime + stime, polled from
  /proc: ChildCpu) of every process of the run from the moment the last simulator has
  published step 0 to the moment the last has reached max_steps, / steps, so start-up (imports,
  discovery, the waits) and shutdown are not in it; CPU per vessel = that / N.
  Ratios: wall / the lone vessel's in the same mode (goal <= GOAL_PLATOON_WALL for 5 vessels
  composed), CPU per vessel / the lone vessel's (goal <= GOAL_PER_VESSEL_CPU), and wall against
  the lone vessel with a process per node (how far the platoon is from today's lone vessel).
- ``flagship, <mode>``: the flagship graph (route, guidance, autopilot, vessel; no recorder) in
  lockstep as the ``lockstep`` section runs it (its graph_run for ``none``; the same four nodes in
  one component_container for ``all``), and the bare 3-hop ``relay floor``
  (scripts/benchmarks/relay_nodes.py): CPU per step of all processes over the stepping phase,
  as a ratio to the floor's (goal for the composed graph: <= GOAL_FLAGSHIP_CPU_FLOOR).

A benchmark is not a test: missed goals are reported as such.
"""
import os
import re
import threading
import time
from pathlib import Path

import yaml

from ship_mission.composition import container_spec, containers
from ship_mission.launcher import MissionFailed, params_file, run_scenario
from ship_mission.processes import ProcessGroup, install_env
from ship_mission.scenario import load_scenario

from . import common, lockstep

PLATOON = common.REPO / 'scenarios' / 'platoon_mariner_5.yaml'
RUN_DIR = common.REPO / 'bench' / 'results' / 'composition'
SIZES = (1, 3, 5)
MODES = ('none', 'vessel', 'all')
STEPS = 1500
QUICK_STEPS = 600
FLAGSHIP_STEPS, QUICK_FLAGSHIP_STEPS = 3000, 1000
GOAL_PLATOON_WALL = 6.0
GOAL_PER_VESSEL_CPU = 1.2
GOAL_FLAGSHIP_CPU_FLOOR = 2.0
_TIMEOUTS = re.compile(r'(?P<n>\d+) lockstep timeouts')


class ChildCpu(threading.Thread):
    """Polls the CPU time (utime + stime) of this process's children (the run's node and
    container processes, started by the launcher in this process) from /proc, keeping each
    one's last value, so one that has ended still counts what it used until shortly before.
    It reads the run's logs (under ``folder``/latest) as it goes: the values when the last of
    the ``n`` simulators has published step 0 and when the last has reached max_steps
    ``steps`` (before the launcher stops the graph) give ``used()``, the stepping phase's CPU."""

    def __init__(self, folder, n, steps, period_s=0.02, log_every=5):
        super().__init__(daemon=True)
        self.folder, self.n, self.steps = folder, n, steps
        self.period_s, self.log_every = period_s, log_every
        self.last, self.at_start, self.at_end = {}, None, None
        self._halt = threading.Event()
        self._children = Path(f'/proc/{os.getpid()}/task/{os.getpid()}/children')

    def run(self):
        i = 0
        while self.at_end is None and not self._halt.wait(self.period_s):
            self.poll()
            i += 1
            if i % self.log_every == 0 and (self.folder / 'latest').exists():
                spans, _ = _stepping_spans(self.folder / 'latest', self.steps, started=True)
                if self.at_start is None and len(spans) == self.n:
                    self.at_start = dict(self.last)
                elif self.at_start is not None and sum(e is not None for _, e in spans.values()) == self.n:
                    self.at_end = dict(self.last)

    def poll(self):
        try:
            pids = self._children.read_text().split()
        except OSError:
            return
        for pid in pids:
            _, cpu = lockstep.proc_stat(int(pid))
            if cpu is not None:
                self.last[pid] = cpu

    def used(self):
        """CPU s of the stepping phase, None if it was not seen whole."""
        self._halt.set()
        self.join()
        if self.at_start is None or self.at_end is None:
            return None
        return sum(cpu - self.at_start.get(pid, 0.0) for pid, cpu in self.at_end.items())


def _platoon_file(n, mode, steps, folder):
    data = yaml.safe_load(PLATOON.read_text())
    data['name'] = f'bench_platoon_{n}_{mode}_{steps}'
    data['platoon']['route'] = str(PLATOON.parent / data['platoon']['route'])
    data['platoon']['vessels'] = data['platoon']['vessels'][:n]
    data['duration_s'] = steps * data['dt_s']
    data['compose'] = mode
    data['record'] = False
    path = folder / f'{data["name"]}.yaml'
    path.write_text(yaml.safe_dump(data))
    return path


_LOG_LINE = re.compile(r'^\[\w+\] \[(?P<t>\d+\.\d+)\] \[(?P<name>[^\]]*)\]: (?P<msg>.*)$', re.M)


def _stepping_spans(run, steps, started=False):
    """{simulator logger name: (its step 0 published, its max_steps reached)} from the logs of
    a run (a container's log holds every member's lines), and the lockstep timeouts reported;
    ``started``: {name: (step 0, max_steps or None)} of those that have published step 0."""
    starts, ends, timeouts = {}, {}, 0
    for log in (run / 'logs').glob('*.log'):
        text = log.read_text(errors='replace')
        for m in _LOG_LINE.finditer(text):
            if m['msg'].startswith('lockstep: publishing step 0'):
                starts[m['name']] = float(m['t'])
            elif m['msg'].startswith(f'max_steps {steps} reached'):
                ends[m['name']] = float(m['t'])
        timeouts += sum(int(m['n']) for m in _TIMEOUTS.finditer(text))
    if started:
        return {k: (t, ends.get(k)) for k, t in starts.items()}, timeouts
    return {k: (starts[k], ends[k]) for k in starts if k in ends}, timeouts


def platoon_run(n, mode, steps, folder, tries=2):
    """A launcher run of an n-vessel platoon: wall stepping span, CPU of all its processes.
    A run that fails (on a loaded machine the lockstep start can time out in any mode) is tried
    again, up to ``tries`` runs; the failures are kept in ``failures``."""
    failures = []
    for i in range(tries):
        try:
            return {**_platoon_run(n, mode, steps, folder / f'try{i}'), 'failures': failures}
        except (MissionFailed, RuntimeError) as exc:
            failures.append(f'{type(exc).__name__}: {exc}'[:400])
    raise RuntimeError(f'platoon {n} {mode} {steps} steps failed {tries} times: {failures}')


def _platoon_run(n, mode, steps, folder):
    folder.mkdir(parents=True, exist_ok=True)
    scenario = load_scenario(_platoon_file(n, mode, steps, folder))
    cpu = ChildCpu(folder, n, steps)
    cpu.start()
    try:
        run, _ = run_scenario(scenario, runs_root=folder, domain_id=lockstep._domain_id(),
                              record=False, progress=lambda *_: None, analyse=False,
                              wall_timeout_s=max(300.0, steps * n * 0.2))
    finally:
        used = cpu.used()
    spans, timeouts = _stepping_spans(run, steps)
    if len(spans) != n or used is None:
        raise RuntimeError(f'platoon {n} {mode}: {len(spans)} of {n} simulators published step 0 '
                           f'and reached max_steps (logs {run / "logs"})')
    # the last simulator to start steps with every other one running (and gated to it): its own
    # span is the platoon's stepping, without the staggered starts before it
    last = max(spans.values())
    return {'span_s': last[1] - last[0], 'cpu_s': used, 'timeouts': timeouts,
            'load_1min': os.getloadavg()[0], 'run': str(run)}


def composed_flagship_run(steps, log_root):
    """The flagship's four nodes (as lockstep.graph_run starts them) in one container."""
    from ship_mission.graph import mission_graph
    scenario = load_scenario(lockstep.SCENARIO)
    scenario.stepping = 'lockstep'
    scenario.duration_s = steps * scenario.dt_s
    scenario.display = None
    graph = mission_graph(scenario, record=False)
    (container,) = containers(graph, 'all')
    run = log_root / 'flagship_composed'
    (run / 'params').mkdir(parents=True, exist_ok=True)
    spec = run / 'params' / 'container.json'
    spec.write_text(container_spec(container, lambda node: params_file(run, node), defer=False))
    group = ProcessGroup(install_env(domain_id=lockstep._domain_id()), run / 'logs')
    try:
        proc = group.start(container.label, 'ship_mission', 'component_container', [spec])
        cpu = lockstep._finish_group(group, proc, lambda: 'publishing step 0' in proc.output(),
                                     stepping_timeout=max(120.0, steps * 0.05))
    finally:
        codes = group.stop()
    log = proc.log_path.read_text(errors='replace')
    times = {m['msg']: float(m['t']) for m in lockstep._LOG_TIME.finditer(log)}
    t0 = next((t for msg, t in times.items() if msg.startswith('lockstep: publishing step 0')),
              None)
    t1 = next((t for msg, t in times.items() if msg.startswith(f'max_steps {steps} reached')),
              None)
    if t0 is None or t1 is None or codes.get(proc.label) != 0:
        raise RuntimeError(f'composed flagship did not complete {steps} steps ({codes}); log '
                           f'{proc.log_path}:\n' + log[-1500:])
    m = _TIMEOUTS.search(log)
    return {'config': 'flagship, all', 'steps': steps, 'sim_time_s': steps * scenario.dt_s,
            'startup_s': 0.0, 'stepping_s': t1 - t0, 'exit_codes': codes, 'cpu_s': cpu,
            'load_1min': os.getloadavg()[0], 'lockstep_timeouts': int(m['n']) if m else None}


def run(quick=False):
    steps_p = QUICK_STEPS if quick else STEPS
    log_root = RUN_DIR / time.strftime('%Y%m%d-%H%M%S')
    rows, runs = [], {}
    for n in SIZES:                 # interleaved: the modes see the same phases of the machine
        for mode in MODES:
            r = platoon_run(n, mode, steps_p, log_root / f'platoon{n}_{mode}')
            runs[f'platoon {n}, {mode}'] = r
            cpu = r['cpu_s'] / steps_p * 1e3
            rows.append({'config': f'platoon {n}, {mode}', 'vessels': n, 'mode': mode,
                         'wall_ms': r['span_s'] / steps_p * 1e3, 'cpu_ms': cpu,
                         'cpu_vessel_ms': cpu / n, 'timeouts': r['timeouts'],
                         'failed_runs': len(r['failures']), 'load_1min': r['load_1min']})
    lone = {r['mode']: r for r in rows if r['vessels'] == 1}
    for r in rows:
        r['wall_ratio'] = r['wall_ms'] / lone[r['mode']]['wall_ms']
        r['cpu_vessel_ratio'] = r['cpu_vessel_ms'] / lone[r['mode']]['cpu_vessel_ms']
        r['wall_vs_lone_none'] = r['wall_ms'] / lone['none']['wall_ms']
    steps = QUICK_FLAGSHIP_STEPS if quick else FLAGSHIP_STEPS
    flag = {'flagship, none': lockstep.graph_run(steps, False, 'flagship, none', log_root),
            'flagship, all': composed_flagship_run(steps, log_root),
            'relay floor': lockstep.relay_run(steps, log_root, raw=True)}
    floor = lockstep._row(flag['relay floor'])['cpu_total']
    for key, res in flag.items():
        row = lockstep._row(res)
        rows.append({'config': key, 'vessels': 1, 'mode': key.split(', ')[-1],
                     'wall_ms': row['us_per_step'] / 1e3, 'cpu_ms': row['cpu_total'] / 1e3,
                     'cpu_vessel_ms': row['cpu_total'] / 1e3, 'cpu_floor_ratio':
                     row['cpu_total'] / floor, 'timeouts': row['lockstep_timeouts'],
                     'load_1min': row['load_1min']})
    runs.update(flag)
    by = {r['config']: r for r in rows}
    five = by[f'platoon {SIZES[-1]}, all']
    goals = [common.goal(f'platoon of {SIZES[-1]}, composed: wall per step / lone vessel',
                         five['wall_ratio'], GOAL_PLATOON_WALL, 'x'),
             common.goal(f'platoon of {SIZES[-1]}, composed: CPU per vessel / lone vessel',
                         five['cpu_vessel_ratio'], GOAL_PER_VESSEL_CPU, 'x'),
             common.goal('flagship composed: CPU per step / relay floor',
                         by['flagship, all']['cpu_floor_ratio'], GOAL_FLAGSHIP_CPU_FLOOR, 'x')]
    bad = [r['config'] for r in rows if r['timeouts']]
    notes = [f'platoon: {steps_p} steps; wall per step = the last-started simulator\'s own span '
             '/ steps; CPU per step = the CPU of every process of the run (not this process and '
             'its launcher monitor) from the moment the last simulator has published step 0 to '
             'the moment the last has reached max_steps / steps; flagship: stepping phase of one '
             f'run of {steps} steps, CPU of all its processes',
             "ratios: x lone = against the 1-vessel platoon in the same mode; x lone 'none' = "
             'against the 1-vessel platoon with a process per node; load = 1-minute load average '
             'when the row ended (2 cores shared: wall times follow the load)',
             'failed runs: launcher runs of the row that failed and were run again (their '
             'errors are in the JSON)',
             f'logs under {log_root}']
    if bad:
        notes.insert(0, f'lockstep timeouts in {bad}: those numbers include held steps')
    return {
        'title': 'composed nodes (compose: vessel, all) vs a process per node (none): platoon of '
                 f'{"/".join(map(str, SIZES))} Mariners in lockstep, flagship vs the relay floor',
        'columns': [['config', 'config'], ['wall_ms', 'wall ms/step'], ['cpu_ms', 'CPU ms/step'],
                    ['cpu_vessel_ms', 'CPU ms/vessel'], ['wall_ratio', 'wall x lone'],
                    ['cpu_vessel_ratio', 'CPU/vessel x lone'],
                    ['wall_vs_lone_none', "wall x lone 'none'"],
                    ['cpu_floor_ratio', 'CPU x floor'], ['load_1min', 'load'],
                    ['timeouts', 'timeouts'], ['failed_runs', 'failed runs']],
        'rows': rows, 'goals': goals, 'notes': notes, 'runs': runs, 'failed': bool(bad),
    }
