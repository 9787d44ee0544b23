"""Section ``node_jitter``: timing regularity of odom from a realtime ``vessel_node`` process.

The installed ``vessel_node`` (colcon install tree, run the way ``ros2 run`` runs it, via
``ship_mission.processes``) is started alone in its own ROS_DOMAIN_ID and a unique namespace with
ROS_AUTOMATIC_DISCOVERY_RANGE=LOCALHOST, in realtime mode at 10 Hz and at 50 Hz odom rate. This
process subscribes to its odom (QoS ship_sim.ros.qos.STREAM, as every subscriber does) and,
after a warm-up, records for ``DURATION_S`` (``--quick``: ``QUICK_DURATION_S``):

- wall clock: the arrival time of every message (time.perf_counter in the callback). Period
  statistics (mean, std) and the deviation of each inter-arrival period from the nominal one
  1/rate (p50, p99, max of |period - 1/rate|), in milliseconds. This is what a subscriber sees:
  the node's timer jitter plus the transport and the receiving executor.
- schedule drift: wall elapsed minus sim elapsed since the first message (the publication's
  lag behind an ideal clock); its spread (max - min) in ms and the realtime factor
  sim elapsed / wall elapsed.
- sim time: the header stamps. Increments that differ from 1/rate by more than 1 us ("odd
  stamps"; 0 for a perfectly regular stream), their std, non-increasing stamps, and missed
  steps = sum over gaps of round(gap / period) - 1 (a gap of 2 periods = 1 missed
  publication). Received count vs expected (window * rate).
- CPU use of the node process over the window (utime + stime from /proc, percent of one core).
- the node's own view, from the pacing summary it logs at shutdown (whole run, warm-up
  included): lateness of each publication behind its wall-clock slot (mean, sd, max) and the
  sd of its publish intervals. Subscriber-side minus node-side spread = transport + receiver.

The node is always stopped (try/finally, ProcessGroup.stop: SIGINT, SIGTERM, SIGKILL) and its
exit code and log path are recorded.
"""
import math
import os
import re
import statistics
import time
from pathlib import Path

from ship_mission.processes import ProcessGroup, install_env, ros_args

from . import common

RATES_HZ = (10.0, 50.0)
DURATION_S = 20.0
QUICK_DURATION_S = 5.0
WARMUP_S = 1.0
START_TIMEOUT_S = 30.0
MODEL = 'mariner'
LOG_DIR = common.REPO / 'bench' / 'results' / 'logs'


# The node's own pacing summary, logged at shutdown (ship_sim.vessel_node.destroy_node).
_PACING = re.compile(r'lateness mean (?P<mean>[-\d.]+) ms, sd (?P<sd>[-\d.]+) ms, '
                     r'max (?P<max>[-\d.]+) ms; interval mean (?P<imean>[-\d.]+) ms '
                     r'\(nominal [-\d.]+\), sd (?P<isd>[-\d.]+) ms')


def node_params(rate):
    """ship_sim.vessel_node parameters: realtime x1, one integration step (dt) per publish."""
    return {'model': MODEL, 'stepping_mode': 'realtime', 'speedup': 1.0,
            'publish_rate': float(rate), 'dt': 1.0 / rate}


def node_pacing(log_text):
    """The node's own pacing figures (ms) from its shutdown summary; {} if it has none."""
    m = _PACING.search(log_text)
    if not m:
        return {}
    return {'node_lateness_mean_ms': float(m['mean']), 'node_lateness_sd_ms': float(m['sd']),
            'node_lateness_max_ms': float(m['max']), 'node_interval_sd_ms': float(m['isd'])}


def _domain_id():
    # Own domain per bench process (other tests may run at the same time); the namespace is
    # unique too, so even a shared domain would not mix streams.
    return 60 + os.getpid() % 40


def _cpu_seconds(pid):
    """utime + stime (s) of a process and its threads, from /proc/<pid>/stat; None if gone."""
    try:
        fields = Path(f'/proc/{pid}/stat').read_text().rsplit(')', 1)[1].split()
    except OSError:
        return None
    return (int(fields[11]) + int(fields[12])) / os.sysconf('SC_CLK_TCK')


