"""Mariner-class cargo vessel (Lpp 160.93 m), 3-DOF manoeuvring model, ported from MSS.

Source: Fossen, Marine Systems Simulator, ``CRAFT/SHIP/models/mariner.m`` (cybergalactic/MSS,
commit 736a3d1; author T. Lauvdal 1994, revised 2001-2024), after M. S. Chislett and
J. Stroem-Tejsen (1965), Planar Motion Mechanism Tests and Full-Scale Steering and
Manoeuvring Predictions for a Mariner Class Vessel, Tech. Rep. Hy-5, Hydro- and Aerodynamics
Laboratory, Lyngby, Denmark. Equations and coefficients as in mariner.m.

State x = [u v r x y psi delta] (NED/FRD):
  u     surge velocity perturbation about U0 (m/s); total surge speed = U0 + u
  v     sway velocity (m/s),  r  yaw rate (rad/s)
  x, y  north, east position (m),  psi  heading (rad)
  delta actual rudder angle (rad); positive delta gives r < 0 (port turn)
Input u = [ui]: commanded rudder (rad). mariner.m sets delta_c = -ui, so a positive ui turns
to starboard and the rudder settles at -ui. Hence the unified command (positive = port) is
ui = -rudder_cmd and the rudder state is already in the unified sign.
Nondimensional coefficients are scaled with the current speed U = sqrt((U0 + u)^2 + v^2).
Limits: |delta_c| <= 40 deg, |delta_dot| <= 5 deg/s. The model has no propulsion input: its
only straight-running speed is U0 (at about -1.108 deg of rudder, because of the asymmetry
terms Y0, N0).
External loads (X, Y, K, N) (ship_sim.models.mss_ship) enter X, Y, N in the prime system
of the coefficients: X' = X / (1/2 rho L^2 U^2), N' = N / (1/2 rho L^3 U^2), rho = 1025
kg/m^3 (mariner.m states no density; with it m' = 798e-5 gives the 17 045 t of SIMmariner.m).
K is ignored (3 DOF).
"""
import math

from ..environment.wind_profile import WindProfile
from .card import SHIP_OMEGA_N_ND_REASON, VesselCard
from .mss_ship import MssShip, rudder_servo

L = 160.93           # length between perpendiculars (m)
U0_DEFAULT = 7.7175  # nominal speed (m/s), 15 knots
RHO = 1025.0         # water density of the prime system (kg/m^3), for external loads

# Nondimensional mass, inertia and hydrodynamic derivatives (mariner.m).
m = 798e-5
Iz = 39.2e-5
xG = -0.023

Xudot = -42e-5;   Yvdot = -748e-5;   Nvdot = 4.646e-5   # noqa: E702
Xu = -184e-5;     Yrdot = -9.354e-5; Nrdot = -43.8e-5   # noqa: E702
Xuu = -110e-5;    Yv = -1160e-5;     Nv = -264e-5       # noqa: E702
Xuuu = -215e-5;   Yr = -499e-5;      Nr = -166e-5       # noqa: E702
Xvv = -899e-5;    Yvvv = -8078e-5;   Nvvv = 1636e-5     # noqa: E702
Xrr = 18e-5;      Yvvr = 15356e-5;   Nvvr = -5483e-5    # noqa: E702
Xdd = -95e-5;     Yvu = -1160e-5;    Nvu = -264e-5      # noqa: E702
Xudd = -190e-5;   Yru = -499e-5;     Nru = -166e-5      # noqa: E702
Xrv = 798e-5;     Yd = 278e-5;       Nd = -139e-5       # noqa: E702
Xvd = 93e-5;      Yddd = -90e-5;     Nddd = 45e-5       # noqa: E702
Xuvd = 93e-5;     Yud = 556e-5;      Nud = -278e-5      # noqa: E702
Yuud = 278e-5;    Nuud = -139e-5                        # noqa: E702
Yvdd = -4e-5;     Nvdd = 13e-5                          # noqa: E702
Yvvd = 1190e-5;   Nvvd = -489e-5                        # noqa: E702
Y0 = -4e-5;       N0 = 3e-5                             # noqa: E702
Y0u = -8e-5;      N0u = 6e-5                            # noqa: E702
Y0uu = -4e-5;     N0uu = 3e-5                           # noqa: E702

# Masses and moments of inertia (rigid body + added mass).
m11 = m - Xudot
m22 = m - Yvdot
m23 = m * xG - Yrdot
m32 = m * xG - Nvdot
m33 = Iz - Nrdot
detM22 = m22 * m33 - m23 * m32


