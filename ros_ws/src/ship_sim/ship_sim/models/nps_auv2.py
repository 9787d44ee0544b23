"""NPS AUV II linear sway/yaw steering model with bow and stern rudders, kinematics and servo.

Source: Simakis 1992 (D. A. Simakis, "Vehicle Guidance and Control along Circular Trajectories",
NPS thesis, 1992), Chapter II: eqs. (2.1)-(2.9) (sway/yaw equations, coefficients a_ij, b_i),
(2.3)-(2.5) (kinematics), (2.10)-(2.11) and (2.12)-(2.16) (Nomoto reduction, PD gains); the
vehicle data and hydrodynamic coefficients are those of the FORTRAN listings NOMO.FOR
(Appendix A) and SIMU.FOR (Appendix C), ported here unchanged. (NOMOV.FOR, Appendix B, as
printed has YVDOT where the others have YRDOT in a few terms; Yrdot = 0 and Yvdot != 0, so we
follow A and C.)

Nondimensional model (lengths in L, time in L/U, seed eqs. 2.8-2.9):
    v'_dot = a11 v' + a12 r' + b1 delta,       r'_dot = a21 v' + a22 r' + b2 delta
Dimensional form used here, Simakis's eqs. (2.6)-(2.7) with the surge speed u:
    v_dot = a11 (u/L) v + a12 u r + b1 (u^2/L) delta
    r_dot = a21 (u/L^2) v + a22 (u/L) r + b2 (u^2/L^2) delta
    north_dot = u cos psi - v sin psi,  east_dot = u sin psi + v cos psi,  psi_dot = r
Simakis's x, y, psi, v, r are NED/FRD (y_dot = u sin psi + v cos psi, eq. 2.5). The vehicle
steers with a stern rudder delta_s and a bow rudder delta_b = RATIO * delta_s with RATIO = -1
(the listings' RATIO), so b_i = b_i,stern + RATIO * b_i,bow; the state's delta is the stern
rudder. Native sign = unified sign: a positive stern rudder gives N_delta_s < 0 (the stern
rudder sits aft, x = -0.337 L) and the bow rudder, turned the other way, a negative moment too,
so r < 0: a turn to port.

Speed and length: Simakis 1992 works nondimensionally (SIMU.FOR integrates with unit speed; its way
points are in vehicle lengths) and gives no dimensional speed. ``NpsAuv2(U=1.0, length=1.0)``
works in Simakis's units (time in L/U, positions in L; add a fast servo, e.g.
rudder_time_constant=0.01, to approach its ideal rudder). The
defaults are the vehicle's length, 7.3 ft = 2.225 m, and our choice U = 1.0 m/s (about 2 kn).

Rudder: Simakis 1992 saturates the command at 0.4 rad and has no servo dynamics. We keep 0.4 rad and
add a fast servo (0.1 s lag, 1 rad/s rate limit; our choice) so that the state carries the
actual rudder like every other model.
"""
import numpy as np

from .card import VesselCard
from .constant_speed import ConstantSpeedModel, check_param

FT = 0.3048  # m per ft

# -- Vehicle data of the listings (US customary; only ratios enter the nondimensional model) --
WEIGHT_LB = 435.0
IZ_SLUG_FT2 = 45.0
L_FT = 7.3
RHO_SLUG_FT3 = 1.94
G_FT_S2 = 32.2
XG_FT = 0.0104
#: Nondimensional hydrodynamic derivatives (NOMO.FOR / SIMU.FOR).
COEFFS = dict(
    Yrdot=0.0, Yvdot=-0.03430, Yr=0.0, Yv=-0.10700,
    Yds=0.01241, Ydb=0.01241,
    Nrdot=-0.00047, Nvdot=0.0, Nr=-0.00390, Nv=0.0,
    Nds=-0.337 * 0.01241, Ndb=0.283 * 0.01241,
)
#: Bow rudder / stern rudder ratio of the listings.
BOW_STERN_RATIO = -1.0


def nondimensional_matrices(ratio=BOW_STERN_RATIO, coeffs=None):
    """(a11, a12, a21, a22, b1, b2) of seed eqs. (2.8)-(2.9), as computed in NOMO.FOR."""
    c = dict(COEFFS, **(coeffs or {}))
    m = WEIGHT_LB / G_FT_S2 / (0.5 * RHO_SLUG_FT3 * L_FT ** 3)
    iz = IZ_SLUG_FT2 / (0.5 * RHO_SLUG_FT3 * L_FT ** 5)
    xg = XG_FT / L_FT
    iz_n = iz - c['Nrdot']
    m_y = m - c['Yvdot']
    mx_y = m * xg - c['Yrdot']
    mx_n = m * xg - c['Nvdot']
    d = iz_n * m_y - mx_y * mx_n
    a11 = (iz_n * c['Yv'] - mx_y * c['Nv']) / d
    a12 = (iz_n * (-m + c['Yr']) - mx_y * (-m * xg + c['Nr'])) / d
    a21 = (m_y * c['Nv'] - mx_n * c['Yv']) / d
    a22 = (m_y * (-m * xg + c['Nr']) - mx_n * (-m + c['Yr'])) / d
    b11 = (iz_n * c['Yds'] - mx_y * c['Nds']) / d
    b12 = (iz_n * c['Ydb'] - mx_y * c['Ndb']) / d
    b21 = (m_y * c['Nds'] - mx_n * c['Yds']) / d
    b22 = (m_y * c['Ndb'] - mx_n * c['Ydb']) / d
    return a11, a12, a21, a22, b11 + ratio * b12, b21 + ratio * b22


