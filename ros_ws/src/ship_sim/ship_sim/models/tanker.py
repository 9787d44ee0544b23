"""Esso 190 000 dwt tanker (Lpp 304.8 m), 3-DOF model with shallow water, from MSS.

Source: Fossen, Marine Systems Simulator, ``CRAFT/SHIP/models/tanker.m`` (cybergalactic/MSS,
commit 736a3d1; author T. Lauvdal 1994, revised 2001-2024), after W. B. Van Berlekom and
T. A. Goddard (1972), Maneuvering of Large Tankers, Trans. SNAME 80:264-298, Appendix A.
Equations and coefficients as in tanker.m (including its 2005 correction
c = sqrt(cun u n + cnn n^2)).

State x = [u v r x y psi delta n] (NED/FRD):
  u surge velocity (m/s, must be > 0; design speed 8.23 m/s),  v sway velocity (m/s)
  r yaw rate (rad/s),  x, y north, east position (m),  psi heading (rad)
  delta actual rudder angle (rad): positive delta gives a negative yaw moment (port turn)
  n actual shaft speed (rpm; nominal 80 rpm)
Input u = [delta_c n_c h]: commanded rudder (rad), commanded shaft speed (rpm), water depth
(m, >= 18.5; the draft is 18.46 m), as the MSS function takes them. ``inputs()`` fills h
from the model's ``h`` parameter; a batch may carry a different depth per vessel.
Limits: |delta_c| <= 10 deg, |delta_dot| <= 2.33 deg/s, |n_c| <= 80 rpm, shaft time
constant 50 s. The shaft command is taken in [0, 80] rpm (``shaft_min`` = 0; the simulator
saturates commands below it): tanker.m accepts astern commands, but the model describes forward
motion only (it errors for u <= 0, and c = sqrt(cun u n + cnn n^2) is imaginary for small
negative n), so an astern command leaves its domain. At 0 rpm the tanker coasts: u decays and
stays > 0.
Shallow-water terms scale with z = T/(h - T), never exactly zero
(z = 0.0188 at h = 1000 m); Yuvz switches on for z >= 0.8 (h <= 41.5 m).
Positive rudder turns to port, so the unified command maps with sign +1.
External loads (X, Y, K, N) (ship_sim.models.mss_ship): tanker.m's gX, gY and gLN are
forces and moment divided by the ship's mass (its surge equation is u_dot = gX / m11 with
m11 = 1 - Xudot''), so the loads enter as X / m, Y / m and N / m with m = 225 500 t, the mass
SIMtanker.m states. K is ignored (3 DOF).
"""
import math

from ..environment.wind_profile import WindProfile
from .card import SHIP_OMEGA_N_ND_REASON, VesselCard
from .mss_ship import MssShip, rudder_servo

L = 304.8          # length between perpendiculars (m)
H_MIN = 18.5       # smallest water depth tanker.m accepts (m)

t = 0.22           # thrust deduction
Tm = 50.0          # shaft time constant (s)
T = 18.46          # draft (m)
MASS = 225.5e6     # kg (SIMtanker.m: 225 500 tonnes), for external loads

cun = 0.605
cnn = 38.2

Tuu = -0.00695
Tun = -0.00063
Tnn = 0.0000354

m11 = 1.050        # 1 - Xudot
m22 = 2.020        # 1 - Yvdot
m33 = 0.1232       # kz^2 - Nrdot

d11 = 2.020        # 1 + Xvr
d22 = -0.752       # Yur - 1
d33 = -0.231       # Nur - xG

Xuuz = -0.0061;   YT = 0.04;         NT = -0.02         # noqa: E702
Xuu = -0.0377;    Yvv = -2.400;      Nvr = -0.300       # noqa: E702
Xvv = 0.3;        Yuv = -1.205;      Nuv = -0.451       # noqa: E702
Xudotz = -0.05;   Yvdotz = -0.387;   Nrdotz = -0.0045   # noqa: E702
Xvrz = 0.387;     Yurz = 0.182;      Nurz = -0.047      # noqa: E702
Xccdd = -0.093;   Yvvz = -1.5;       Nvrz = -0.120      # noqa: E702
Xccbd = 0.152;    Yuvz = 0.0;        Nuvz = -0.241      # noqa: E702
Xvvzz = 0.0125;   Yccd = 0.208;      Nccd = -0.098      # noqa: E702
Yccbbd = -2.16;   Nccbbd = 0.688                        # noqa: E702
Yccbbdz = -0.191; Nccbbdz = 0.344                       # noqa: E702


