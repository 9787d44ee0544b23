"""vessel_node's waves: their parameters, the latched ``sea_state`` topic and the odometry
with the wave-frequency motion superposed (ship_sim.environment.sea_state; Fossen 2021,
Sec. 10.4, output superposition: the manoeuvring state is untouched, only what odom reports
moves with the waves).

Odometry with waves (REP-103/105 frames, as without): position = the manoeuvring position plus
the wave-frequency surge/sway displacement rotated by the heading, z = -heave (up);
orientation = roll phi, pitch -theta, yaw pi/2 - (psi + psi_WF) (Fossen's ZYX angles in
NED/FRD -> ENU/FLU); twist = manoeuvring velocities over ground plus the wave-frequency body
rates [u, -v, -w] and [p, -q, -r].
"""
import math

from std_msgs.msg import Float64MultiArray, MultiArrayDimension

from ship_sim.environment.sea_state import SeaState, ShipWaves, rao_table_for, superpose
from ship_sim.environment.sea_state_relations import vw2hs
from ship_sim.frames import psi_to_yaw
from ship_sim.ros.conversions import fill_odometry
from ship_sim.ros.params import ParameterError
from ship_sim.ros.qos import LATCHED

#: parameter value -> ship_sim.environment spectrum name
SPECTRA = {'jonswap': 'JONSWAP', 'modified_pm': 'Modified PM', 'torsethaugen': 'Torsethaugen'}
SEA_STATE_LABELS = ('hs_m', 'tp_s', 'spectrum(0 jonswap 1 modified_pm 2 torsethaugen)', 'gamma',
                    'direction_rad(towards, cw from north)', 'spreading', 'n_frequencies',
                    'n_directions', 'omega_max_rad_s', 'seed')


def declare_waves(p, model):
    """Declare the waves_* parameters on NodeParameters ``p``; the SeaState (None if calm)."""
    hs = p.declare('waves_hs', 0.0, 'significant wave height (0 = calm sea; see also '
                   'waves_wind_speed)', lo=0.0, hi=20.0, unit='m', read_only=True)
    wind = p.declare('waves_wind_speed', 0.0, 'fully developed sea of this wind speed: Hs = '
                     '0.21 V^2 / g (MSS vw2hs), Pierson-Moskowitz peak (0 = use waves_hs)',
                     lo=0.0, hi=40.0, unit='m/s', read_only=True)
    tp = p.declare('waves_tp', 0.0, 'peak period (0 = the Pierson-Moskowitz peak of the Hs)',
                   lo=0.0, hi=30.0, unit='s', read_only=True)
    spectrum = p.declare('waves_spectrum', 'jonswap', 'wave spectrum', choices=tuple(SPECTRA),
                         read_only=True)
    gamma = p.declare('waves_gamma', 3.3, 'JONSWAP peak enhancement (0 = DNV rule)', lo=0.0,
                      hi=7.0, read_only=True)
    direction = p.declare('waves_direction_deg', 0.0, 'main direction the waves travel '
                          'towards, clockwise from north (as the current)', lo=-360.0,
                          hi=360.0, unit='deg', read_only=True)
    spreading = p.declare('waves_spreading', False, 'cos^2 directional spreading',
                          read_only=True)
    n_freq = p.declare('waves_n_frequencies', 100, 'wave components in frequency', lo=1,
                       hi=2000, read_only=True)
    n_dir = p.declare('waves_n_directions', 16, 'wave directions with spreading', lo=2, hi=100,
                      read_only=True)
    omega_max = p.declare('waves_omega_max', 3.0, 'highest wave frequency', lo=0.5, hi=6.0,
                          unit='rad/s', read_only=True)
    seed = p.declare('waves_seed', 0, 'random seed of the wave components (same seed, same '
                     'waves)', lo=0, hi=2**31 - 1, read_only=True)
    if hs > 0.0 and wind > 0.0:
        raise ParameterError('waves_wind_speed', wind, '0 when waves_hs is given (one of them)')
    if wind > 0.0:
        hs = float(vw2hs(wind))
    if hs == 0.0:
        return None
    try:
        sea = SeaState(hs=hs, tp=tp, spectrum=SPECTRA[spectrum], gamma=gamma,
                       direction=math.radians(direction), spreading=spreading,
                       n_frequencies=n_freq, n_directions=n_dir, omega_max=omega_max, seed=seed)
        sea.components()   # JONSWAP's validity check (w0 sqrt(Hs) <= 1.75)
        rao_table_for(model.name, model.length)
    except ValueError as exc:
        raise ParameterError('waves_hs', hs, f'a sea state the model takes: {exc}') from None
    return sea


class WaveOdometry:
    """The wave-frequency motion of one vessel and the odometry it makes."""

    def __init__(self, node, sea, model):
        self.sea = sea
        self.waves = ShipWaves(sea, rao_table_for(model.name, model.length))
        self._pub = node.create_publisher(Float64MultiArray, 'sea_state', LATCHED)
        msg = Float64MultiArray()
        msg.layout.dim = [MultiArrayDimension(label=','.join(SEA_STATE_LABELS),
                                              size=len(SEA_STATE_LABELS),
                                              stride=len(SEA_STATE_LABELS))]
        msg.data = [sea.hs, 2.0 * math.pi / sea.peak_frequency,
                    float(tuple(SPECTRA.values()).index(sea.spectrum)), sea.gamma, sea.direction,
                    float(sea.spreading), float(sea.n_frequencies), float(sea.n_directions),
                    sea.omega_max, float(sea.seed)]
        self._pub.publish(msg)

    def describe(self):
        return f'waves {self.sea.describe()} (RAO {self.waves.response.table.vessel}' + (
            f' Froude-scaled x{self.waves.response.table.scale:.3f})'
            if self.waves.response.table.scale != 1.0 else ')')

    def fill(self, msg, t, north, east, psi, u, v, r, speed):
        """fill_odometry with the wave-frequency motion at time t (s) and speed (m/s) added."""
        eta, nu = self.waves.motion(t, speed, psi)
        fill_odometry(msg, t, *superpose(eta, nu, north, east, psi, u, v, r))
        msg.pose.pose.position.z = -float(eta[2])
        roll, pitch, yaw = float(eta[3]), -float(eta[4]), float(psi_to_yaw(psi + eta[5]))
        cr, sr = math.cos(roll / 2), math.sin(roll / 2)
        cp, sp = math.cos(pitch / 2), math.sin(pitch / 2)
        cy, sy = math.cos(yaw / 2), math.sin(yaw / 2)
        o = msg.pose.pose.orientation
        o.x = sr * cp * cy - cr * sp * sy
        o.y = cr * sp * cy + sr * cp * sy
        o.z = cr * cp * sy - sr * sp * cy
        o.w = cr * cp * cy + sr * sp * sy
        tw = msg.twist.twist
        tw.linear.z = -float(nu[2])
        tw.angular.x, tw.angular.y = float(nu[3]), -float(nu[4])
        return msg
