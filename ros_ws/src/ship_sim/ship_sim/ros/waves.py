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

from ship_sim.environment.sea_state import SPECTRUM_NAMES as SPECTRA
from ship_sim.environment.sea_state import SeaState, ShipWaves, rao_table_for, superpose
from ship_sim.environment.sea_state_relations import vw2hs
from ship_sim.frames import psi_to_yaw
from ship_sim.ros.conversions import fill_odometry
from ship_sim.ros.params import ParameterError
from ship_sim.ros.qos import LATCHED

#: parameter value -> ship_sim.environment spectrum name
SEA_STATE_LABELS = ('hs_m', 'tp_s', 'spectrum(0 jonswap 1 modified_pm 2 torsethaugen)', 'gamma',
                    'direction_rad(towards, cw from north)', 'spreading', 'n_frequencies',
                    'n_directions', 'omega_max_rad_s', 'seed')


def declare_waves(p, model):
    """Declare the waves_* parameters on NodeParameters ``p``; the SeaState (None if calm)."""
    hs = p.param('waves_hs')
    wind = p.param('waves_wind_speed')
    tp = p.param('waves_tp')
    spectrum = p.param('waves_spectrum')
    gamma = p.param('waves_gamma')
    direction = p.param('waves_direction_deg')
    spreading = p.param('waves_spreading')
    n_freq = p.param('waves_n_frequencies')
    n_dir = p.param('waves_n_directions')
    omega_max = p.param('waves_omega_max')
    seed = p.param('waves_seed')
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
