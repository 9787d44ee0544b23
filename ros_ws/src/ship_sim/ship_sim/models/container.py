"""High-speed container ship (Lpp 175 m), 4-DOF surge-sway-roll-yaw model, ported from MSS.

Source: Fossen, Marine Systems Simulator, ``CRAFT/SHIP/models/container.m``
(cybergalactic/MSS, commit 736a3d1; author T. Lauvdal 1994, revised 2001-2024), after
K. Son and K. Nomoto (1982), On the Coupled Motion of Steering and Rolling of a High Speed
Container Ship, Naval Architect of Ocean Engineering 20:73-83 (J.S.N.A. Japan 150, 1981).
Equations and coefficients as in container.m (including its 2022 correction of u_P).

State x = [u v r x y psi p phi delta n] (NED/FRD):
  u, v surge, sway velocity (m/s),  r yaw rate (rad/s),  x, y north, east position (m)
  psi heading (rad),  p roll rate (rad/s),  phi roll angle (rad)
  delta actual rudder angle (rad): positive delta gives r > 0 (starboard turn)
  n actual shaft speed (rpm, must be > 0)
Input u = [delta_c n_c]: commanded rudder (rad), commanded shaft speed (rpm).
Nondimensional coefficients are scaled with the current speed U = sqrt(u^2 + v^2).
Limits: |delta_c| <= 10 deg, |delta_dot| <= 5 deg/s, |n_c| <= 160 rpm; shaft time constant
5.65/n s (n in rps) above 0.3 rps, else 18.83 s. The shaft command is taken in [1, 160] rpm
(``shaft_min`` = 1 rpm; the simulator saturates commands below it): container.m errors for
n <= 0 and describes forward motion only, so -160 rpm left its domain within 5 s, and a 0 rpm
command lets n decay towards 0, where it does too; 1 rpm keeps n > 0 and the ship coasting.
Positive rudder turns to starboard, so the unified command (positive = port) maps with sign -1.
External loads (X, Y, K, N) (ship_sim.models.mss_ship) enter X, Y, K, N in the prime
system of container.m: forces / (1/2 rho L^2 U^2), moments / (1/2 rho L^3 U^2), rho = 1025.
"""
import math

from ..environment.wind_profile import WindProfile
from .card import SHIP_OMEGA_N_ND_REASON, VesselCard
from .mss_ship import MssShip, rudder_servo

L = 175.0                       # length between perpendiculars (m)

# Main dimensions and nondimensional mass/inertia (container.m).
m = 0.00792;     mx = 0.000238;   my = 0.007049          # noqa: E702
Ix = 0.0000176;  alphay = 0.05;   lx = 0.0313            # noqa: E702
ly = 0.0313;     Iz = 0.000456                           # noqa: E702
Jx = 0.0000034;  Jz = 0.000419                           # noqa: E702

g = 9.81
nabla = 21222.0
AR = 33.0376
Delta = 1.8219
D = 6.533
GM = 0.3 / L
rho = 1025.0
t = 0.175

Xuu = -0.0004226;    Xvr = -0.00311;     Xrr = 0.00020           # noqa: E702
Xphiphi = -0.00020;  Xvv = -0.00386                              # noqa: E702

Kv = 0.0003026;      Kr = -0.000063;     Kp = -0.0000075         # noqa: E702
Kphi = -0.000021;    Kvvv = 0.002843;    Krrr = -0.0000462       # noqa: E702
Kvvr = -0.000588;    Kvrr = 0.0010565;   Kvvphi = -0.0012012     # noqa: E702
Kvphiphi = -0.0000793; Krrphi = -0.000243; Krphiphi = 0.00003569  # noqa: E702

Yv = -0.0116;        Yr = 0.00242;       Yp = 0.0                # noqa: E702
Yphi = -0.000063;    Yvvv = -0.109;      Yrrr = 0.00177          # noqa: E702
Yvvr = 0.0214;       Yvrr = -0.0405;     Yvvphi = 0.04605        # noqa: E702
Yvphiphi = 0.00304;  Yrrphi = 0.009325;  Yrphiphi = -0.001368    # noqa: E702

