"""autopilot_node: heading command + odom -> rudder command (PD, fuzzy PID or a learned policy).

Subscribes `odom` (nav_msgs/Odometry, ENU) and `heading_cmd` (std_msgs/Float64, ENU yaw, rad);
publishes `rudder_cmd` (std_msgs/Float64, rad, positive turns to port), one per control step.
The law is one of ship_autopilot.steering (HeadingSteering, PolicySteering): the node feeds
it odometry and commands and publishes what it returns.

Pairing (`pairing` parameter):
  sequence  the n-th odom is paired with the n-th heading_cmd and the rudder is computed when
            both are held (lockstep: deterministic, one rudder_cmd per simulator step;
            ship_sim.pacing.SequencePairer);
  latest    the rudder is computed on every odom with the latest heading command (realtime).
Stale command (latest pairing): if no heading_cmd arrived for `heading_timeout_s` of sim time,
the autopilot keeps steering the last commanded heading (course keeping) and warns; before the
first command it holds the heading the vessel had at its first odom. Non-finite inputs never
reach the rudder: the controller holds its previous output and the event is counted. A
non-finite heading_cmd is refused and counted (warning, throttled): the previous command is
held (sequence pairing: it still answers its odom, so the pairing holds).

Gains: from the per-model table (ship_autopilot/data/autopilot_gains.yaml, designed from the
identified Nomoto K, T) for `vessel_model`, unless `k1`/`k2` (PD) are given (> 0), or
`omega_n`/`zeta` are given to redesign PD gains from the identified Nomoto a, b, or the fuzzy
PID's scaling `fuzzy_ge`/`fuzzy_gr`/`fuzzy_ga`/`fuzzy_gu` (`fuzzy_l`) is given (e.g. Lee 2004's).
Rudder limits default to the vessel model's (`rudder_max_deg`/`rudder_rate_max_deg` override).

`wave_filter` (default off) passes heading and yaw rate through ship_autopilot.wave_filter (a
notch at the encounter frequency + low-pass) before the classical controller sees them.

`controller: policy` runs a learned policy (learning.policy) on the guidance node's path_state
(in place of heading_cmd, paired the same way);
with `policy_recovery` (default true) ILOS + the gain-table PD takes over outside the region the
policy was trained in (learning.policy.Recovery) and hands back inside it.
"""
import math

from nav_msgs.msg import Odometry
from rclpy.node import Node
from std_msgs.msg import Float64, Float64MultiArray

from ship_autopilot.gains import (FUZZY_SCALING_PARAMETERS, autopilot_gains,
                                  build_autopilot, heading_loop_design)
from ship_autopilot.steering import HeadingSteering, PolicySteering
from ship_autopilot.wave_filter import WaveFilter
from ship_sim.models import make_model
from ship_sim.pacing import SequencePairer
from ship_sim.ros.held_start import HeldStart
from ship_sim.ros.readiness import names_param
from ship_sim.ros.conversions import odometry_to_ned
from ship_sim.ros.params import NodeParameters, ParameterError
from ship_sim.ros.qos import STREAM
from ship_sim.ros.run import run_node
from ship_autopilot.schema import AUTOPILOT_NODE

# The message type of each steering law's command topic (ship_autopilot.steering).
COMMAND_TYPES = {'heading_cmd': Float64, 'path_state': Float64MultiArray}


