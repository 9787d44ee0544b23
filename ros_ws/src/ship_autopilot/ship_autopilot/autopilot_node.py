"""autopilot_node: heading command + odom -> rudder command (PD or fuzzy PID).

Subscribes `odom` (nav_msgs/Odometry, ENU) and `heading_cmd` (std_msgs/Float64, ENU yaw, rad);
publishes `rudder_cmd` (std_msgs/Float64, rad, positive turns to port), one per control step.

Pairing (`pairing` parameter):
  sequence  the n-th odom is paired with the n-th heading_cmd and the rudder is computed when
            both are held (lockstep: deterministic, one rudder_cmd per simulator step);
  latest    the rudder is computed on every odom with the latest heading command (realtime).
Stale command (latest pairing): if no heading_cmd arrived for `heading_timeout_s` of sim time,
the autopilot keeps steering the last commanded heading (course keeping) and warns; before the
first command it holds the heading the vessel had at its first odom. Non-finite inputs never
reach the rudder: the controller holds its previous output and the event is counted. A
non-finite heading_cmd is refused and counted (warning, throttled): the previous command is
held (sequence pairing: it still answers its odom, so the pairing holds).

Gains: from the per-model table (ship_autopilot/data/autopilot_gains.yaml, designed from the
identified Nomoto K, T) for `vessel_model`, unless `k1`/`k2` (PD) are given (> 0), or
`omega_n`/`zeta` are given to redesign PD gains from the identified Nomoto a, b.
Rudder limits default to the vessel model's (`rudder_max_deg`/`rudder_rate_max_deg` override).

`controller: policy` runs a learned policy (learning.policy) on the guidance node's path_state;
with `policy_recovery` (default true) ILOS + the gain-table PD takes over outside the region the
policy was trained in (learning.policy.Recovery) and hands back inside it.
"""
import collections
import math

import numpy as np

from nav_msgs.msg import Odometry
from rclpy.node import Node
from std_msgs.msg import Float64, Float64MultiArray

from ship_autopilot.gains import (CONTROLLERS, ZETA, autopilot_gains, build_autopilot,
                                  heading_loop_design)
from ship_sim.frames import yaw_to_psi
from ship_sim.models import MODEL_NAMES, make_model
from ship_sim.ros.conversions import odometry_to_ned
from ship_sim.ros.params import NodeParameters, ParameterError
from ship_sim.ros.qos import STREAM
from ship_sim.ros.run import run_node


