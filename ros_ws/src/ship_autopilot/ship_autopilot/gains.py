"""Per-model autopilot gains from identified Nomoto K, T, and a factory for the controllers.

Design (the choices, documented once here; ``scripts/identify_nomoto.py`` applies them to the
identified K, T and writes ship_autopilot/data/autopilot_gains.yaml):

- PD (Angelopoulos 2011 eq. 20, Simakis 1992 eqs. 2.15-2.16; ship_guidance.heading_loop):
  k1 = -wn^2/b, k2 = -(a + 2 zeta wn)/b with a = -1/T, b = -K/T (unified rudder sign).
  ``heading_loop_design`` is the one place that turns an autopilot's parameters (table, k1/k2,
  or omega_n/zeta) into gains and a design; autopilot_node and the launcher's platoon check
  both call it.
- zeta = 0.8 for every model: Simakis 1992 (Ch. III) picks 0.8 as "neither too sluggish, nor too
  stiff"; it is inside Fossen's (2011) recommended 0.8..1.0.
- wn is chosen nondimensionally, wn' = wn L / U (time in ship lengths travelled, the natural
  time scale of steering; K' = K L/U, T' = T U/L are the usual nondimensional Nomoto gains):
  each model's card (ship_sim.models.card) states its wn' (``omega_n_nd``) and why
  (``omega_n_nd_reason``): 1.0 for the ships, 3.0 for the NPS AUV II (Simakis 1992).
- Fuzzy PID (Lee 2004 Ch. 5, ship_autopilot.fuzzy_pid): its linearisation at the origin is the
  PID K_P = k1, K_D = k2 (the PD above near zero error), K_I = k1 wn / 10 (Fossen's rule of
  thumb for the integral of a PID autopilot: integral time 10/wn, well below the closed-loop
  bandwidth, so it hardly changes the designed transient). The free scaling is set by
  e_sat = 30 deg, the heading error where block 1 saturates: larger errors are handled as a
  course change whose approach rate the fuzzy block limits to r_sat = e_sat K_P / K_D; with
  30 deg that rate is above the ships' steady turn rates at full rudder, so the fuzzy block
  does not slow course changes (a smaller e_sat would). The integrator runs only while
  |psi_e| < 10 deg (integration band, part of the anti-windup of ship_autopilot.fuzzy_pid):
  it limits the overshoot the integral adds to large course changes, and any offset the rudder
  can hold leaves a PD error well inside the band (k1 is of order 1).

Files (data YAML read by this module; the autopilot node chooses one model's entry), in the
folder the model's card names (``gain_tables``; by default this package's data/):
- nomoto_gains.yaml: identified K, T, a, b per model with the manoeuvre used.
- autopilot_gains.yaml: the design choices above and the resulting gains per model.
"""
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .fuzzy_pid import FuzzyPIDAutopilot, FuzzyPIDGains, scaling_from_pid
from ship_guidance.heading_loop import pd_design, pd_gains

from .pd import PDAutopilot, nomoto_ab
from .rudder import RudderLimiter

#: Default damping ratio (Simakis 1992 Ch. III).
ZETA = 0.8
#: Integral gain of the fuzzy PID's linearisation: K_I = K_P * wn * KI_FACTOR.
KI_FACTOR = 0.1
#: Heading error (deg) where the fuzzy PID's error input reaches the edge of its universe.
E_SAT_DEG = 30.0

#: The fuzzy PID integrates only while |heading error| is below this (deg).
INTEGRATION_BAND_DEG = 10.0

#: Controller names accepted by ``build_autopilot``.
CONTROLLERS = ('pd', 'fuzzy_pid')

#: Gain tables ship as package data next to this module (source tree and install alike).
DATA_DIR = Path(__file__).resolve().parent / 'data'


def config_dir(model=None):
    """Folder of the gain tables of ``model`` (its card's ``gain_tables``), or of the shipped
    models (package data; scripts/identify_nomoto.py writes them)."""
    if model is not None:
        from ship_sim.models import card
        folder = card(model).gain_tables
        if folder is not None:
            return Path(folder)
    return DATA_DIR