Nv = -0.0038545;     Nr = -0.00222;      Np = 0.000213           # noqa: E702
Nphi = -0.0001424;   Nvvv = 0.001492;    Nrrr = -0.00229         # noqa: E702
Nvvr = -0.0424;      Nvrr = 0.00156;     Nvvphi = -0.019058      # noqa: E702
Nvphiphi = -0.0053766; Nrrphi = -0.0038592; Nrphiphi = 0.0024195  # noqa: E702

kk = 0.631;     epsilon = 0.921;  xR = -0.5       # noqa: E702
wp = 0.184;     tau = 1.09;       xp = -0.526     # noqa: E702
cpv = 0.0;      cpr = 0.0;        ga = 0.088      # noqa: E702
cRr = -0.156;   cRrrr = -0.275;   cRrrv = 1.96    # noqa: E702
cRX = 0.71;     aH = 0.237;       zR = 0.033      # noqa: E702
xH = -0.48

# Masses and moments of inertia.
m11 = (m + mx)
m22 = (m + my)
m32 = -my * ly
m42 = my * alphay
m33 = (Ix + Jx)
m44 = (Iz + Jz)
detM = m22 * m33 * m44 - m32 ** 2 * m44 - m42 ** 2 * m33

# Speed-independent factors of W, FN and T, grouped as container.m evaluates them.
_W_NUM = rho * g * nabla                            # W = _W_NUM / (rho L^2 U^2 / 2)
_FN_GAIN = -((6.13 * Delta) / (Delta + 2.25)) * (AR / L ** 2)
_T_NUM = 2 * rho * D ** 4                           # T = _T_NUM / (U^2 L^2 rho) KT n|n|