class AutopilotNode(Node):
    def __init__(self):
        super().__init__('autopilot_node')
        p = self.params = NodeParameters(self)
        model = p.declare('vessel_model', 'mariner', 'vessel model the gains and rudder limits '
                          'are taken from', choices=MODEL_NAMES, read_only=True)
        kind = p.declare('controller', 'pd', 'heading controller (policy: learned steering on '
                         'the guidance node\'s path_state)', choices=CONTROLLERS + ('policy',),
                         read_only=True)
        policy_file = p.declare('policy_file', '', 'controller policy: policy file (.npz; empty: '
                                'the one shipped for vessel_model)', read_only=True)
        k1 = p.declare('k1', 0.0, 'PD heading gain (0: from the gain table)', lo=0.0, hi=1e3,
                       unit='rad/rad', read_only=True)
        k2 = p.declare('k2', 0.0, 'PD yaw-rate gain (0: from the gain table)', lo=0.0, hi=1e5,
                       unit='rad/(rad/s)', read_only=True)
        omega_n = p.declare('omega_n', 0.0, 'redesign PD gains for this natural frequency '
                            '(0: gain table)', lo=0.0, hi=100.0, unit='rad/s', read_only=True)
        zeta = p.declare('zeta', ZETA, 'damping ratio used with omega_n', lo=0.05, hi=5.0,
                         read_only=True)
        rmax = p.declare('rudder_max_deg', 0.0, 'rudder angle limit (0: the model\'s)', lo=0.0,
                         hi=90.0, unit='deg', read_only=True)
        rrate = p.declare('rudder_rate_max_deg', 0.0, 'rudder rate limit (0: the model\'s)',
                          lo=0.0, hi=1e3, unit='deg/s', read_only=True)
        shape = p.declare('saturation', 'hard', 'rudder saturation form (tanh: seed 001 eq. 15)',
                          choices=('hard', 'tanh'), read_only=True)
        self.pairing = p.declare('pairing', 'sequence', 'how odom and heading_cmd are paired',
                                 choices=('sequence', 'latest'), read_only=True)
        self.timeout = p.declare('heading_timeout_s', 5.0, 'sim time without heading_cmd after '
                                 'which the command counts as stale (latest pairing)', lo=0.01,
                                 hi=1e4, unit='s', read_only=True)
        recovery = p.declare('policy_recovery', True, 'controller policy: steer with ILOS + the '
                             'gain-table PD while the vessel is outside the policy\'s training '
                             'region (|e| beyond its start range, or heading > 90 deg off the '
                             'path), hand back within half that range', read_only=True)

        # The instance's limits: models set them in __init__ (e.g. Nomoto presets, NPS AUV II),
        # the class attributes are only the base defaults.
        vessel = make_model(model)
        max_angle = math.radians(rmax) if rmax else vessel.rudder_max
        max_rate = math.radians(rrate) if rrate else vessel.rudder_rate_max
        self.steer = None
        if kind == 'policy':
            self.steer = self._load_policy(model, policy_file, max_angle, recovery, vessel)
        else:
            self._build_classical(kind, model, k1, k2, omega_n, zeta, max_angle, max_rate, shape)

        self.pub = self.create_publisher(Float64, 'rudder_cmd', STREAM)
        self.odoms = collections.deque()
        self.headings = collections.deque()  # heading commands, or path states (policy)
        self.psi_c = None           # last heading command (NED)
        self.state = None           # last path state (policy, latest pairing)
        self.t_cmd = None           # sim time of the last heading command (latest pairing)
        self.t_prev = None
        self.stale = False
        self.n_bad_cmd = 0          # non-finite heading commands refused
        self.msg = Float64()
        # raw: odometry_to_ned reads the CDR bytes (rclpy's conversion costs ~20x more).
        self.create_subscription(Odometry, 'odom', self._on_odom, STREAM, raw=True)
        if self.steer is None:
            self.create_subscription(Float64, 'heading_cmd', self._on_heading, STREAM)
        else:
            self.create_subscription(Float64MultiArray, 'path_state', self._on_state, STREAM)

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

    def _build_classical(self, kind, model, k1, k2, omega_n, zeta, max_angle, max_rate, shape):
        if kind == 'pd' and (k1 or k2) and not (k1 and k2):
            raise ParameterError('k1', k1, 'k1 and k2 both > 0 (or both 0)')
        try:
            gains = heading_loop_design(model, kind, k1, k2, omega_n, zeta).gains
            self.controller = build_autopilot(kind, gains, max_angle, max_rate, shape)
        except (ValueError, KeyError, OSError) as exc:
            raise ParameterError('vessel_model', message=f'vessel_model {model!r}: {exc}') from None
        self.get_logger().info(
            f'{kind} autopilot for {model}: rudder limit {math.degrees(max_angle):.1f} deg, '
            f'{math.degrees(max_rate):.2f} deg/s, gains {gains.get("pd", gains) if kind == "pd" else "fuzzy table"}')

    def _on_state(self, msg):
        # A state of the wrong length counts as non-finite: the policy holds its command.
        state = np.asarray(msg.data, dtype=float)
        if state.shape != (9,):
            state = np.full(9, np.nan)
        if self.pairing == 'sequence':
            self.headings.append(state)
            self._drain()
        else:
            self.state = state

    def _on_heading(self, msg):
        psi_c = float(yaw_to_psi(msg.data)) if math.isfinite(msg.data) else math.nan
        if self.pairing == 'sequence':
            self.headings.append(psi_c)
            self._drain()
        elif math.isfinite(psi_c):
            self.psi_c = psi_c
            self.t_cmd = None  # stamped with the next odom's sim time
        else:
            self._refuse_command(msg.data)

    def _refuse_command(self, value):
        self.n_bad_cmd += 1
        self.get_logger().warning(f'heading_cmd {value} refused (not finite): holding the '
                                  f'previous command ({self.n_bad_cmd} so far)',
                                  throttle_duration_sec=5.0)

    def _on_odom(self, msg):
        o = odometry_to_ned(msg)
        if self.pairing == 'sequence':
            self.odoms.append(o)
            self._drain()
            return
        if self.steer is not None:
            self._step(o, self.state if self.state is not None else np.full(9, np.nan))
            return
        if self.psi_c is None:
            self.psi_c = o.psi  # no command yet: hold the current heading
            self.t_cmd = o.t
        if self.t_cmd is None:
            self.t_cmd = o.t
        stale = o.t - self.t_cmd > self.timeout
        if stale and not self.stale:
            self.get_logger().warning(f'heading_cmd stale for {o.t - self.t_cmd:.1f} s: holding '
                                      f'the last commanded heading')
        self.stale = stale
        self._step(o, self.psi_c)

    def _drain(self):
        while self.odoms and self.headings:
            o = self.odoms.popleft()
            cmd = self.headings.popleft()
            if self.steer is None and not math.isfinite(cmd):
                self._refuse_command(cmd)
                cmd = self.psi_c if self.psi_c is not None else o.psi
            self._step(o, cmd)

    def _step(self, o, psi_c):
        if self.steer is not None:  # psi_c is the path state here
            n_bad, recovering = self.steer.n_rejected, self.steer.recovering
            self.msg.data = self.steer.update(psi_c, o.t)
            if self.steer.recovering != recovering:
                self.get_logger().info(
                    f'cross-track {psi_c[0]:.0f} m: ' + ('outside the policy\'s training region, '
                                                         'ILOS + PD steers' if self.steer.recovering
                                                         else 'the policy steers again'))
            if self.steer.n_rejected != n_bad:
                self.get_logger().warning(f'invalid path_state held the rudder '
                                          f'({self.steer.n_rejected} so far)',
                                          throttle_duration_sec=5.0)
            self.pub.publish(self.msg)
            return
        dt = 0.0 if self.t_prev is None else o.t - self.t_prev
        self.t_prev = o.t
        self.psi_c = psi_c
        n_bad = self.controller.n_rejected
        # A first step (dt = 0) only initialises the rate limiter's memory.
        rudder = self.controller.update(o.psi, o.r, psi_c, dt if dt > 0.0 else 1e-9)
        if self.controller.n_rejected != n_bad:
            self.get_logger().warning(f'non-finite input held the rudder '
                                      f'({self.controller.n_rejected} so far)',
                                      throttle_duration_sec=5.0)
        self.msg.data = float(rudder) if math.isfinite(rudder) else 0.0
        self.pub.publish(self.msg)


def main(args=None):
    return run_node(AutopilotNode, args=args)


if __name__ == '__main__':
    raise SystemExit(main())