def _percentile(values, q):
    s = sorted(values)
    if not s:
        return math.nan
    k = (len(s) - 1) * q / 100.0
    lo, hi = math.floor(k), math.ceil(k)
    return s[lo] + (s[hi] - s[lo]) * (k - lo)


def stream_stats(wall_s, stamps_ns, rate):
    """Jitter figures from arrival times (s) and header stamps (ns) of one odom stream."""
    period = 1.0 / rate
    period_ns = round(period * 1e9)
    d_wall = [b - a for a, b in zip(wall_s, wall_s[1:])]
    dev_ms = [abs(d - period) * 1e3 for d in d_wall]
    d_sim = [b - a for a, b in zip(stamps_ns, stamps_ns[1:])]
    missed = sum(max(0, round(d / period_ns) - 1) for d in d_sim if d > 0)
    drift_ms = [((w - wall_s[0]) - (s - stamps_ns[0]) * 1e-9) * 1e3
                for w, s in zip(wall_s, stamps_ns)]
    wall_span = wall_s[-1] - wall_s[0]
    sim_span = (stamps_ns[-1] - stamps_ns[0]) * 1e-9
    return {
        'rate_hz': int(rate) if float(rate).is_integer() else rate,
        'received': len(wall_s),
        'expected': int(round(wall_span * rate)) + 1,
        'period_mean_ms': statistics.fmean(d_wall) * 1e3,
        'period_std_ms': statistics.pstdev(d_wall) * 1e3,
        'dev_p50_ms': _percentile(dev_ms, 50),
        'dev_p99_ms': _percentile(dev_ms, 99),
        'dev_max_ms': max(dev_ms),
        'drift_spread_ms': max(drift_ms) - min(drift_ms),
        'realtime_factor': sim_span / wall_span if wall_span > 0 else math.nan,
        'sim_dt_mean_ms': statistics.fmean(d_sim) * 1e-6,
        'sim_dt_std_ms': statistics.pstdev(d_sim) * 1e-6,
        # Stamps are rounded to the ns: allow 1 us before calling an increment irregular.
        'sim_dt_irregular': sum(1 for d in d_sim if abs(d - period_ns) > 1000),
        'sim_nonincreasing': sum(1 for d in d_sim if d <= 0),
        'missed_steps': missed,
    }


