"""Section ``realtime_latency``: odom -> rudder_cmd latency of the flagship graph in realtime.

The flagship scenario's four nodes (scenarios/flagship_mariner.yaml, parameters from
ship_mission.launcher.node_parameters, stepping_mode realtime x1, 10 Hz, autopilot pairing
'latest': one rudder_cmd per odom) run from the colcon install tree in an own ROS_DOMAIN_ID and
namespace, no recorder. This process subscribes to ``odom`` and ``rudder_cmd`` (QoS
ship_sim.ros.qos.STREAM, SingleThreadedExecutor: rclpy's EventsExecutor cannot hand over the
message info) and, after a warm-up of WARMUP_S, records every message with its DDS message info
for DURATION_S (``--quick``: QUICK_DURATION_S).

Latency: each rudder_cmd is paired with the odom it answers by DDS publication sequence numbers
(the autopilot answers every odom in order, so answer s belongs to odom s + c, c found as the
usual offset to the latest odom published before each answer; see ``match_latencies``), and
timed with the DDS source timestamps, written by the publishers from the system clock of this
one machine, so neither depends on when this process gets to read the messages:
- ``pub``: rudder_cmd source timestamp - odom source timestamp, from the vessel node publishing
  the odom to the autopilot publishing its answer (one transport hop + the autopilot's work);
  the goal (p99 < GOAL_P99_MS) is judged on this;
- ``arrival``: the same pair's receive timestamps in this process (what a node downstream
  would see; adds this process' own reading delays).
An odom inside the window that never got its answer is "unanswered" (a skipped control step).

Missed steps: gaps in the odom header stamps (a gap of k periods = k - 1 missed steps), as in
the ``node_jitter`` section, plus the count received against the window's length. Also: CPU of
each node over the window (% of one core) and the vessel node's own pacing summary (lateness of
its publications behind the wall-clock schedule, logged at shutdown).
"""
import bisect
import collections
import os
import time

from ship_mission.processes import INSTALL, ProcessGroup, executable, install_env

from . import common
from .lockstep import SCENARIO, _domain_id, proc_stat
from .node_jitter import _percentile, node_pacing, stream_stats

DURATION_S = 600.0
QUICK_DURATION_S = 30.0
WARMUP_S = 3.0
START_TIMEOUT_S = 60.0
GOAL_P99_MS = 5.0
RUN_DIR = common.REPO / 'bench' / 'results' / 'realtime_latency'


def match_latencies(odoms, rudders):
    """Pair each rudder_cmd with the odom it answers, by DDS publication sequence numbers.

    odoms, rudders: lists of (source_ns, received_ns, publication_sequence_number) sorted by
    source time. With 'latest' pairing the autopilot answers every odom it gets, in order, so
    rudder_cmd number s answers odom number s + c for one constant c; c is the most common
    offset between each rudder_cmd and the latest odom published before it (that rule alone
    misattributes answers when the vessel node catches up with a burst of steps). Returns
    (pub latencies ms, arrival latencies ms, unanswered odoms, offset c). Unanswered: odoms
    between the first and the last answered one whose answer never came (a skipped step).
    """
    src = [o[0] for o in odoms]
    offsets = collections.Counter()
    for r_src, _, r_seq in rudders:
        i = bisect.bisect_right(src, r_src) - 1
        if i >= 0:
            offsets[odoms[i][2] - r_seq] += 1
    if not offsets:
        return [], [], 0, None
    c = offsets.most_common(1)[0][0]
    by_seq = {o[2]: o for o in odoms}
    pub, arr, answered = [], [], set()
    for r_src, r_recv, r_seq in rudders:
        o = by_seq.get(r_seq + c)
        if o is None:
            continue  # answers an odom from before the window
        answered.add(o[2])
        pub.append((r_src - o[0]) * 1e-6)
        arr.append((r_recv - o[1]) * 1e-6)
    lo, hi = min(answered), max(answered)
    unanswered = sum(1 for q in by_seq if lo < q < hi and q not in answered)
    return pub, arr, unanswered, c