def omega_n_nd(model):
    """The nondimensional closed-loop natural frequency wn L / U of ``model`` (its card)."""
    from ship_sim.models import card
    return float(card(model).omega_n_nd)


def design_gains(K, T, speed, length, omega_n_nd=1.0, zeta=ZETA, ki_factor=KI_FACTOR,
                 e_sat=np.deg2rad(E_SAT_DEG),
                 integration_band=np.deg2rad(INTEGRATION_BAND_DEG)):
    """PD and fuzzy PID gains for a first-order Nomoto model (K 1/s, T s) at speed U (m/s).

    e_sat, integration_band in rad. Returns a dict: omega_n (rad/s), omega_n_nd, zeta,
    pd {k1, k2}, fuzzy_pid {kp, kd, ki, e_sat_deg, integration_band_deg, GE, GR, GA, GU, L}.
    ValueError if the design gives a non-positive PD gain (wn below what the ship's own yaw
    damping already provides: 2 zeta wn <= 1/T).
    """
    if not (np.isfinite(speed) and speed > 0 and np.isfinite(length) and length > 0):
        raise ValueError(f'speed = {speed!r}, length = {length!r} must be positive')
    omega_n = omega_n_nd * speed / length
    a, b = nomoto_ab(K, T)
    k1, k2 = pd_gains(a, b, omega_n=omega_n, zeta=zeta)
    if not (k1 > 0 and k2 > 0):
        raise ValueError(f'PD design gives k1 = {k1:.4g}, k2 = {k2:.4g} (need > 0) for K = {K}, '
                         f'T = {T}, omega_n = {omega_n:.4g}: raise omega_n')
    ki = k1 * omega_n * ki_factor
    g = scaling_from_pid(k1, k2, ki, e_sat)
    return {
        'omega_n': float(omega_n), 'omega_n_nd': float(omega_n_nd), 'zeta': float(zeta),
        'pd': {'k1': float(k1), 'k2': float(k2)},
        'fuzzy_pid': {'kp': float(k1), 'kd': float(k2), 'ki': float(ki),
                      'e_sat_deg': float(np.rad2deg(e_sat)),
                      'integration_band_deg': float(np.rad2deg(integration_band)),
                      'GE': g.GE, 'GR': g.GR, 'GA': g.GA, 'GU': g.GU, 'L': g.L},
    }


def load_yaml(path):
    from ship_sim.safe_load import load_yaml_file
    return load_yaml_file(path)


def nomoto_gains(model, path=None):
    """Identified {K, T, a, b, ...} of ``model`` from its nomoto_gains.yaml (or ``path``)."""
    data = load_yaml(path or config_dir(model) / 'nomoto_gains.yaml')
    return _entry(data, model, path or 'nomoto_gains.yaml')


def autopilot_gains(model, path=None):
    """Designed gains of ``model`` from its autopilot_gains.yaml (or ``path``)."""
    data = load_yaml(path or config_dir(model) / 'autopilot_gains.yaml')
    return _entry(data, model, path or 'autopilot_gains.yaml')


def _entry(data, model, where):
    models = data.get('models', {})
    if model not in models:
        raise ValueError(f"model '{model}' not in {where}; available: {', '.join(models)}")
    return models[model]


@dataclass(frozen=True)
class HeadingLoopDesign:
    """The heading loop an autopilot runs: its gains (an autopilot_gains.yaml entry, or
    {k1, k2}), the design (zeta, omega_n in rad/s) they place on the model's Nomoto model
    (None if they place no oscillatory one), and where they came from ('k1, k2',
    'omega_n, zeta' or 'gain table')."""
    gains: dict
    zeta: float
    omega_n: float
    source: str


#: autopilot_node's fuzzy scaling parameters -> FuzzyPIDGains fields (0: the gain table's)
FUZZY_SCALING_PARAMETERS = {'fuzzy_ge': 'GE', 'fuzzy_gr': 'GR', 'fuzzy_ga': 'GA', 'fuzzy_gu': 'GU',
                            'fuzzy_l': 'L'}


