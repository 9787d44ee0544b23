"""Section ``lockstep``: how fast the flagship graph steps in lockstep, against a middleware floor.

Rows (every row is a set of node processes started from the colcon install tree, as
``ros2 run`` would, in an own ROS_DOMAIN_ID and namespace, ROS_AUTOMATIC_DISCOVERY_RANGE=
LOCALHOST):

- ``graph``: the flagship scenario (scenarios/flagship_mariner.yaml: one Mariner, 10 Hz
  control, ILOS + PD) in lockstep for SIM_TIME_S of sim time, its four nodes started with the
  very parameters the mission launcher writes (ship_mission.launcher.node_parameters), no bag
  recorder. The launcher's own progress monitor (an rclpy node following /clock) is not
  started: it is no part of the graph and would take CPU from it.
- ``graph + recorder``: the same with the launcher's bag recorder (ros_ws/src/ship_mission/ship_mission/recorder.py,
  MCAP, every topic), as ``make demo`` records: lossless, the simulator waits for the
  recorder's acknowledgements (vessel_node ``lockstep_record_topic``).
- ``graph + recorder, no handshake``: the recorder without that handshake (as before it
  existed; it may lose messages on a loaded machine). Goal: the handshake costs at most 20 %
  of the real-time factor (GOAL_RECORDER_RATIO).
- ``graph, no /clock subscribers`` (diagnostic): the graph with use_sim_time false on route,
  guidance and autopilot, so nobody follows the /clock the vessel publishes every step (those
  nodes time everything from odom stamps and have no timers; see NO_CLOCK_PARAMS): the cost of
  the /clock fan-out that doc/design.md's "every node runs with use_sim_time" implies.
- ``relay floor``: three relay processes (scripts/benchmarks/relay_nodes.py) with empty
  callbacks: odom (Odometry) -> heading_cmd (Float64) -> rudder_cmd (Float64) -> next odom,
  the same QoS (ship_sim.ros.qos.STREAM), executor and main loop (ship_sim.ros.run.run_node),
  start rule and number of steps, subscriptions raw (nothing deserialised: an empty callback
  needs no content). What rclpy + Fast DDS cost per round trip on this machine.
- ``relay, deserialising``: the same relay with ordinary subscriptions (rclpy turns every
  message into Python objects before the empty callback), for comparison.

Figures:
- stepping time: wall time from publishing step 0 to publishing the last step (step N, after N
  round trips). For the graph from the timestamps of the vessel node's own log lines ("lockstep:
  publishing step 0" and "max_steps N reached", system clock); for the relay from the sim
  relay's own monotonic clock. Start-up (first process started -> step 0 published) is reported
  apart: it is mostly Python imports, DDS discovery and the vessel node's start grace.
- real-time factor = sim time / stepping time (goal >= GOAL_RTF without recorder);
  us/step = stepping time / N; floor ratio = stepping time / the raw relay's stepping time
  (goal < GOAL_FLOOR_RATIO).
- CPU of each process over the stepping phase (utime + stime from /proc, read when step 0 is
  seen in the log and when the stepping process has ended), in microseconds per step: which
  process costs what; on a shared 2-core machine the wall time follows the CPU per step.
- lockstep timeouts from the vessel node's end summary (must be 0: else a step was held for
  ``lockstep_timeout`` and the numbers mean nothing).

Each configuration runs REPEATS times (``--quick``: once, QUICK_SIM_TIME_S of sim time),
interleaved (graph, graph + recorder, diagnostic, floor, deserialising relay per repeat), so
slow phases of a shared machine hit them alike; the best repeat of each is reported and the
floor ratio uses the best of both.
"""
import functools
import json
import os
import re
import shutil
import sys
import time
from pathlib import Path

from ship_mission.processes import INSTALL, ProcessGroup, executable, install_env

from . import common