class Tanker(MssShip):
    """Esso 190 000 dwt tanker (Van Berlekom & Goddard 1972) as coded in MSS tanker.m."""

    name = 'tanker'
    source = ('MSS tanker.m (cybergalactic/MSS 736a3d1): Esso 190000 dwt tanker, '
              'Van Berlekom & Goddard (1972)')
    state_names = ('u', 'v', 'r', 'x', 'y', 'psi', 'delta', 'n')
    state_units = ('m/s', 'm/s', 'rad/s', 'm', 'm', 'rad', 'rad', 'rpm')
    input_names = ('delta_c', 'n_c', 'h')
    IDELTA = 6
    IN = 7
    RUDDER_SIGN = 1.0        # positive delta turns to port already
    STATE_RUDDER_SIGN = 1.0
    rudder_max = math.radians(10.0)
    rudder_rate_max = math.radians(2.33)
    shaft_min = 0.0          # no astern: outside the model's domain (module docstring)
    shaft_max = 80.0
    shaft_nominal = 80.0
    length = L

    def __init__(self, h=1000.0, rudder_max=None, rudder_rate_max=None):
        super().__init__(rudder_max, rudder_rate_max)
        h = float(h)
        if not (math.isfinite(h) and h >= H_MIN):
            raise ValueError(f'h = {h!r} m is out of range; allowed: h >= {H_MIN} '
                             f'(the draft is {T} m)')
        #: Water depth (m), passed as the third native input.
        self.h = h

    def _extra_inputs(self):
        return (self.h,)

    def _derivatives(self, ops, u, v, r, x_n, x_e, psi, delta, x_n_rpm, delta_c, n_c_rpm, h,
                     loads=None):
        n = x_n_rpm / 60          # rps
        n_c = n_c_rpm / 60        # rps

        # Shallow-water factor; Yuvz is 0 in deep water.
        z = T / (h - T)
        yuvz = ops.where(z >= 0.8, -0.85 * (1 - 0.8 / z), Yuvz)

        delta_dot = rudder_servo(ops, delta_c, delta, self.rudder_max, self.rudder_rate_max)
        n_dot = 1 / Tm * (ops.sat(n_c, self.shaft_max / 60) - n) * 60

        beta = ops.atan(v / u)
        gT = (1 / L * Tuu * u ** 2 + Tun * u * n + L * Tnn * abs(n) * n)
        c = ops.sqrt(cun * u * n + cnn * n ** 2)
        cc = abs(c) * c

        gX = 1 / L * (Xuu * u ** 2 + L * d11 * v * r + Xvv * v ** 2 + Xccdd * cc * delta ** 2
                      + Xccbd * cc * beta * delta + L * gT * (1 - t) + Xuuz * u ** 2 * z
                      + L * Xvrz * v * r * z + Xvvzz * v ** 2 * z ** 2)

        gY = 1 / L * (Yuv * u * v + Yvv * abs(v) * v + Yccd * cc * delta + L * d22 * u * r
                      + Yccbbd * cc * abs(beta) * beta * abs(delta) + YT * gT * L
                      + L * Yurz * u * r * z + yuvz * u * v * z + Yvvz * abs(v) * v * z
                      + Yccbbdz * cc * abs(beta) * beta * abs(delta) * z)

        gLN = (Nuv * u * v + L * Nvr * abs(v) * r + Nccd * cc * delta + L * d33 * u * r
               + Nccbbd * cc * abs(beta) * beta * abs(delta) + L * NT * gT
               + L * Nurz * u * r * z + Nuvz * u * v * z + L * Nvrz * abs(v) * r * z
               + Nccbbdz * cc * abs(beta) * beta * abs(delta) * z)

        if loads is not None:   # external loads per unit mass (module docstring)
            gX = gX + loads[0] / MASS
            gY = gY + loads[1] / MASS
            gLN = gLN + loads[3] / MASS

        m11z = (m11 - Xudotz * z)
        m22z = (m22 - Yvdotz * z)
        m33z = (m33 - Nrdotz * z)

        return (gX / m11z,
                gY / m22z,
                gLN / (L ** 2 * m33z),
                ops.cos(psi) * u - ops.sin(psi) * v,
                ops.sin(psi) * u + ops.cos(psi) * v,
                r,
                delta_dot,
                n_dot)

    def _check_domain(self, x, u):
        surge = x[..., self.IU]
        self._require(surge > 0.0, 'surge velocity u must be > 0 m/s (tanker.m errors)', surge)
        # c = sqrt(cun u n + cnn n^2) is imaginary for small negative shaft speeds.
        n = x[..., self.IN] / 60
        rad = cun * surge * n + cnn * n ** 2
        self._require(rad >= 0.0, 'shaft speed n makes c = sqrt(cun u n + cnn n^2) complex '
                      f'(refused: -{60 * cun:.3g} u/{cnn} < n < 0 rpm); n in rpm',
                      x[..., self.IN])
        if u is not None:
            h = u[..., 2]
            self._require(h >= H_MIN, f'water depth h must be >= {H_MIN} m', h)


#: Above-water geometry for the wind loads (doc/results/wind_waves.md; estimates but the beam).
WIND = WindProfile(Loa=320.0, B=47.17, ALw=2500.0, AFw=850.0, A_SS=700.0, S=370.0, C=198.0, M=1,
                   sH=6.4, sL=-38.0, blendermann_type=15,
                   source='Esso 190 000 dwt tanker: beam from SIMtanker.m; Loa and areas '
                          'estimated')

CARD = VesselCard(
    name='tanker', model=Tanker, node_kwargs={'water_depth_m': 'h'}, kinds={'ship', 'mss'},
    Loa=WIND.Loa, beam=WIND.B, wind=WIND, rao=('s175', True),
    omega_n_nd=1.0, omega_n_nd_reason=SHIP_OMEGA_N_ND_REASON,
    nominal_curve=(250.0, 5000.0), policy='tanker.npz')