def heading_loop_design(model, controller='pd', k1=0.0, k2=0.0, omega_n=0.0, zeta=ZETA,
                        fuzzy_ge=0.0, fuzzy_gr=0.0, fuzzy_ga=0.0, fuzzy_gu=0.0, fuzzy_l=0.0):
    """The heading loop autopilot_node builds for ``model`` from its parameters, as a
    HeadingLoopDesign; the node and the launcher's platoon check both call this.

    Fuzzy PID with its scaling given (fuzzy_ge, fuzzy_gr, fuzzy_ga, fuzzy_gu all > 0; fuzzy_l
    0 = 1, e.g. Lee 2004's own values) -> those gains, integration band the error universe
    L / GE (ship_autopilot.fuzzy_pid), design None (no Nomoto design behind them).

    PD with k1, k2 (both > 0) -> those gains and the design they place (Angelopoulos 2011
    eq. 20 inverted, ship_guidance.heading_loop.pd_design); PD with omega_n > 0 -> gains
    redesigned on the identified Nomoto a, b for (zeta, omega_n); otherwise (the gain table, or
    the fuzzy PID whose linearisation is that PD) the table's entry and design. ValueError
    (or KeyError, OSError from the tables) if the model or the parameters do not fit."""
    table = autopilot_gains(model)
    scaling = {'GE': fuzzy_ge, 'GR': fuzzy_gr, 'GA': fuzzy_ga, 'GU': fuzzy_gu}
    if controller == 'fuzzy_pid' and any(scaling.values()):
        if not all(scaling.values()):
            raise ValueError('fuzzy_ge, fuzzy_gr, fuzzy_ga and fuzzy_gu all > 0 (or all 0)')
        g = FuzzyPIDGains(**scaling, L=fuzzy_l or 1.0)
        return HeadingLoopDesign({'GE': g.GE, 'GR': g.GR, 'GA': g.GA, 'GU': g.GU, 'L': g.L},
                                 None, None, 'GE, GR, GA, GU')
    if controller == 'pd' and (k1 or k2):
        if not (k1 and k2):
            raise ValueError('k1 and k2 both > 0 (or both 0)')
        nm = nomoto_gains(model)
        try:
            z, w = pd_design(nm['a'], nm['b'], k1=k1, k2=k2)
        except ValueError:
            z = w = None
        return HeadingLoopDesign({'k1': k1, 'k2': k2}, z, w, 'k1, k2')
    if controller == 'pd' and omega_n:
        nm = nomoto_gains(model)
        g1, g2 = pd_gains(nm['a'], nm['b'], omega_n=omega_n, zeta=zeta)
        return HeadingLoopDesign({'k1': g1, 'k2': g2}, float(zeta), float(omega_n),
                                 'omega_n, zeta')
    return HeadingLoopDesign(table, float(table['zeta']), float(table['omega_n']), 'gain table')


def build_autopilot(kind, gains, max_angle, max_rate=None, shape='hard', anti_windup=True):
    """Controller ``kind`` ('pd' or 'fuzzy_pid') from a gains entry (autopilot_gains.yaml).

    ``gains``: for 'pd' a dict with k1, k2; for 'fuzzy_pid' one with GE, GR, GA, GU (and
    optionally L, integration_band_deg).
    The entry of a model (``autopilot_gains(model)``) may be passed whole. Rudder limits in
    rad, rad/s; ``shape`` 'hard' or 'tanh'.
    """
    limiter = RudderLimiter(max_angle, max_rate, shape)
    if kind == 'pd':
        g = gains.get('pd', gains)
        return PDAutopilot(g['k1'], g['k2'], limiter)
    if kind == 'fuzzy_pid':
        g = gains.get('fuzzy_pid', gains)
        band = g.get('integration_band_deg')
        return FuzzyPIDAutopilot(FuzzyPIDGains(g['GE'], g['GR'], g['GA'], g['GU'],
                                               g.get('L', 1.0)), limiter, anti_windup,
                                 None if band is None else np.deg2rad(band))
    raise ValueError(f"controller = {kind!r} is not allowed; allowed: {', '.join(CONTROLLERS)}")
