"""Nomoto steering models (first and second order) with linear kinematics and a rudder servo.

In the project's sign (NED, r > 0 to starboard; unified rudder, positive turns to port):
    first order:   T r_dot + r = -K delta          (r_dot = a r + b delta, a = -1/T, b = -K/T)
    second order:  T1 T2 r_ddot + (T1 + T2) r_dot + r = -K (delta + T3 delta_dot)
with K > 0 for a course-stable ship (Nomoto et al. 1957; Fossen 2011, Ch. 7); the first-order
model uses T = T1 + T2 - T3. Presets 'mariner' and 'tanker' are Lee 2004, Table 2.2 (Fossen's
table; the tanker is course unstable, T1 < 0). Kinematics psi_dot = r, x_dot = U cos psi,
y_dot = U sin psi (Lee 2004 eq. 4.29). State (SI): [u, v, r, north, east, psi, delta]
(+ r_dot for the second order), u constant, v = 0; input [delta_c] (rad, unified sign); the
rudder servo clips the command, lags it by a first-order filter and clips its rate (as MSS).

Why the signs map as they do, the presets as read from the source's OCR (and the one misprint
corrected), and the servo: ros_ws/src/ship_sim/doc/nomoto.md.
"""
import numpy as np

from .card import SHIP_OMEGA_N_ND_REASON, VesselCard
from .constant_speed import ConstantSpeedModel, check_param

# Preset values: Table 2.2 of Lee 2004 in the unified rudder sign (doc/nomoto.md).
# Rudder limits are our choice (the table has none): the mariner gets those of the MSS mariner
# model (40 deg, 5 deg/s); the tanker the SOLAS minimum steering rate (35 deg to 30 deg on the
# other side in 28 s: 65/28 = 2.32 deg/s) with a 35 deg limit.
PRESETS = {
    'mariner': dict(K=0.185, T1=118.0, T2=7.8, T3=18.5, length=161.0, U=7.7,
                    rudder_max=np.deg2rad(40.0), rudder_rate_max=np.deg2rad(5.0)),
    'tanker': dict(K=-0.019, T1=-124.1, T2=16.4, T3=46.0, length=350.0, U=8.1,
                   rudder_max=np.deg2rad(35.0), rudder_rate_max=np.deg2rad(65.0 / 28.0)),
}
PRESET_NAMES = tuple(PRESETS)

#: Default rudder servo time constant (s), as in the MSS ship models.
RUDDER_TIME_CONSTANT = 1.0




class _NomotoBase(ConstantSpeedModel):
    """Shared parts: parameters, rudder servo, kinematics, inputs, initial state."""

    source = 'Nomoto (1957); Fossen (2011) Ch. 7; presets: Lee 2004 Table 2.2'

    def __init__(self, preset='mariner', *, U=None, length=None, rudder_max=None,
                 rudder_rate_max=None, rudder_time_constant=RUDDER_TIME_CONSTANT,
                 speed_scaling=False, **gains):
        if preset is not None and preset not in PRESETS:
            raise ValueError(f"preset = {preset!r} is not allowed; allowed: "
                             f"{', '.join(PRESET_NAMES)} or None (explicit gains)")
        p = dict(PRESETS[preset]) if preset is not None else {}
        self.preset = preset
        U0 = p.get('U')
        p.update({k: v for k, v in gains.items() if v is not None})
        for key, val in (('U', U), ('length', length), ('rudder_max', rudder_max),
                         ('rudder_rate_max', rudder_rate_max)):
            if val is not None:
                p[key] = val
        p.setdefault('U', 5.0)
        p.setdefault('length', 100.0)
        # U = 0 is allowed (a hull at rest in the water, e.g. to watch it drift with the
        # current); its yaw equation still answers the rudder, which is not physical.
        self.U = check_param('U', p['U'], 0.0, 30.0)
        self.length = check_param('length', p['length'], 0.0, 500.0, lo_open=True)
        self.rudder_max = check_param('rudder_max', p.get('rudder_max', np.deg2rad(35.0)),
                                      0.0, np.pi / 2, lo_open=True)
        self.rudder_rate_max = check_param('rudder_rate_max',
                                           p.get('rudder_rate_max', np.deg2rad(5.0)),
                                           0.0, 2.0 * np.pi, lo_open=True)
        self.rudder_time_constant = check_param('rudder_time_constant', rudder_time_constant,
                                                0.0, 60.0, lo_open=True)
        # Nomoto gains scale as K = K' U / L, T = T' L / U (Fossen, nondimensional form); with
        # speed_scaling the gains (preset or given), taken as valid at the preset's speed U0,
        # are moved to U.
        if speed_scaling:
            if U0 is None:
                raise ValueError('speed_scaling = True needs a preset (its speed is the reference)')
            check_param('U', self.U, 0.0, 30.0, lo_open=True)
            s = self.U / U0
            p['K'] = p['K'] * s
            for key in ('T', 'T1', 'T2', 'T3'):
                if key in p:
                    p[key] = p[key] / s
        self._set_gains(p)

    # -- rudder servo and kinematics, shared by both orders ------------------------------------
    def _kinematics(self, x, xdot):
        u, v, psi = x[..., self.IU], x[..., self.IV], x[..., self.IPSI]
        c, s = np.cos(psi), np.sin(psi)
        xdot[..., self.IX] = u * c - v * s
        xdot[..., self.IY] = u * s + v * c

    def nomoto_ab(self):
        """First-order Nomoto (a, b) in the unified sign: r_dot = a r + b delta (1/s, 1/s^2)."""
        T = self.T_first_order
        return -1.0 / T, -self.K / T