class AutopilotNode(Node):
    def __init__(self):
        super().__init__('autopilot_node')
        p = self.params = NodeParameters(self, AUTOPILOT_NODE)
        model = p.param('vessel_model')
        kind = p.param('controller')
        policy_file = p.param('policy_file')
        k1 = p.param('k1')
        k2 = p.param('k2')
        fuzzy = {name: p.param(name) for name in FUZZY_SCALING_PARAMETERS}
        omega_n = p.param('omega_n')
        zeta = p.param('zeta')
        rmax = p.param('rudder_max_deg')
        rrate = p.param('rudder_rate_max_deg')
        shape = p.param('saturation')
        self.pairing = p.param('pairing')
        readers = names_param(p.param('rudder_cmd_readers'))
        self.timeout = p.param('heading_timeout_s')
        recovery = p.param('policy_recovery')

        # The instance's limits: models set them in __init__ (e.g. Nomoto presets, NPS AUV II),
        # the class attributes are only the base defaults.
        vessel = make_model(model)
        max_angle = math.radians(rmax) if rmax else vessel.rudder_max
        max_rate = math.radians(rrate) if rrate else vessel.rudder_rate_max
        if kind == 'policy':
            self.steer = PolicySteering(self._load_policy(model, policy_file, max_angle,
                                                          recovery, vessel))
        else:
            self._build_classical(kind, model, k1, k2, omega_n, zeta, max_angle, max_rate, shape,
                                  fuzzy)
            self.steer = HeadingSteering(self.controller)

        self.wave_filter = self._declare_wave_filter(p, kind)
        self.pub = self.create_publisher(Float64, 'rudder_cmd', STREAM)
        # Sequence pairing: the simulator takes the n-th rudder_cmd it receives as step n's, so
        # the first ones wait until the named readers (the simulator, the recorder; without
        # names, any one) are listed and every listed subscriber has matched (none is lost).
        self.out = (HeldStart(self, self.pub, names=readers) if self.pairing == 'sequence'
                    else self.pub)
        self.pairer = SequencePairer()  # sequence pairing: A odometry, B commands
        self.latest = None          # latest pairing: the last accepted command
        self.t_cmd = None           # sim time of the last command (latest pairing)
        self.stale = False
        self.n_bad_cmd = 0          # commands refused (non-finite heading_cmd)
        self.msg = Float64()
        # raw: odometry_to_ned reads the CDR bytes (rclpy's conversion costs more).
        self.create_subscription(Odometry, 'odom', self._on_odom, STREAM, raw=True)
        self.create_subscription(COMMAND_TYPES[self.steer.command_topic],
                                 self.steer.command_topic, self._on_command, STREAM)

    def _declare_wave_filter(self, p, kind):
        """The optional wave filter (ship_autopilot.wave_filter) on heading and yaw rate."""
        on = p.param('wave_filter')
        freq = p.param('wave_filter_frequency')
        tp = p.param('wave_filter_peak_period')
        direction = p.param('wave_filter_direction_deg')
        zeta = p.param('wave_filter_zeta')
        lowpass = p.param('wave_filter_lowpass')
        if not on:
            return None
        if kind == 'policy':
            raise ParameterError('wave_filter', True, 'false with controller policy (the policy '
                                 'steers by path_state, which the filter does not see)')
        if not (freq or tp):
            raise ParameterError('wave_filter_frequency', freq, '> 0, or wave_filter_peak_period '
                                 '> 0, when wave_filter is on')
        filt = WaveFilter(freq, peak_frequency=2.0 * math.pi / tp if tp else 0.0,
                          direction=math.radians(direction), zeta=zeta, lowpass=lowpass)
        self.get_logger().info(
            'wave filter: notch ' + (f'at {freq:g} rad/s' if freq else
                                     f'following the encounter frequency of Tp {tp:g} s towards '
                                     f'{direction:g} deg') + f', zeta {zeta:g}, low-pass '
            + (f'{lowpass:g} rad/s' if lowpass else 'at the notch frequency'))
        return filt

    def _load_policy(self, model, policy_file, max_angle, recovery, vessel):
        from ship_autopilot.learning.policy import (LearnedSteering, PolicyError, Recovery,
                                                    check_model_limits, load_policy)
        try:
            policy = load_policy(model, policy_file or None)
            check_model_limits(policy, max_angle)
        except PolicyError as exc:
            raise ParameterError('policy_file', message=f'policy_file: {exc}') from None
        self.get_logger().info(f'learned steering for {model}: {policy!r}')
        law = None
        if recovery:
            pd = autopilot_gains(model)['pd']
            law = Recovery.for_policy(policy, pd['k1'], pd['k2'], vessel.length,
                                      float(vessel.speed(vessel.initial_state())))
            self.get_logger().info(
                f'recovery: ILOS (look-ahead {law.lookahead:.0f} m) + PD beyond |e| '
                f'{law.engage_m:.0f} m or 90 deg off the path, back to the policy within '
                f'{law.release_m:.0f} m')
        return LearnedSteering(policy, recovery=law)

    def _build_classical(self, kind, model, k1, k2, omega_n, zeta, max_angle, max_rate, shape,
                         fuzzy):
        if kind == 'pd' and (k1 or k2) and not (k1 and k2):
            raise ParameterError('k1', k1, 'k1 and k2 both > 0 (or both 0)')
        scaling = [v for k, v in fuzzy.items() if k != 'fuzzy_l']
        if any(scaling) and not all(scaling):
            raise ParameterError('fuzzy_ge', fuzzy['fuzzy_ge'], 'fuzzy_ge, fuzzy_gr, fuzzy_ga and '
                                 'fuzzy_gu all > 0 (or all 0)')
        try:
            gains = heading_loop_design(model, kind, k1, k2, omega_n, zeta, **fuzzy).gains
            self.controller = build_autopilot(kind, gains, max_angle, max_rate, shape)
        except (ValueError, KeyError, OSError) as exc:
            raise ParameterError('vessel_model', message=f'vessel_model {model!r}: {exc}') from None
        self.get_logger().info(
            f'{kind} autopilot for {model}: rudder limit {math.degrees(max_angle):.1f} deg, '
            f'{math.degrees(max_rate):.2f} deg/s, gains '
            f'{gains.get("pd", gains) if kind == "pd" or "GE" in gains else "fuzzy table"}')

    def _on_command(self, msg):
        cmd = self.steer.decode(msg.data)
        if cmd is None:
            self._refuse_command(msg.data)
        if self.pairing == 'sequence':
            self.pairer.push_b(cmd)     # a refused command still answers its odom
            self._drain()
        elif cmd is not None:
            self.latest = cmd
            self.t_cmd = None  # stamped with the next odom's sim time

    def _refuse_command(self, value):
        self.n_bad_cmd += 1
        self.get_logger().warning(f'{self.steer.command_topic} {value} refused (not finite): '
                                  f'holding the previous command ({self.n_bad_cmd} so far)',
                                  throttle_duration_sec=5.0)

    def _on_odom(self, msg):
        o = odometry_to_ned(msg)
        if self.pairing == 'sequence':
            self.pairer.push_a(o)
            self._drain()
            return
        if self.t_cmd is None:
            self.t_cmd = o.t   # before the first command: from the first odom
        stale = o.t - self.t_cmd > self.timeout
        if stale and not self.stale:
            self.get_logger().warning(f'{self.steer.command_topic} stale for '
                                      f'{o.t - self.t_cmd:.1f} s: holding the last command')
        self.stale = stale
        self._step(o, self.latest)

    def _drain(self):
        for o, cmd in self.pairer.pairs():
            self._step(o, cmd)

    def _step(self, o, cmd):
        steer = self.steer
        n_bad, mode = steer.n_rejected, steer.mode
        psi, r = o.psi, o.r
        if self.wave_filter is not None:
            psi, r = self.wave_filter.update(o.t, psi, r, math.hypot(o.u, o.v))
        self.msg.data = steer.update(o.t, psi, r, cmd)
        if steer.mode != mode:
            self.get_logger().info(steer.mode_text(cmd))
        if steer.n_rejected != n_bad:
            self.get_logger().warning(f'{steer.rejected_text} held the rudder '
                                      f'({steer.n_rejected} so far)', throttle_duration_sec=5.0)
        self.out.publish(self.msg)


def main(args=None):
    return run_node(AutopilotNode, args=args)


if __name__ == '__main__':
    raise SystemExit(main())