SCENARIO = common.REPO / 'scenarios' / 'flagship_mariner.yaml'
RELAY = Path(__file__).resolve().parent / 'relay_nodes.py'
RUN_DIR = common.REPO / 'bench' / 'results' / 'lockstep'
SIM_TIME_S = 1000.0
QUICK_SIM_TIME_S = 200.0
REPEATS = 2
GOAL_RTF = 50.0
GOAL_RECORDER_RATIO = 0.8
NO_HANDSHAKE = 'graph + recorder, no handshake'
GOAL_FLOOR_RATIO = 1.5
START_TIMEOUT_S = 60.0
POLL_S = 0.01
#: Diagnostic row: the graph with route, guidance and autopilot off sim time, so that /clock
#: (published every step) has no subscriber. Guidance and autopilot take their times from odom
#: stamps and have no timers, so the loop behaves the same (only the route's header stamp,
#: which nothing in the loop reads, becomes wall time); the row measures the /clock fan-out.
NO_CLOCK = 'graph, no /clock subscribers'
NO_CLOCK_PARAMS = {exe: {'use_sim_time': False}
                   for exe in ('route_node', 'guidance_node', 'autopilot_node')}

_LOG_TIME = re.compile(r'^\[\w+\] \[(?P<t>\d+\.\d+)\] \[[^\]]*\]: (?P<msg>.*)$', re.M)
_TIMEOUTS = re.compile(r'(?P<n>\d+) lockstep timeouts')


def proc_stat(pid):
    """(state letter, utime + stime in s) of a process from /proc, or (None, None) once reaped.

    A process that has exited but not been waited for is a zombie ('Z') whose CPU times are
    still there: the bench reads them before it reaps the process.
    """
    try:
        fields = Path(f'/proc/{pid}/stat').read_text().rsplit(')', 1)[1].split()
    except OSError:
        return None, None
    return fields[0], (int(fields[11]) + int(fields[12])) / os.sysconf('SC_CLK_TCK')


def _cpu_snapshot(group):
    return {p.label: proc_stat(p.popen.pid)[1] for p in group.procs}


def _wait_for(pred, timeout, procs, what):
    """Poll ``pred()`` until true; fail if a process has exited (zombie) or on timeout."""
    deadline = time.monotonic() + timeout
    while not pred():
        for p in procs:
            state, _ = proc_stat(p.popen.pid)
            if state in ('Z', None):
                p.popen.poll()
                raise RuntimeError(f'{p.label} exited (code {p.popen.returncode}) while waiting '
                                   f'for {what}; log {p.log_path}:\n' + p.output()[-1500:])
        if time.monotonic() > deadline:
            raise RuntimeError(f'no {what} within {timeout:.0f} s')
        time.sleep(POLL_S)


def _finish_group(group, stepper, step0_seen, stepping_timeout):
    """Wait until ``stepper`` has ended by itself; CPU per process over the stepping phase."""
    others = [p for p in group.procs if p is not stepper]
    _wait_for(step0_seen, START_TIMEOUT_S, group.procs, 'step 0')
    cpu0 = _cpu_snapshot(group)
    _wait_for(lambda: proc_stat(stepper.popen.pid)[0] in ('Z', None), stepping_timeout,
              others, f'the end of the run of {stepper.label}')
    cpu1 = _cpu_snapshot(group)
    stepper.popen.wait()
    return {label: (cpu1[label] - cpu0[label]) if None not in (cpu0[label], cpu1[label])
            else None for label in cpu0}


def _folder(label):
    return re.sub(r'[^\w+-]+', '_', label).strip('_')


@functools.lru_cache(maxsize=None)
def _domain_id():
    """A ROS_DOMAIN_ID for this bench process, leased the way the launcher leases one for a
    run (a lock per id, held until the process ends), so no other run or test shares it; the
    runs of the bench use it one after the other, each in its own namespace."""
    try:
        from ship_mission.domain import lease_domain_id
    except ImportError:  # a launcher without leases: a domain from the pid
        return 80 + os.getpid() % 20
    return lease_domain_id()