def nondimensional_nomoto_ab(a11, a12, a21, a22, b1, b2):
    """Seed eq. (2.11): first-order Nomoto (a', b') from the sway/yaw model, nondimensional.

    The reduction expands the inverse of r/delta (eq. 2.10) in powers of s and keeps two terms,
    so it keeps the static gain and the first moment of the response (the low-frequency
    reduction, the same that gives T = T1 + T2 - T3 for ships). c1, c2, c3 as in Simakis 1992;
    a = -c1/c2, b = c3/c2 (NOMO.FOR writes C1 with the opposite sign and A = C1/C2).
    """
    det = a11 * a22 - a21 * a12
    n0 = a21 * b1 - a11 * b2
    c1 = -det * n0
    c2 = (a11 + a22) * n0 + b2 * det
    c3 = -n0 ** 2
    return -c1 / c2, c3 / c2


class NpsAuv2(ConstantSpeedModel):
    """NPS AUV II sway/yaw model (Simakis 1992). State [u, v, r, north, east, psi, delta]."""

    name = 'nps_auv2'
    state_names = ('u', 'v', 'r', 'north', 'east', 'psi', 'delta')
    state_units = ('m/s', 'm/s', 'rad/s', 'm', 'm', 'rad', 'rad')
    input_names = ('delta_c',)
    source = 'Simakis 1992 (NPS thesis), eqs. 2.3-2.16, NOMO.FOR/SIMU.FOR coefficients'

    def __init__(self, *, U=1.0, length=L_FT * FT, rudder_max=0.4, rudder_rate_max=1.0,
                 rudder_time_constant=0.1, bow_stern_ratio=BOW_STERN_RATIO):
        self.U = check_param('U', U, 0.0, 20.0, lo_open=True)
        self.length = check_param('length', length, 0.0, 100.0, lo_open=True)
        self.rudder_max = check_param('rudder_max', rudder_max, 0.0, np.pi / 2, lo_open=True)
        self.rudder_rate_max = check_param('rudder_rate_max', rudder_rate_max, 0.0, 100.0,
                                      lo_open=True)
        self.rudder_time_constant = check_param('rudder_time_constant', rudder_time_constant,
                                           0.0, 10.0, lo_open=True)
        self.bow_stern_ratio = check_param('bow_stern_ratio', bow_stern_ratio, -1.0, 1.0)
        (self.a11, self.a12, self.a21, self.a22,
         self.b1, self.b2) = nondimensional_matrices(self.bow_stern_ratio)

    def rhs(self, x, u):
        x = np.asarray(x, dtype=float)
        u = np.asarray(u, dtype=float)
        xdot = np.zeros(np.broadcast_shapes(x.shape, u.shape[:-1] + (x.shape[-1],)))
        su, v, r, psi, delta = x[..., 0], x[..., 1], x[..., 2], x[..., 5], x[..., 6]
        L = self.length
        xdot[..., 1] = self.a11 * su / L * v + self.a12 * su * r + self.b1 * su ** 2 / L * delta
        xdot[..., 2] = (self.a21 * su / L ** 2 * v + self.a22 * su / L * r
                        + self.b2 * su ** 2 / L ** 2 * delta)
        c, s = np.cos(psi), np.sin(psi)
        xdot[..., 3] = su * c - v * s
        xdot[..., 4] = su * s + v * c
        xdot[..., 5] = r
        xdot[..., 6] = self._rudder_rate(delta, u[..., 0])
        return xdot

    def nondimensional_nomoto_ab(self):
        """Simakis's (a, b) of eq. (2.11), time in L/U: about (-1.468, -2.859)."""
        return nondimensional_nomoto_ab(self.a11, self.a12, self.a21, self.a22,
                                        self.b1, self.b2)

    def nomoto_ab(self):
        """First-order Nomoto (a, b) at speed U in SI (1/s, 1/s^2), unified sign.

        r_dot = a r + b delta; a = a' U/L, b = b' (U/L)^2 from Simakis's reduction (2.11).
        """
        a_n, b_n = self.nondimensional_nomoto_ab()
        w = self.U / self.length
        return a_n * w, b_n * w * w


CARD = VesselCard(
    name='nps_auv2', model=NpsAuv2, node_kwargs={'nominal_speed_mps': 'U'}, kinds={'auv'},
    omega_n_nd=3.0,
    omega_n_nd_reason='the value Simakis 1992 selects for the NPS AUV II (it reproduces the '
                      "thesis's gains k1, k2' from its a', b')")
