"""vessel_node: one simulated vessel on the ROS graph (thin plumbing around VesselSimulator).

Topics (relative names: the namespace makes the vessel, e.g. /vessel_0/odom; QoS
ship_sim.ros.qos.STREAM = reliable, keep-last 100):
  publishes  odom        nav_msgs/Odometry   ENU pose, frame 'map', child '<ns>/base_link',
                                             twist in body FLU over ground (REP-103/105)
             rudder      std_msgs/Float64    actual rudder angle (rad, positive turns to port)
             /clock      rosgraph_msgs/Clock sim time, when clock_master (reliable +
                                             transient_local, ship_sim.ros.qos.CLOCK:
                                             a per-step subscriber matched late still hears
                                             step 0; rclpy's best-effort /clock subscribers
                                             match it)
             ready       std_msgs/Bool       true once step 0 is out (latched: reliable +
                                             transient_local); the launcher starts a platoon
                                             follower's simulator after it
             sea_state   std_msgs/Float64MultiArray  with waves: the sea state (latched;
                                             labels in the layout); odom then carries the
                                             wave-frequency motion (ship_sim.ros.waves)
  subscribes rudder_cmd  std_msgs/Float64    rudder command (rad, positive turns to port)
             shaft_cmd   std_msgs/Float64    shaft speed command (rpm), models with a shaft only
             speed_factor_cmd std_msgs/Float64  with speed_factor_input: the shaft runs at
                                             factor x shaft command (ship_sim.speed_factor);
                                             in lockstep the k-th factor is awaited before
                                             step k is advanced (a gate of window 0), so the
                                             run stays deterministic; a model without a shaft
                                             (Mariner) ignores it, with one info line

One "step" of the node is one publish period 1/publish_rate, made of an integer number of
integration steps dt. Step k publishes /clock, odom and rudder for sim time k/publish_rate.

Stepping modes (parameter stepping_mode; the pacing rules live in ship_sim.pacing):
- realtime: wall-clock paced (x speedup; a steady-clock timer, steps that fell behind are
  caught up at once, at most MAX_CATCHUP per tick, so sim time keeps pace with wall time), the
  latest command is held. The pacing lateness of every step is measured and logged at shutdown.
- lockstep (doc/design.md "Lockstep needs a deterministic pairing of messages"): publish step k,
  then advance to k+1 only when the rudder_cmd for step k (the k-th rudder_cmd message since
  start, pairing by sequence, 0-based) has arrived. Deterministic: the same run repeats bit for
  bit whatever the load. Step 0 is published only when odom serves the nodes named in
  lockstep_odom_readers (each listed on odom by name and matched, ship_sim.ros.readiness;
  without names, any one subscriber), rudder the recorder's subscription (with
  lockstep_record_topic) and rudder_cmd a publisher (then START_GRACE_S more so that the
  controller's publisher has also matched us), or after lockstep_start_timeout (a warning naming
  the nodes still missing, e.g. "/vessel_0/odom: waiting for /vessel_0/colav_node"). Step 0 out,
  the node announces that it is ready on /graph_ready. If the command
  for step k does not come within lockstep_timeout (wall seconds): a warning naming the step,
  then the previous command is held for that step and the run continues; the late message,
  when it comes, is recognised by its sequence number and dropped (counted), so pairing stays
  aligned. Timeouts are counted and make the run no longer bit-identical, which the shutdown
  summary says. (Chosen over stopping: a slow controller costs one late step, not the run.)
  shaft_cmd is not paired (nobody publishes it per step): it applies from the next step on.

Bad input never crashes the node: a non-finite command is refused, counted and warned about
(throttled), and the previous command is held (in lockstep it still counts as that step's
message). Out-of-range commands are saturated by the simulator. If the model leaves its valid
domain (e.g. the tanker's surge speed drops to zero) the node logs an error and ends with exit
code 1. max_steps > 0 ends the run cleanly (exit 0) after publishing step max_steps (in lockstep
once its rudder_cmd has come and every gate, e.g. the recorder, has taken it: the bag then holds
the answer to the last step too; lockstep_timeout bounds that wait).

Executor: run_node spins with rclpy.experimental.EventsExecutor, which runs the lockstep loop
several times faster than SingleThreadedExecutor (the measured round trips and the cost of a
simulator step are in doc/results/performance.md and `make bench`).
"""
import math