def run(quick=False):
    return measure(QUICK_DURATION_S if quick else DURATION_S)


def measure(window, install=INSTALL):
    """Run the graph from ``install`` for a ``window`` (s) after the warm-up: the section."""
    import rclpy
    from nav_msgs.msg import Odometry
    from rclpy.executors import SingleThreadedExecutor
    from std_msgs.msg import Float64
    from ship_mission.launcher import NODES, node_parameters, write_params
    from ship_mission.scenario import load_scenario
    from ship_sim.ros.qos import STREAM

    scenario = load_scenario(SCENARIO)
    scenario.stepping = 'realtime'
    scenario.speedup = 1.0
    scenario.duration_s = WARMUP_S + window + 60.0  # the run is stopped after the window
    spec = scenario.vessels[0]
    rate = 1.0 / scenario.dt_s
    params, _plan = node_parameters(scenario, spec, 0, False)
    domain, ns = _domain_id(), f'bench_rt_{os.getpid()}'
    run_dir = RUN_DIR / time.strftime('%Y%m%d-%H%M%S')
    (run_dir / 'params').mkdir(parents=True, exist_ok=True)
    group = ProcessGroup(install_env(domain_id=domain, install=install), run_dir / 'logs')

    odoms, rudders, stamps, arrivals = [], [], [], []
    state = {'recording': False, 'first': None}

    def on_odom(msg, info):
        if state['recording']:
            odoms.append((info['source_timestamp'], info['received_timestamp'],
                          info['publication_sequence_number']))
            s = msg.header.stamp
            stamps.append(s.sec * 1_000_000_000 + s.nanosec)
            arrivals.append(time.perf_counter())
        elif state['first'] is None:
            state['first'] = time.monotonic()

    def on_rudder(msg, info):
        if state['recording']:
            rudders.append((info['source_timestamp'], info['received_timestamp'],
                            info['publication_sequence_number']))

    os.environ['ROS_AUTOMATIC_DISCOVERY_RANGE'] = 'LOCALHOST'
    context = rclpy.Context()
    rclpy.init(context=context, domain_id=domain)
    node = rclpy.create_node('bench_latency_listener', context=context)
    node.create_subscription(Odometry, f'/{ns}/odom', on_odom, STREAM)
    node.create_subscription(Float64, f'/{ns}/rudder_cmd', on_rudder, STREAM)
    executor = SingleThreadedExecutor(context=context)
    executor.add_node(node)

    def spin_for(seconds):
        end = time.monotonic() + seconds
        while (left := end - time.monotonic()) > 0:
            executor.spin_once(timeout_sec=min(left, 0.1))

    out = {}
    try:
        for exe, pkg in NODES + (('vessel_node', 'ship_sim'),):
            f = write_params(run_dir, ns, exe, params[exe])
            group.start_argv(f'{ns}/{exe}', [executable(pkg, exe, install), '--ros-args', '-r',
                                             f'__ns:=/{ns}', '--params-file', f])
        vessel = group.procs[-1]
        deadline = time.monotonic() + START_TIMEOUT_S
        while state['first'] is None:
            dead = group.failed()
            if dead or time.monotonic() > deadline:
                why = (f'{dead[0].label} exited with code {dead[0].returncode}' if dead
                       else f'no odom within {START_TIMEOUT_S:.0f} s')
                raise RuntimeError(f'{why}; logs in {run_dir / "logs"}')
            executor.spin_once(timeout_sec=0.1)
        spin_for(WARMUP_S)
        cpu0 = {p.label: proc_stat(p.popen.pid)[1] for p in group.procs}
        t0 = time.monotonic()
        state['recording'] = True
        spin_for(window)
        state['recording'] = False
        t1 = time.monotonic()
        cpu1 = {p.label: proc_stat(p.popen.pid)[1] for p in group.procs}
        dead = group.failed()
        if dead:
            raise RuntimeError(f'{dead[0].label} exited during the window with code '
                               f'{dead[0].returncode}; log {dead[0].log_path}')
    finally:
        executor.shutdown()
        node.destroy_node()
        rclpy.try_shutdown(context=context)
        codes = group.stop()
    if len(odoms) < 3 or not rudders:
        raise RuntimeError(f'only {len(odoms)} odom and {len(rudders)} rudder_cmd messages in '
                           f'{window:g} s; logs in {run_dir / "logs"}')
    odoms.sort()
    rudders.sort()
    pub, arr, unanswered, offset = match_latencies(odoms, rudders)
    if not pub:
        raise RuntimeError('no rudder_cmd could be paired with an odom')
    jitter = stream_stats(arrivals, stamps, rate)
    cpu = {lbl.split('/')[-1]: 100.0 * (cpu1[lbl] - cpu0[lbl]) / (t1 - t0)
           for lbl in cpu0 if None not in (cpu0[lbl], cpu1[lbl])}
    out.update(node_pacing(vessel.log_path.read_text(errors='replace')))
    row = {'window_s': window, 'odom': len(odoms), 'rudder_cmd': len(rudders),
           'expected': jitter['expected'], 'missed_steps': jitter['missed_steps'],
           'unanswered': unanswered, 'seq_offset': offset,
           'pub_p50_ms': _percentile(pub, 50), 'pub_p99_ms': _percentile(pub, 99),
           'pub_max_ms': max(pub), 'arr_p50_ms': _percentile(arr, 50),
           'arr_p99_ms': _percentile(arr, 99), 'arr_max_ms': max(arr),
           'cpu_vessel': cpu.get('vessel_node'), 'cpu_guidance': cpu.get('guidance_node'),
           'cpu_autopilot': cpu.get('autopilot_node'),
           'node_late_max_ms': out.get('node_lateness_max_ms')}
    bad = {k: v for k, v in codes.items() if v not in (0, None)}
    notes = ['pub = rudder_cmd publish time - odom publish time (DDS source timestamps); '
             'arrival = the same at this subscriber; pairs by DDS publication sequence number '
             f'(rudder_cmd s answers odom s + {offset}); unanswered = odoms whose answer never '
             'came',
             'missed = odom header-stamp gaps (a gap of k periods = k - 1 missed steps); '
             'CPU % of one core over the window; node late max = worst lateness of a vessel '
             'publication behind its wall-clock slot (its own shutdown summary, whole run)',
             f'logs in {run_dir / "logs"}']
    if bad:
        notes.append(f'exit codes after SIGINT: {bad}')
    return {
        'title': f'flagship graph in realtime at {rate:g} Hz, {window:g} s window: odom -> '
                 'rudder_cmd latency (ms)',
        'columns': [['window_s', 'window s'], ['odom', 'odom'], ['rudder_cmd', 'rudder_cmd'],
                    ['expected', 'expected'], ['missed_steps', 'missed'],
                    ['unanswered', 'unanswered'], ['pub_p50_ms', 'pub p50'],
                    ['pub_p99_ms', 'pub p99'], ['pub_max_ms', 'pub max'],
                    ['arr_p50_ms', 'arr p50'], ['arr_p99_ms', 'arr p99'],
                    ['arr_max_ms', 'arr max'], ['cpu_vessel', 'CPU% sim'],
                    ['cpu_guidance', 'CPU% guid'], ['cpu_autopilot', 'CPU% ap'],
                    ['node_late_max_ms', 'sim late max']],
        'rows': [row],
        'goals': [common.goal('odom -> rudder_cmd latency p99 (publish to publish)',
                              row['pub_p99_ms'], GOAL_P99_MS, 'ms'),
                  common.goal('missed steps (odom stamp gaps)', row['missed_steps'], 1, 'steps'),
                  common.goal('unanswered odoms', row['unanswered'], 1, 'msgs')],
        'notes': notes, 'latencies_pub_ms': pub, 'exit_codes': codes, 'jitter': jitter,
        'cpu_pct': cpu,
    }