def graph_run(steps, record, label, log_root, overrides=None, install=INSTALL, handshake=True,
              display=False, live=None):
    """The flagship graph in lockstep for ``steps`` steps; figures from the vessel node's log.
    ``overrides``: {executable: {parameter: value}} on top of the launcher's parameters;
    ``install``: the colcon install tree to run (A/B comparisons of two builds);
    ``handshake``: with ``record``, the recorder's lockstep acknowledgements (False: the
    simulator does not wait for the recorder, which may then lose messages);
    ``display``: also the vessel's nav_display_node, as the launcher starts it;
    ``live``: also the live view (scripts/live_view.py, as ``--live`` starts it), None: not;
    'idle': no client; 'client': a Foxglove protocol client subscribed to every topic (in this
    process, ship_mission.foxglove_client)."""
    from ship_mission.launcher import (DISPLAY_NODE, LIVE_VIEW, NODES, RECORDER, display_every,
                                  display_parameters, node_parameters, record_ack_arg,
                                  write_params)
    from ship_mission.scenario import load_scenario
    scenario = load_scenario(SCENARIO)
    scenario.stepping = 'lockstep'
    scenario.duration_s = steps * scenario.dt_s
    spec = scenario.vessels[0]
    ns = f'bench_{os.getpid()}'
    run = log_root / _folder(label)
    (run / 'params').mkdir(parents=True, exist_ok=True)
    params, _plan = node_parameters(scenario, spec, 0, record)
    for exe, extra in (overrides or {}).items():
        params[exe].update(extra)
    if not handshake:
        params['vessel_node']['lockstep_record_topic'] = ''
    nodes = NODES
    if display:
        params[DISPLAY_NODE[0]] = display_parameters(scenario, spec)
        params['vessel_node']['display_every'] = display_every(scenario)
        nodes = NODES + (DISPLAY_NODE,)
    client = None
    group = ProcessGroup(install_env(domain_id=_domain_id(), install=install), run / 'logs')
    t_start = time.time()
    out = {'config': label, 'steps': steps, 'sim_time_s': steps * scenario.dt_s}
    try:
        for exe, pkg in nodes + (('vessel_node', 'ship_sim'),):
            if exe == 'vessel_node' and record:
                group.start_argv('recorder', [sys.executable, RECORDER, run / 'bag',
                                              '--time-source', 'sim', '--exclude',
                                              r'^/(rosout|parameter_events)$',
                                              *(record_ack_arg(ns, True) if handshake else [])])
            if exe == 'vessel_node' and live:
                port = _free_port()
                view = group.start_argv('live_view', [sys.executable, LIVE_VIEW, '--port',
                                                      str(port), '--wait-ready', f'/{ns}/ready'])
                _wait_for(lambda: 'live view: ws://' in view.output(), START_TIMEOUT_S, [view],
                          'the live view')
                if live == 'client':
                    from ship_mission.foxglove_client import FoxgloveClient
                    client = FoxgloveClient(f'ws://127.0.0.1:{port}')
            f = write_params(run, ns, exe, params[exe])
            group.start_argv(f'{ns}/{exe}', [executable(pkg, exe, install), '--ros-args', '-r',
                                             f'__ns:=/{ns}', '--params-file', f])
        vessel = group.procs[-1]
        cpu = _finish_group(group, vessel, lambda: 'publishing step 0' in vessel.output(),
                            stepping_timeout=max(120.0, steps * 0.05))
    finally:
        codes = group.stop()
        if client is not None:
            client.close()
    log = vessel.log_path.read_text(errors='replace')
    times = {m['msg']: float(m['t']) for m in _LOG_TIME.finditer(log)}
    t0 = next((t for msg, t in times.items() if msg.startswith('lockstep: publishing step 0')),
              None)
    t1 = next((t for msg, t in times.items() if msg.startswith(f'max_steps {steps} reached')),
              None)
    if t0 is None or t1 is None or codes.get(vessel.label) != 0:
        raise RuntimeError(f'{label}: vessel node did not complete {steps} steps (exit codes '
                           f'{codes}); log {vessel.log_path}:\n' + log[-1500:])
    if record:  # the bag (~1 MB per 1000 steps) is not needed for the timings
        shutil.rmtree(run / 'bag', ignore_errors=True)
    m = _TIMEOUTS.search(log)
    out.update(startup_s=t0 - t_start, stepping_s=t1 - t0, exit_codes=codes,
               load_1min=os.getloadavg()[0],
               lockstep_timeouts=int(m['n']) if m else None, log=str(vessel.log_path))
    out['cpu_s'] = cpu
    if client is not None:
        out['client_messages'] = sum(len(v) for v in client.messages.values())
        out['client_error'] = client.error
    return out