class Mariner(MssShip):
    """Mariner cargo ship (Chislett & Stroem-Tejsen 1965) as coded in MSS mariner.m."""

    name = 'mariner'
    source = ('MSS mariner.m (cybergalactic/MSS 736a3d1): Mariner class cargo vessel, '
              'Chislett & Stroem-Tejsen (1965)')
    state_names = ('u', 'v', 'r', 'x', 'y', 'psi', 'delta')
    state_units = ('m/s (perturbation about U0)', 'm/s', 'rad/s', 'm', 'm', 'rad', 'rad')
    input_names = ('ui',)
    IDELTA = 6
    IN = None
    RUDDER_SIGN = -1.0       # mariner.m: delta_c = -ui, positive ui turns to starboard
    STATE_RUDDER_SIGN = 1.0  # positive rudder state turns to port
    rudder_max = math.radians(40.0)
    rudder_rate_max = math.radians(5.0)
    length = L

    def __init__(self, U0=U0_DEFAULT, rudder_max=None, rudder_rate_max=None):
        super().__init__(rudder_max, rudder_rate_max)
        U0 = float(U0)
        if not (math.isfinite(U0) and U0 > 0.0):
            raise ValueError(f'U0 = {U0!r} m/s is out of range; allowed: U0 > 0')
        #: Nominal speed (m/s) about which the surge state is a perturbation.
        self.U0 = U0

    def _derivatives(self, ops, x_u, x_v, x_r, x_n, x_e, psi, delta, ui, loads=None):
        U0 = self.U0
        U = ops.sqrt((U0 + x_u) ** 2 + x_v ** 2)

        # Nondimensional states (prime system with the current speed U).
        u = x_u / U
        v = x_v / U
        r = x_r * L / U

        delta_dot = rudder_servo(ops, -ui, delta, self.rudder_max, self.rudder_rate_max)

        # Powers as products: numpy's pow with a negative base is far slower (doc/results/performance.md).
        u2, v2, r2, d2 = u * u, v * v, r * r, delta * delta
        u3, v3, d3 = u2 * u, v2 * v, d2 * delta

        X = (Xu * u + Xuu * u2 + Xuuu * u3 + Xvv * v2 + Xrr * r2 + Xrv * r * v
             + Xdd * d2 + Xudd * u * d2 + Xvd * v * delta + Xuvd * u * v * delta)

        Y = (Yv * v + Yr * r + Yvvv * v3 + Yvvr * v2 * r + Yvu * v * u + Yru * r * u
             + Yd * delta + Yddd * d3 + Yud * u * delta + Yuud * u2 * delta
             + Yvdd * v * d2 + Yvvd * v2 * delta + (Y0 + Y0u * u + Y0uu * u2))

        N = (Nv * v + Nr * r + Nvvv * v3 + Nvvr * v2 * r + Nvu * v * u + Nru * r * u
             + Nd * delta + Nddd * d3 + Nud * u * delta + Nuud * u2 * delta
             + Nvdd * v * d2 + Nvvd * v2 * delta + (N0 + N0u * u + N0uu * u2))

        if loads is not None:   # external loads in the prime system (module docstring)
            q = 0.5 * RHO * L ** 2 * U ** 2
            X = X + loads[0] / q
            Y = Y + loads[1] / q
            N = N + loads[3] / (q * L)

        c, s = ops.cos(psi), ops.sin(psi)
        return (X * (U ** 2 / L) / m11,
                -(-m33 * Y + m23 * N) * (U ** 2 / L) / detM22,
                (-m32 * Y + m22 * N) * (U ** 2 / L ** 2) / detM22,
                (c * (U0 / U + u) - s * v) * U,
                (s * (U0 / U + u) + c * v) * U,
                r * (U / L),
                delta_dot)

    def surge_speed(self, x):
        """Total surge speed U0 + u (m/s)."""
        return self.U0 + super().surge_speed(x)

    def _set_trim(self, x, speed, shaft):
        # No propulsion: the straight-running state of mariner.m is u = 0 (speed U0).
        if shaft is not None:
            raise ValueError(f'mariner has no shaft (got shaft={shaft!r})')
        if speed is not None and not math.isclose(speed, self.U0, rel_tol=1e-12):
            raise ValueError(f'mariner: speed = {speed!r} m/s differs from its nominal speed '
                             f'U0 = {self.U0} m/s, the only straight-running speed of this '
                             f'unpropelled model; build it with Mariner(U0={speed!r})')

    def _check_domain(self, x, u):
        U = self.speed(x)
        self._require(U > 0.0, 'speed U = sqrt((U0+u)^2+v^2) must be > 0 m/s', U)


#: Above-water geometry for the wind loads (how each number is derived: doc/results/wind_waves.md;
#: only Lpp, beam, draft and mass are given by MSS, the rest are estimates).
WIND = WindProfile(Loa=171.8, B=23.2, ALw=1500.0, AFw=310.0, A_SS=450.0, S=210.0, C=88.0, M=4,
                   sH=5.3, sL=-2.0, blendermann_type=2,
                   source='Mariner class C4-S-1a: Loa and beam of the class; areas estimated')

CARD = VesselCard(
    name='mariner', model=Mariner, node_kwargs={'nominal_speed_mps': 'U0'}, kinds={'ship', 'mss'},
    Loa=WIND.Loa, beam=WIND.B, wind=WIND, rao=('s175', True),
    omega_n_nd=1.0, omega_n_nd_reason=SHIP_OMEGA_N_ND_REASON,
    nominal_curve=(500.0, 4000.0), policy='mariner.npz')