class Container(MssShip):
    """Container ship (Son & Nomoto 1982), 4 DOF with roll, as coded in MSS container.m."""

    name = 'container'
    source = ('MSS container.m (cybergalactic/MSS 736a3d1): high-speed container ship, '
              'Son & Nomoto (1982), 4 DOF with roll')
    state_names = ('u', 'v', 'r', 'x', 'y', 'psi', 'p', 'phi', 'delta', 'n')
    state_units = ('m/s', 'm/s', 'rad/s', 'm', 'm', 'rad', 'rad/s', 'rad', 'rad', 'rpm')
    input_names = ('delta_c', 'n_c')
    IP = 6
    IPHI = 7
    IDELTA = 8
    IN = 9
    RUDDER_SIGN = -1.0       # positive delta turns to starboard
    STATE_RUDDER_SIGN = -1.0
    rudder_max = math.radians(10.0)
    rudder_rate_max = math.radians(5.0)
    shaft_min = 1.0          # no astern, n > 0: the model's domain (module docstring)
    shaft_max = 160.0
    shaft_nominal = 70.0     # SIMcontainer.m starts at 70 rpm
    length = L

    def __init__(self, rudder_max=None, rudder_rate_max=None):
        super().__init__(rudder_max, rudder_rate_max)

    def _derivatives(self, ops, x_u, x_v, x_r, x_n, x_e, psi, x_p, phi, delta, x_n_rpm,
                     delta_c, n_c_rpm, loads=None):
        U = ops.sqrt(x_u ** 2 + x_v ** 2)
        W = _W_NUM / (rho * L ** 2 * U ** 2 / 2)

        # Nondimensional velocities. container.m also scales n, n_c by L/U and back before
        # use; the shaft equations below work in rps as it does after scaling back.
        u = x_u / U
        v = x_v / U
        p = x_p * L / U
        r = x_r * L / U
        n = x_n_rpm / 60
        n_c = ops.sat(n_c_rpm / 60, self.shaft_max / 60)

        delta_dot = rudder_servo(ops, delta_c, delta, self.rudder_max, self.rudder_rate_max)

        Tm = ops.where(n > 0.3, 5.65 / n, 18.83)
        n_dot = 1 / Tm * (n_c - n) * 60

        # Powers as products: numpy's pow with a negative base is far slower (doc/results/performance.md).
        v2, r2, phi2 = v * v, r * r, phi * phi
        v3, r3 = v2 * v, r2 * r

        # Propeller and rudder.
        vR = ga * v + cRr * r + cRrrr * r3 + cRrrv * r2 * v
        uP = u * ((1 - wp) + tau * ((v + xp * r) ** 2 + cpv * v + cpr * r))
        J = uP * U / (n * D)
        KT = 0.527 - 0.455 * J
        uR = uP * epsilon * ops.sqrt(1 + 8 * kk * KT / (math.pi * J ** 2))
        alphaR = delta + ops.atan(vR / uR)
        FN = _FN_GAIN * (uR ** 2 + vR ** 2) * ops.sin(alphaR)
        T = _T_NUM / (U ** 2 * L ** 2 * rho) * KT * n * abs(n)

        cd = ops.cos(delta)
        X = (Xuu * u ** 2 + (1 - t) * T + Xvr * v * r + Xvv * v2 + Xrr * r2
             + Xphiphi * phi2 + cRX * FN * ops.sin(delta) + (m + my) * v * r)

        Y = (Yv * v + Yr * r + Yp * p + Yphi * phi + Yvvv * v3 + Yrrr * r3
             + Yvvr * v2 * r + Yvrr * v * r2 + Yvvphi * v2 * phi
             + Yvphiphi * v * phi2 + Yrrphi * r2 * phi + Yrphiphi * r * phi2
             + (1 + aH) * FN * cd - (m + mx) * u * r)

        K = (Kv * v + Kr * r + Kp * p + Kphi * phi + Kvvv * v3 + Krrr * r3
             + Kvvr * v2 * r + Kvrr * v * r2 + Kvvphi * v2 * phi
             + Kvphiphi * v * phi2 + Krrphi * r2 * phi + Krphiphi * r * phi2
             - (1 + aH) * zR * FN * cd + mx * lx * u * r - W * GM * phi)

        N = (Nv * v + Nr * r + Np * p + Nphi * phi + Nvvv * v3 + Nrrr * r3
             + Nvvr * v2 * r + Nvrr * v * r2 + Nvvphi * v2 * phi
             + Nvphiphi * v * phi2 + Nrrphi * r2 * phi + Nrphiphi * r * phi2
             + (xR + aH * xH) * FN * cd)

        if loads is not None:   # external loads in the prime system (module docstring)
            q = 0.5 * rho * L ** 2 * U ** 2
            X = X + loads[0] / q
            Y = Y + loads[1] / q
            K = K + loads[2] / (q * L)
            N = N + loads[3] / (q * L)

        cpsi, spsi, cphi = ops.cos(psi), ops.sin(psi), ops.cos(phi)
        return (X * (U ** 2 / L) / m11,
                -((-m33 * m44 * Y + m32 * m44 * K + m42 * m33 * N) / detM) * (U ** 2 / L),
                ((-m42 * m33 * Y + m32 * m42 * K + N * m22 * m33 - N * m32 ** 2) / detM)
                * (U ** 2 / L ** 2),
                (cpsi * u - spsi * cphi * v) * U,
                (spsi * u + cpsi * cphi * v) * U,
                cphi * r * (U / L),
                ((-m32 * m44 * Y + K * m22 * m44 - K * m42 ** 2 + m32 * m42 * N) / detM)
                * (U ** 2 / L ** 2),
                p * (U / L),
                delta_dot,
                n_dot)

    def _check_domain(self, x, u):
        # container.m errors for U <= 0 and n <= 0; u = 0 makes the advance ratio J = 0 and
        # the rudder inflow 0 * inf (NaN), and the model describes forward motion only.
        surge = x[..., self.IU]
        self._require(surge > 0.0, 'surge velocity u must be > 0 m/s (and U > 0)', surge)
        n = x[..., self.IN]
        self._require(n > 0.0, 'shaft speed n must be > 0 rpm (container.m errors)', n)


#: Above-water geometry for the wind loads (doc/results/wind_waves.md; estimates but the beam).
WIND = WindProfile(Loa=183.0, B=25.4, ALw=2100.0, AFw=450.0, A_SS=800.0, S=220.0, C=95.0, M=1,
                   sH=6.1, sL=-3.5, blendermann_type=4,
                   source='S-175 container ship: beam from container.m; Loa and areas '
                          'estimated')

# The S-175 is this ship: its RAO table needs no scaling.
CARD = VesselCard(
    name='container', model=Container, node_kwargs={}, kinds={'ship', 'mss'},
    Loa=WIND.Loa, beam=WIND.B, wind=WIND, rao=('s175', False),
    omega_n_nd=1.0, omega_n_nd_reason=SHIP_OMEGA_N_ND_REASON,
    nominal_curve=(250.0, 4000.0), policy='container.npz')