def _free_port():
    import socket
    with socket.socket() as s:
        s.bind(('127.0.0.1', 0))
        return s.getsockname()[1]


def relay_run(steps, log_root, raw=True, install=INSTALL):
    """The bare three-hop relay for ``steps`` round trips; figures from the sim relay."""
    ns = f'/relay_{os.getpid()}'
    label = 'relay floor' if raw else 'relay, deserialising'
    group = ProcessGroup(install_env(domain_id=_domain_id(), install=install),
                         log_root / _folder(label) / 'logs')
    t_start = time.time()
    try:
        for role in ('guidance', 'autopilot', 'sim'):
            group.start_argv(f'relay_{role}', [sys.executable, RELAY, role, '--steps', steps]
                             + (['--raw'] if raw else [])
                             + ['--ros-args', '-r', f'__ns:={ns}'])
        sim = group.procs[-1]
        cpu = _finish_group(group, sim, lambda: 'RELAY_STEP0' in sim.output(),
                            stepping_timeout=max(120.0, steps * 0.05))
    finally:
        codes = group.stop()
    log = sim.log_path.read_text(errors='replace')
    line = next((ln for ln in log.splitlines() if ln.startswith('RELAY_RESULT ')), None)
    if line is None or codes.get(sim.label) != 0:
        raise RuntimeError(f'relay did not complete {steps} steps (exit codes {codes}); log '
                           f'{sim.log_path}:\n' + log[-1500:])
    res = json.loads(line.split(' ', 1)[1])
    return {'config': label, 'steps': res['steps'], 'sim_time_s': res['steps'] * 0.1,
            'startup_s': res['t_step0_unix'] - t_start, 'stepping_s': res['stepping_s'],
            'exit_codes': codes, 'lockstep_timeouts': 0, 'cpu_s': cpu,
            'load_1min': os.getloadavg()[0]}


def _row(r):
    wall, n = r['stepping_s'], r['steps']
    row = {k: r[k] for k in ('config', 'steps', 'startup_s', 'stepping_s', 'lockstep_timeouts',
                             'load_1min')}
    row['us_per_step'] = wall / n * 1e6
    row['rtf'] = r['sim_time_s'] / wall
    # CPU microseconds per step of each process (None where /proc had nothing).
    roles = {'sim': ('vessel_node', 'relay_sim'), 'guidance': ('guidance_node', 'relay_guidance'),
             'autopilot': ('autopilot_node', 'relay_autopilot')}
    cpu = {k: v for k, v in (r.get('cpu_s') or {}).items() if v is not None}
    for role, names in roles.items():
        us = [v / n * 1e6 for k, v in cpu.items() if k.endswith(names)]
        row[f'cpu_{role}'] = us[0] if us else None
    row['cpu_other'] = sum(v for k, v in cpu.items()
                           if not k.endswith(sum(roles.values(), ()))) / n * 1e6
    row['cpu_total'] = sum(cpu.values()) / n * 1e6
    return row