def measure(rate, duration, rclpy_mods):
    """Start a vessel_node at ``rate`` Hz, record its odom for ``duration`` s, stop it."""
    rclpy, Odometry, qos = rclpy_mods
    domain = _domain_id()
    ns = f'/bench_{os.getpid()}_{int(rate)}hz'
    env = install_env(domain_id=domain)
    group = ProcessGroup(env, LOG_DIR)
    context = rclpy.Context()
    node = executor = None
    wall, stamps = [], []
    first = [None]          # wall time of the first message (start-up done)
    recording = [False]
    clock = time.perf_counter
    out = {'namespace': ns, 'domain_id': domain, 'params': node_params(rate)}

    def on_odom(msg):
        if recording[0]:
            wall.append(clock())
            stamps.append(msg.header.stamp.sec * 1_000_000_000 + msg.header.stamp.nanosec)
        elif first[0] is None:
            first[0] = clock()

    try:
        proc = group.start(f'vessel_node_{int(rate)}hz', 'ship_sim', 'vessel_node',
                           ros_args(namespace=ns, params=node_params(rate)))
        out['log'] = str(proc.log_path)
        # The subscriber must discover the same way as the node (same env variables).
        os.environ['ROS_AUTOMATIC_DISCOVERY_RANGE'] = 'LOCALHOST'
        rclpy.init(context=context, domain_id=domain)
        node = rclpy.create_node('bench_odom_listener', context=context)
        node.create_subscription(Odometry, f'{ns}/odom', on_odom, qos)
        from rclpy.experimental import EventsExecutor
        executor = EventsExecutor(context=context)
        executor.add_node(node)

        deadline = time.monotonic() + START_TIMEOUT_S
        while first[0] is None:
            if proc.returncode is not None or time.monotonic() > deadline:
                why = (f'exited with code {proc.returncode}' if proc.returncode is not None
                       else f'sent no odom within {START_TIMEOUT_S} s')
                raise RuntimeError(f'vessel_node {why}; log {proc.log_path}:\n'
                                   + proc.output()[-2000:])
            executor.spin_once(timeout_sec=0.1)
        _spin_for(executor, WARMUP_S)
        cpu0, t0 = _cpu_seconds(proc.popen.pid), time.monotonic()
        recording[0] = True
        _spin_for(executor, duration)
        recording[0] = False
        cpu1, t1 = _cpu_seconds(proc.popen.pid), time.monotonic()
        if proc.returncode is not None:
            raise RuntimeError(f'vessel_node exited during the run with code {proc.returncode}')
        if len(wall) < 3:
            raise RuntimeError(f'only {len(wall)} odom messages in {duration} s')
        out.update(stream_stats(wall, stamps, rate))
        if cpu0 is not None and cpu1 is not None:
            out['node_cpu_pct'] = 100.0 * (cpu1 - cpu0) / (t1 - t0)
    finally:
        if executor is not None:
            executor.shutdown()
        if node is not None:
            node.destroy_node()
        rclpy.try_shutdown(context=context)
        out['exit_codes'] = group.stop()
        if out.get('log'):
            out.update(node_pacing(Path(out['log']).read_text(errors='replace')))
    return out


def _spin_for(executor, seconds):
    end = time.monotonic() + seconds
    while (left := end - time.monotonic()) > 0:
        executor.spin_once(timeout_sec=min(left, 0.1))


def run(quick=False):
    import rclpy
    from nav_msgs.msg import Odometry
    from ship_sim.ros.qos import STREAM as qos  # the profile every odom subscriber uses

    duration = QUICK_DURATION_S if quick else DURATION_S
    rows, notes = [], []
    failed = []
    for rate in RATES_HZ:
        try:
            row = measure(rate, duration, (rclpy, Odometry, qos))
        except Exception as exc:  # noqa: BLE001 (keep the other rate's numbers; the section still fails)
            failed.append(f'{rate:g} Hz: {type(exc).__name__}: {exc}')
            rows.append({'rate_hz': rate, 'error': str(exc)})
            continue
        row['window_s'] = duration
        bad = {k: v for k, v in row['exit_codes'].items() if v not in (0, None)}
        if bad:
            notes.append(f'{rate:g} Hz: vessel_node exit code(s) after SIGINT: {bad} '
                         f'(log {row.get("log")})')
        rows.append(row)
    notes.append('dev = |inter-arrival period - 1/rate| at the subscriber (wall clock); '
                 'drift spread = range of (wall elapsed - sim elapsed); odd stamps = stamp '
                 'increments != 1/rate; missed = stamp gaps counted in periods minus one; '
                 'node late max = worst lateness of a publication behind its slot, logged by '
                 'the node itself')
    return {
        'title': f'{MODEL} vessel_node, realtime, odom at 10 / 50 Hz, {duration:g} s window '
                 '(ms unless stated)',
        'columns': [['rate_hz', 'Hz'], ['received', 'msgs'], ['expected', 'expected'],
                    ['period_mean_ms', 'period mean'], ['period_std_ms', 'std'],
                    ['dev_p50_ms', 'dev p50'], ['dev_p99_ms', 'dev p99'],
                    ['dev_max_ms', 'dev max'], ['drift_spread_ms', 'drift spread'],
                    ['realtime_factor', 'RT factor'], ['sim_dt_irregular', 'odd stamps'],
                    ['missed_steps', 'missed'], ['node_cpu_pct', 'node CPU %'],
                    ['node_lateness_max_ms', 'node late max']],
        'rows': rows, 'goals': [], 'notes': failed + notes, 'failed': bool(failed),
    }