from nav_msgs.msg import Odometry
import rclpy.logging
from rclpy.clock import Clock, ClockType
from rclpy.node import Node
from rosgraph_msgs.msg import Clock as ClockMsg
from std_msgs.msg import Bool, Float64, UInt64

from ship_sim.current import OceanCurrent
from ship_sim.environment.wind import WindField
from ship_sim.frames import yaw_to_psi
from ship_sim.models import ModelStateError, card, model_names
from ship_sim.pacing import LockstepPacer, RealtimePacer, StepGate
from ship_sim.ros.conversions import base_link_frame, fill_odometry, time_to_msg
from ship_sim.ros.params import NodeParameters, ParameterError
from ship_sim.ros.qos import CLOCK, DISPLAY, LATCHED, RECORD_ACK, STREAM
from ship_sim.ros.readiness import PeerWait, ReadyAnnouncer, describe_waits, names_param
from ship_sim.ros.run import finish, run_node, wait_for_acks
from ship_sim.ros.waves import WaveOdometry, declare_waves
from ship_sim.simulator import VesselSimulator
from ship_sim.speed_factor import scaled_shaft
from ship_sim.schema import VESSEL_NODE

class VesselNode(Node):
    def __init__(self):
        super().__init__('vessel_node')
        self.exit_code = 0
        self._declare_and_build()
        self._make_topics()
        self._n_rejected = 0      # non-finite commands refused
        self._running = False
        self._done = False
        if self.mode == 'realtime':
            self._pacer = RealtimePacer(self.period, self.speedup)
            self._tick_timer = None
            self._start_realtime()
        else:
            self._check_timer = self.create_timer(
                0.05, self._lockstep_watchdog, clock=Clock(clock_type=ClockType.STEADY_TIME))
        self.get_logger().info(
            f'{self.sim.model.name} ({self.sim.model.source}); dt {self.sim.dt} s, '
            f'{self.rate:g} Hz ({self.n_sub} integration steps per step), {self.mode}'
            + (f' x{self.speedup:g}' if self.mode == 'realtime' else '')
            + f", clock master {self.clock_master}, start ENU ({self.start[0]:.1f}, "
            f'{self.start[1]:.1f}) m, yaw {self.start[2]:.1f} deg, U {self.sim.speed_water():.3f}'
            ' m/s' + (f', shaft {self._shaft_cmd:g} rpm' if self._shaft_cmd is not None else '')
            + (f', current {self._current_text}' if self._current_text else '')
            + (f'; {self._waves.describe()}' if self._waves is not None else '')
            + (f', wind {self._wind.describe()} ({self._wind_coefficients})'
               if self._wind is not None else ''))

    # -- parameters and the simulator ---------------------------------------------------------
    def _declare_and_build(self):
        p = self.params = NodeParameters(self, VESSEL_NODE)
        model = p.param('model')
        given = {
            'preset': p.param('preset'),
            'nominal_speed_mps': p.param('nominal_speed_mps'),
            'water_depth_m': p.param('water_depth_m'),
        }
        rmax = p.param('rudder_max_deg')
        rrate = p.param('rudder_rate_max_deg')
        x0 = p.param('initial_x')
        y0 = p.param('initial_y')
        yaw0 = p.param('initial_yaw_deg')
        speed0 = p.param('initial_speed')
        shaft = p.param('shaft_rpm')
        dt = p.param('dt')
        rate = p.param('publish_rate', check=lambda r: _substeps_problem(r, dt))
        self.mode = p.param('stepping_mode')
        self.speedup = p.param('speedup', on_change=self._set_speedup)
        self.lockstep_timeout = p.param('lockstep_timeout', on_change=self._set_lockstep_timeout)
        self.start_timeout = p.param('lockstep_start_timeout')
        self.max_timeouts = p.param('lockstep_max_timeouts')
        self.record_topic = p.param('lockstep_record_topic')
        self.record_window = p.param('lockstep_record_window')
        self.follower_topics = p.param('lockstep_follower_odom_topics')
        self.follower_window = p.param('lockstep_follower_window')
        self.command_timeout = p.param('command_timeout_s')
        self.odom_readers = names_param(p.param('lockstep_odom_readers'))
        self.display_every = p.param('display_every')
        self.clock_master = p.param('clock_master')
        self.max_steps = p.param('max_steps')
        self.speed_factor_input = p.param('speed_factor_input')
        c_speed = p.param('current_speed')
        c_dir = p.param('current_direction_deg')
        c_sd = p.param('current_speed_sd')
        c_dir_sd = p.param('current_direction_sd_deg')
        c_tc = p.param('current_time_constant')
        c_seed = p.param('current_seed')
        self._wind, self._wind_coefficients = _declare_wind(p)

        # Model: the card says which node parameters its constructor takes. 0 / '' means
        # "model default" and is not passed; a non-default value for a model without that
        # keyword is refused.
        vessel_card = card(model)
        table = vessel_card.node_kwargs
        kwargs = {}
        for pname, value in given.items():
            if not value:
                continue
            if pname not in table:
                takes = ', '.join(table) or 'none of preset, nominal_speed_mps, water_depth_m'
                raise ParameterError(pname, value, f"the default (0 or '') for model {model!r}, "
                                     f'which takes: {takes}')
            kwargs[table[pname]] = value
        if rmax:
            kwargs['rudder_max'] = math.radians(rmax)
        if rrate:
            kwargs['rudder_rate_max'] = math.radians(rrate)
        try:
            m = vessel_card.make(**kwargs)
        except (ValueError, TypeError) as exc:
            raise ParameterError('model', message=f'model {model!r} with {kwargs}: {exc}') from None

        # Current (ship_sim.current: intensity q = 2 sd^2 / T gives stationary sd).
        current, self._current_text = None, ''
        if c_speed > 0.0 or c_sd > 0.0 or c_dir_sd > 0.0:
            sd_dir = math.radians(c_dir_sd)
            current = OceanCurrent(
                c_speed, math.radians(c_dir),
                speed_time_constant=c_tc if c_sd > 0.0 else None,
                speed_noise=2.0 * c_sd ** 2 / c_tc,
                direction_time_constant=c_tc if sd_dir > 0.0 else None,
                direction_noise=2.0 * sd_dir ** 2 / c_tc, seed=c_seed)
            self._current_text = (f'{c_speed:g} m/s towards {c_dir:g} deg'
                                  + (f' (sd {c_sd:g} m/s, {c_dir_sd:g} deg, T {c_tc:g} s, seed '
                                     f'{c_seed})' if current.varying else ''))

        self._sea = declare_waves(p, m)

        # Initial state: ENU pose -> NED; shaft default for models with a shaft.
        if shaft and not m.has_shaft:
            raise ParameterError('shaft_rpm', shaft, f'0 for model {model!r} (it has no shaft)')
        # Unset speed and shaft: the model's trim at its nominal shaft speed; only a speed: the
        # shaft speed that holds it; only a shaft speed: the speed it gives. The shaft command
        # starts at the state's shaft speed.
        try:
            self.sim = VesselSimulator(
                m, dt=dt, north=y0, east=x0, psi=float(yaw_to_psi(math.radians(yaw0))),
                speed=speed0 or None, shaft=shaft or None, current=current,
                **self._wind_arguments(m))
        except (ValueError, ModelStateError) as exc:
            raise ParameterError('initial_speed', message=f'initial state of {model!r} (initial_'
                                 f'speed {speed0}, shaft_rpm {shaft}): {exc}') from None
        self.rate = rate
        self.n_sub = int(round(1.0 / (rate * dt)))
        self.period = self.n_sub * dt
        self.start = (x0, y0, yaw0)
        self._rudder_cmd = 0.0
        self._shaft_cmd = self.sim.shaft_command

    def _wind_arguments(self, model):
        """VesselSimulator keywords for the wind; ParameterError if the model cannot take it."""
        if self._wind is None:
            return {}
        if not card(model.name).has_wind:
            raise ParameterError('wind_speed', message=f'wind needs a model with wind loads '
                                 f"({', '.join(model_names('wind'))}), not {model.name!r}; set "
                                 'wind_speed and wind_gust_sd to 0')
        return {'wind': self._wind, 'wind_coefficients': self._wind_coefficients}

    # -- topics -------------------------------------------------------------------------------
    def _make_topics(self):
        self._speed_factor, self._speed_factor_ignored = 1.0, False
        self._odom_pub = self.create_publisher(Odometry, 'odom', STREAM)
        self._rudder_pub = self.create_publisher(Float64, 'rudder', STREAM)
        self._display_pub = (self.create_publisher(Odometry, 'odom_display', DISPLAY)
                             if self.display_every else None)
        self._clock_pub = (self.create_publisher(ClockMsg, '/clock', CLOCK)
                           if self.clock_master else None)
        # Reused messages: publishing copies them, so one object per topic is enough.
        self._odom = Odometry()
        self._odom.header.frame_id = 'map'
        self._odom.child_frame_id = base_link_frame(self.get_namespace())
        self._rudder_msg = Float64()
        self._clock_msg = ClockMsg()
        self._ready_msg = Bool(data=False)
        on_cmd = self._on_rudder_cmd_lockstep if self.mode == 'lockstep' else self._on_rudder_cmd
        self._cmd_sub = self.create_subscription(Float64, 'rudder_cmd', on_cmd, STREAM)
        self._shaft_sub = (self.create_subscription(Float64, 'shaft_cmd', self._on_shaft_cmd,
                                                    STREAM)
                           if self.sim.model.has_shaft else None)
        self._ready_pub = self.create_publisher(Bool, 'ready', LATCHED)
        self._announcer = ReadyAnnouncer(self)
        # Before step 0 in lockstep: the readers of odom by name, the recorder on rudder, and
        # a publisher of rudder_cmd (the autopilot holds its first commands until it has
        # matched us by name, ship_sim.ros.held_start).
        self._start_waits = [PeerWait(self, self._odom_pub, self.odom_readers),
                             PeerWait(self, self._cmd_sub)]
        if self.record_topic:
            self._start_waits.append(PeerWait(self, self._rudder_pub))
        self._waves = None if self._sea is None else WaveOdometry(self, self._sea, self.sim.model)
        # Lockstep step gates: who must keep up before the next step goes out.
        self._lockstep = None
        if self.mode == 'lockstep':
            gates = []
            if self.record_topic:
                gates.append(self._gate(StepGate(f'the recorder ({self.record_topic})',
                                                 self.record_window, needed_at_start=True),
                                        UInt64, self.record_topic,
                                        lambda g, msg: g.acknowledge(msg.data), RECORD_ACK))
            gates += self._speed_factor_gates()
            for topic in filter(None, (t.strip() for t in self.follower_topics.split(','))):
                gates.append(self._gate(StepGate(f'follower {topic}', self.follower_window,
                                                 heard=0), Odometry, topic,
                                        lambda g, msg: g.acknowledge(g.acked + 1), STREAM))
            log = self.get_logger()
            self._lockstep = LockstepPacer(
                start=self._start_lockstep, step=self._lockstep_step, stop=self._stop,
                warn=log.warning, error=log.error, graph=self._graph_matched,
                describe_graph=self._describe_graph, timeout=self.lockstep_timeout,
                max_timeouts=self.max_timeouts, start_timeout=self.start_timeout, gates=gates,
                command=self._rudder_cmd, last_step=self.max_steps or None)
        self._t_last_cmd = self.sim.t        # realtime: sim time of the latest rudder_cmd
        self._centred = False
        if self.speed_factor_input and self.mode == 'realtime':
            self.create_subscription(Float64, 'speed_factor_cmd', self._on_speed_factor, STREAM)

    # -- speed factor (colav_node's speed_factor_cmd) ---------------------------------------------
    def _speed_factor_gates(self):
        """Lockstep: speed_factor_cmd as a gate of window 0 (step k+1 goes out once the k-th
        factor, the one for step k, has come), or a plain subscription for a model without a
        shaft (ignored, logged once)."""
        if not self.speed_factor_input:
            return []
        if not self.sim.model.has_shaft:
            self.create_subscription(Float64, 'speed_factor_cmd', self._on_speed_factor, STREAM)
            return []
        return [self._gate(StepGate('speed_factor_cmd', 0, heard=0), Float64, 'speed_factor_cmd',
                           self._on_speed_factor_step, STREAM)]

    def _on_speed_factor_step(self, gate, msg):
        self._on_speed_factor(msg)
        gate.acknowledge(gate.acked + 1)

    def _on_speed_factor(self, msg):
        if not self.sim.model.has_shaft:
            if not self._speed_factor_ignored:
                self._speed_factor_ignored = True
                self.get_logger().info(f'speed_factor_cmd ignored: {self.sim.model.name} has no '
                                       'shaft input (its speed is set by the model, e.g. the '
                                       "Mariner's U0)")
            return
        if self._finite(msg.data, 'speed_factor_cmd'):
            self._speed_factor = msg.data

    def _publish(self):
        sim = self.sim
        t, n, e, psi, u, v, r = sim.nav_state()
        if self._waves is None:
            fill_odometry(self._odom, t, n, e, psi, u, v, r)
        else:
            self._waves.fill(self._odom, t, n, e, psi, u, v, r, sim.speed_water())
        self._rudder_msg.data = sim.rudder()
        try:
            if self._clock_pub is not None:
                time_to_msg(t, self._clock_msg.clock)
                self._clock_pub.publish(self._clock_msg)
            self._odom_pub.publish(self._odom)
            self._rudder_pub.publish(self._rudder_msg)
            if self._display_pub is not None and self._step_index() % self.display_every == 0:
                self._display_pub.publish(self._odom)
            if not self._ready_msg.data:
                self._ready_msg.data = True
                self._ready_pub.publish(self._ready_msg)
                self._announcer.announce(['odom'])
        except Exception:  # re-raised unless we are shutting down
            if self.context.ok():
                raise
            self._running = False   # a signal shut the context down mid-step: just stop

    def _advance(self):
        """One node step (n_sub integration steps) with the held commands. False if stopped."""
        sim = self.sim
        try:
            shaft = scaled_shaft(self._shaft_cmd, self._speed_factor)
            for _ in range(self.n_sub):
                sim.step(self._rudder_cmd, shaft)
        except ModelStateError as exc:
            self.get_logger().error(f'step {self._step_index()}: the model left its valid '
                                    f'domain, stopping: {exc}')
            self._stop(1)
            return False
        return True

    def _step_index(self):
        return self.sim.k // self.n_sub

    def _stop(self, code):
        if self._done:
            return
        self._done = True
        self._running = False
        if code == 0:
            # Let reliable subscribers get the last step before the node goes away.
            wait_for_acks(self, (self._odom_pub, self._rudder_pub, self._display_pub))
        finish(self, code)

    def _after_publish(self):
        if self.max_steps and self._step_index() >= self.max_steps:
            if self._lockstep is not None:   # it stops once the step is answered and recorded
                self.get_logger().info(f'max_steps {self.max_steps} reached at sim time '
                                       f'{self.sim.t:.3f} s: waiting for its answer')
                return
            self.get_logger().info(f'max_steps {self.max_steps} reached at sim time '
                                   f'{self.sim.t:.3f} s')
            self._stop(0)

    # -- commands -------------------------------------------------------------------------------
    def _finite(self, value, topic):
        if math.isfinite(value):
            return True
        self._n_rejected += 1
        self.get_logger().warning(f'{topic} {value} refused (not finite; {self._n_rejected} '
                                  'so far): holding the previous command',
                                  throttle_duration_sec=5.0)
        return False

    def _on_rudder_cmd(self, msg):
        if self._finite(msg.data, 'rudder_cmd'):
            self._rudder_cmd = msg.data
            self._t_last_cmd = self.sim.t
            if self._centred:
                self._centred = False
                self.get_logger().info(f'rudder_cmd again at sim time {self.sim.t:.1f} s')

    def _check_command_age(self):
        """Realtime: centre the rudder once rudder_cmd has been silent for command_timeout_s."""
        if (self.command_timeout > 0.0 and not self._centred
                and self.sim.t - self._t_last_cmd > self.command_timeout):
            self._centred = True
            self._rudder_cmd = 0.0
            self.get_logger().warning(
                f'no rudder_cmd for {self.sim.t - self._t_last_cmd:.1f} s of sim time (command_'
                f'timeout_s {self.command_timeout:g}): rudder centred until commands come again')

    def _on_shaft_cmd(self, msg):
        if self._finite(msg.data, 'shaft_cmd'):
            self._shaft_cmd = msg.data

    # -- realtime -----------------------------------------------------------------------------
    def _start_realtime(self):
        self._running = True
        self._pacer.start(self._step_index())
        self._publish()
        self._after_publish()
        self._make_tick_timer()

    def _make_tick_timer(self):
        if self._tick_timer is not None:
            self.destroy_timer(self._tick_timer)
        self._tick_timer = self.create_timer(self._pacer.wall_period, self._on_tick,
                                             clock=Clock(clock_type=ClockType.STEADY_TIME))

    def _set_speedup(self, value):
        self.speedup = float(value)
        if self.mode == 'realtime' and self._running:
            self._pacer.set_speedup(self.speedup, self._step_index())
            self._make_tick_timer()
            self.get_logger().info(f'speedup now x{self.speedup:g}')

    def _on_tick(self):
        if not self._running:
            return
        k = self._step_index()
        due, behind = self._pacer.due(k)
        if behind:
            self.get_logger().warning(f'step {k}: {behind} steps behind the wall clock at '
                                      f'x{self.speedup:g}; resetting the pace',
                                      throttle_duration_sec=5.0)
        while k < due and self._running:
            self._check_command_age()
            if not self._advance():
                return
            k += 1
            self._publish()
            self._pacer.published(k)
            self._after_publish()

    # -- lockstep (the rules: ship_sim.pacing.LockstepPacer) ------------------------------------
    def _set_lockstep_timeout(self, value):
        self.lockstep_timeout = float(value)
        if self._lockstep is not None:
            self._lockstep.timeout = self.lockstep_timeout

    def _graph_matched(self):
        # With a recorder, its rudder subscription too: our publisher may match it only after
        # the recorder has said it is ready (discovery is per endpoint), and step 0 would be
        # missing from the bag.
        return all(w.ready() for w in self._start_waits)

    def _describe_graph(self):
        return describe_waits(self._start_waits) or 'every reader and writer is there'

    def _lockstep_watchdog(self):
        if self._done or (self._lockstep.started and not self._running):
            return
        self._lockstep.watchdog()

    def _start_lockstep(self):
        """Publish step 0; whether the node still runs."""
        self._running = True
        self.get_logger().info('lockstep: publishing step 0')
        self._publish()
        self._after_publish()
        return self._running

    def _on_rudder_cmd_lockstep(self, msg):
        self._lockstep.on_command(msg.data if self._finite(msg.data, 'rudder_cmd') else None)

    def _gate(self, gate, msg_type, topic, on_msg, qos):
        def callback(msg):
            on_msg(gate, msg)
            self._lockstep.on_gate()
        gate.sub = self.create_subscription(msg_type, topic, callback, qos)
        return gate

    def _lockstep_step(self, command):
        """One step with ``command`` (rad), published; whether the node still runs."""
        self._rudder_cmd = command
        if self._advance():
            self._publish()
            self._after_publish()
        return self._running

    # -- shutdown -----------------------------------------------------------------------------
    def destroy_node(self):
        # After a signal the context is already shut down, and the node's logger (and its
        # children) would fail to publish to /rosout: then log to the console only, through a
        # logger rosout does not know.
        log = self.get_logger()
        if not self.context.ok():
            log = rclpy.logging.get_logger(log.name + '_summary')
        k = self._step_index()
        text = (f'end: {k} steps, sim time {self.sim.t:.3f} s, {self._n_rejected} non-finite '
                'commands refused')
        if self._lockstep is not None:
            ls = self._lockstep
            text += (f', {ls.n_timeouts} lockstep timeouts, {ls.n_stale} late commands '
                     'dropped' + ('' if ls.n_timeouts else ' (deterministic run)'))
            for g in ls.gates:
                text += (f'; {g.name} took {g.acked} steps, {g.waits} waits for it'
                         + (', then went on without it' if g.given_up else ''))
        elif self._pacer.lateness.n:
            text += '; ' + self._pacer.summary()
        log.info(text)
        super().destroy_node()


def _declare_wind(p):
    """Declare the wind_* parameters; return (WindField or None when calm, coefficients)."""
    speed = p.param('wind_speed')
    direction = p.param('wind_direction_deg')
    gust_sd = p.param('wind_gust_sd')
    tc = p.param('wind_time_constant')
    seed = p.param('wind_seed')
    coefficients = p.param('wind_coefficients')
    if speed == 0.0 and gust_sd == 0.0:
        return None, coefficients
    return WindField(speed, math.radians(direction), gust_sd=gust_sd, time_constant=tc,
                     seed=seed), coefficients


def _substeps_problem(rate, dt):
    """None if 1/rate is a whole multiple (>= 1) of dt, else what is allowed."""
    n = round(1.0 / (rate * dt))
    if n >= 1 and abs(n * dt * rate - 1.0) < 1e-9:
        return None
    return f'a rate whose period 1/publish_rate is a whole multiple of dt = {dt} s'


def main(args=None):
    return run_node(VesselNode, args=args)


if __name__ == '__main__':
    raise SystemExit(main())