def run(quick=False):
    sim_time = QUICK_SIM_TIME_S if quick else SIM_TIME_S
    steps = int(round(sim_time / 0.1))
    repeats = 1 if quick else REPEATS
    log_root = RUN_DIR / time.strftime('%Y%m%d-%H%M%S')
    configs = {
        'graph': lambda d: graph_run(steps, False, 'graph', d),
        'graph + recorder': lambda d: graph_run(steps, True, 'graph + recorder', d),
        NO_HANDSHAKE: lambda d: graph_run(steps, True, NO_HANDSHAKE, d, handshake=False),
        NO_CLOCK: lambda d: graph_run(steps, False, NO_CLOCK, d, overrides=NO_CLOCK_PARAMS),
        'relay floor': lambda d: relay_run(steps, d, raw=True),
        'relay, deserialising': lambda d: relay_run(steps, d, raw=False),
    }
    results = {k: [] for k in configs}
    for i in range(repeats):
        for key, fn in configs.items():
            results[key].append(fn(log_root / f'r{i}'))
    best = {k: min(v, key=lambda r: r['stepping_s']) for k, v in results.items()}
    floor = best['relay floor']['stepping_s']
    floor_cpu = min(_row(r)['cpu_total'] for r in results['relay floor'])
    rows = []
    for key in configs:
        row = _row(best[key])
        row['floor_ratio'] = best[key]['stepping_s'] / floor
        # CPU per step is much less disturbed by other load than wall time (best repeats).
        row['cpu_floor_ratio'] = min(_row(r)['cpu_total'] for r in results[key]) / floor_cpu
        walls = [r['stepping_s'] for r in results[key]]
        row['spread'] = max(walls) / min(walls)
        rows.append(row)
    g = rows[0]
    rec = next(r for r in rows if r['config'] == 'graph + recorder')
    loose = next(r for r in rows if r['config'] == NO_HANDSHAKE)
    walls = '; '.join(k + ' ' + ', '.join(f"{r['stepping_s']:.2f}" for r in v)
                      for k, v in results.items())
    notes = [f'{steps} steps ({sim_time:g} s sim), best of {repeats} repeat(s) per row; '
             f'all stepping times (s): {walls}',
             'CPU = CPU microseconds per step of each process over the stepping phase (sim = '
             'vessel_node or the sim relay; other = route_node and the recorder); on 2 cores '
             'the graph is bound by its CPU per step once the machine is busy',
             'relay floor: empty callbacks on raw (serialized) messages, the minimum rclpy + '
             'Fast DDS need; "deserialising": the same relay letting rclpy build the message '
             'objects (the guidance and autopilot nodes read odom raw, see '
             'ship_sim.ros.conversions)',
             'x floor = best stepping time / best floor stepping time (the goal); CPU x floor = '
             'best CPU per step / best floor CPU per step; spread = slowest / fastest repeat '
             '(well above 1: other load on the machine set the wall times); load = 1-minute '
             'load average when the row\'s best run ended',
             f'logs under {log_root}']
    bad = [r['config'] for r in rows if r['lockstep_timeouts']]
    if bad:
        notes.insert(0, f'lockstep timeouts in {bad}: those numbers include held steps')
    return {
        'title': f'flagship graph in lockstep, {sim_time:g} s sim at 10 Hz, vs a bare 3-hop '
                 'relay (stepping phase only)',
        'columns': [['config', 'config'], ['steps', 'steps'], ['startup_s', 'start-up s'],
                    ['stepping_s', 'stepping s'], ['us_per_step', 'us/step'],
                    ['rtf', 'RT factor'], ['floor_ratio', 'x floor'],
                    ['cpu_floor_ratio', 'CPU x floor'], ['spread', 'spread'],
                    ['load_1min', 'load'],
                    ['cpu_sim', 'CPU sim'], ['cpu_guidance', 'CPU guid'],
                    ['cpu_autopilot', 'CPU ap'], ['cpu_other', 'CPU other'],
                    ['cpu_total', 'CPU total'], ['lockstep_timeouts', 'timeouts']],
        'rows': rows,
        'goals': [common.goal('real-time factor, no recorder', g['rtf'], GOAL_RTF, 'x',
                              below=False),
                  common.goal('stepping time / relay floor', g['floor_ratio'],
                              GOAL_FLOOR_RATIO, 'x'),
                  # the lossless recorder handshake may cost at most 20 % of the rate
                  common.goal('RT factor with the recorder handshake / without', rec['rtf'] / loose['rtf'],
                              GOAL_RECORDER_RATIO, '', below=False)],
        'notes': notes, 'runs': results,
        'failed': bool(bad),
    }