class Nomoto1(_NomotoBase):
    """First-order Nomoto model T r_dot + r = -K delta (unified delta) + kinematics + servo.

    Parameters: ``preset`` ('mariner', 'tanker' or None) or explicit ``K`` (1/s) and ``T`` (s);
    with a preset and no T, T = T1 + T2 - T3. ``U`` (m/s, [0, 30]), ``length`` (m),
    ``rudder_max`` (rad), ``rudder_rate_max`` (rad/s), ``rudder_time_constant`` (s),
    ``speed_scaling`` (move the preset's K, T to speed U with K ~ U, T ~ 1/U).
    """

    name = 'nomoto1'
    state_names = ('u', 'v', 'r', 'north', 'east', 'psi', 'delta')
    state_units = ('m/s', 'm/s', 'rad/s', 'm', 'm', 'rad', 'rad')
    input_names = ('delta_c',)

    def __init__(self, preset='mariner', *, K=None, T=None, **kw):
        super().__init__(preset, K=K, T=T, **kw)

    def _set_gains(self, p):
        if 'T' not in p:
            if not {'T1', 'T2', 'T3'} <= set(p):
                raise ValueError('T = None: give T (s) or a preset')
            p['T'] = p['T1'] + p['T2'] - p['T3']
        if 'K' not in p:
            raise ValueError('K = None: give K (1/s) or a preset')
        self.K = check_param('K', p['K'], -10.0, 10.0, nonzero=True)
        self.T = check_param('T', p['T'], -1e4, 1e4, nonzero=True)
        self.T_first_order = self.T

    def rhs(self, x, u):
        x = np.asarray(x, dtype=float)
        u = np.asarray(u, dtype=float)
        xdot = np.zeros(np.broadcast_shapes(x.shape, u.shape[:-1] + (x.shape[-1],)))
        r, delta = x[..., 2], x[..., 6]
        xdot[..., 2] = (-r - self.K * delta) / self.T
        xdot[..., 5] = r
        xdot[..., 6] = self._rudder_rate(delta, u[..., 0])
        self._kinematics(x, xdot)
        return xdot


class Nomoto2(_NomotoBase):
    """Second-order Nomoto model (K, T1, T2, T3) + kinematics + servo; extra state r_dot.

    T1 T2 r_ddot + (T1 + T2) r_dot + r = -K (delta + T3 delta_dot), with delta_dot the actual
    rudder rate from the servo (so the model is exact for the rate-limited rudder too).
    Parameters as Nomoto1, with ``K``, ``T1``, ``T2``, ``T3`` (s) instead of T.
    """

    name = 'nomoto2'
    state_names = ('u', 'v', 'r', 'north', 'east', 'psi', 'delta', 'r_dot')
    state_units = ('m/s', 'm/s', 'rad/s', 'm', 'm', 'rad', 'rad', 'rad/s^2')
    input_names = ('delta_c',)
    IRDOT = 7

    def __init__(self, preset='mariner', *, K=None, T1=None, T2=None, T3=None, **kw):
        super().__init__(preset, K=K, T1=T1, T2=T2, T3=T3, **kw)

    def _set_gains(self, p):
        for key in ('K', 'T1', 'T2', 'T3'):
            if key not in p:
                raise ValueError(f'{key} = None: give it or a preset')
        self.K = check_param('K', p['K'], -10.0, 10.0, nonzero=True)
        self.T1 = check_param('T1', p['T1'], -1e4, 1e4, nonzero=True)
        self.T2 = check_param('T2', p['T2'], 0.0, 1e4, lo_open=True)
        self.T3 = check_param('T3', p['T3'], 0.0, 1e4)
        self.T_first_order = check_param('T1 + T2 - T3', self.T1 + self.T2 - self.T3,
                                    -1e4, 1e4, nonzero=True)

    def rhs(self, x, u):
        x = np.asarray(x, dtype=float)
        u = np.asarray(u, dtype=float)
        xdot = np.zeros(np.broadcast_shapes(x.shape, u.shape[:-1] + (x.shape[-1],)))
        r, delta, rdot = x[..., 2], x[..., 6], x[..., 7]
        delta_dot = self._rudder_rate(delta, u[..., 0])
        xdot[..., 2] = rdot
        xdot[..., 7] = (-(self.T1 + self.T2) * rdot - r
                        - self.K * (delta + self.T3 * delta_dot)) / (self.T1 * self.T2)
        xdot[..., 5] = r
        xdot[..., 6] = delta_dot
        self._kinematics(x, xdot)
        return xdot


# Waves: the S-175 RAOs Froude-scaled to the preset's length.
CARDS = tuple(
    VesselCard(name=cls.name, model=cls, node_kwargs={'preset': 'preset', 'nominal_speed_mps': 'U'},
               kinds={'ship', 'nomoto'}, rao=('s175', True), omega_n_nd=1.0,
               omega_n_nd_reason=SHIP_OMEGA_N_ND_REASON)
    for cls in (Nomoto1, Nomoto2))
