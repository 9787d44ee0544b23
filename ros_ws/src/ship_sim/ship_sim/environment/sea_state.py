"""A sea state and the wave-frequency motion it gives a ship (Fossen 2021, Ch. 10).

``SeaState`` (Hs, peak period, spectrum, main direction, spreading, seed) -> wave components
(``wave_directional_spectrum``: frequencies, directions, amplitudes; random phases) ->
``ShipWaves``: the first-order motion (and loads) of one ship from its RAO table at the
encounter frequency for its heading and speed (``WaveResponse``). The output-superposition
principle (Fossen 2021, Sec. 10.4): the manoeuvring model runs in calm water and the
wave-frequency motion is added to its output, so the manoeuvring state is untouched.

Conventions: ``direction`` (rad) is where the waves travel TOWARDS, clockwise from north, as
the current's (ship_sim.current); the relative direction beta = direction - psi is then 0 for
a following sea and pi for a head sea, MSS's beta_wave. A peak period of 0 takes the peak of
the Pierson-Moskowitz spectrum (MSS waveSpectrum type 2) of the fully developed sea of that
Hs: wind speed V = hs2vw(Hs), w0 = (4 B / 5)^(1/4) with B = 0.74 (g / V)^4.
All random numbers come from numpy.random.default_rng(seed) in a fixed order (direction
draws, frequency draws, phases): the same sea state gives the same waves, bit for bit.

RAOs per model: the S-175 tables for the container ship (MSS container.m is the S-175);
for the Mariner, the tanker and the Nomoto models, the S-175 tables Froude-scaled to the
model's Lpp (``RaoTable.froude_scaled``). That assumes geometric similarity, which these hulls
do not have (block coefficients, L/B and draughts differ): an order-of-magnitude model of
their wave response, not their RAOs. Mean wave drift is not added to any plant
(``mean_drift_upper_bound`` is the documented approximation available).
"""
import math
from dataclasses import dataclass

import numpy as np

from ship_sim.environment.sea_state_relations import G, hs2vw, vw2hs
from ship_sim.environment.wave_directional import SPECTRA, wave_directional_spectrum
from ship_sim.environment.wave_rao import WaveResponse, load_rao_table

RHO = 1025.0
#: spectrum parameter value (vessel_node's waves_spectrum) -> SeaState.spectrum
SPECTRUM_NAMES = {'jonswap': 'JONSWAP', 'modified_pm': 'Modified PM', 'torsethaugen': 'Torsethaugen'}


def __getattr__(name):
    # MODEL_RAO: model name -> (RAO vessel, scale to the model's length?) of the registered
    # cards (read at each access, so a card registered later is included).
    if name == 'MODEL_RAO':
        return _model_rao()
    raise AttributeError(f'module {__name__!r} has no attribute {name!r}')


def _model_rao():
    from ship_sim.models import cards
    return {c.name: c.rao for c in cards() if c.has_waves}


def pm_peak_frequency(hs):
    """Peak frequency (rad/s) of the Pierson-Moskowitz sea of significant wave height hs (m)."""
    v = float(hs2vw(hs))
    return (4.0 * 0.74 * (G / v) ** 4 / 5.0) ** 0.25


@dataclass(frozen=True)
class SeaState:
    """Hs (m; 0 = calm); ``tp`` peak period (s; 0 = Pierson-Moskowitz peak of that Hs);
    ``spectrum`` 'JONSWAP' (with ``gamma``), 'Modified PM' or 'Torsethaugen'; ``direction``
    (rad, towards, clockwise from north); ``spreading`` (cos^2, ``n_directions``);
    ``n_frequencies`` components up to ``omega_max`` (rad/s); ``seed``."""
    hs: float = 0.0
    tp: float = 0.0
    spectrum: str = 'JONSWAP'
    gamma: float = 3.3
    direction: float = 0.0
    spreading: bool = False
    n_frequencies: int = 100
    n_directions: int = 16
    omega_max: float = 3.0
    seed: int = 0

    @classmethod
    def from_wind(cls, wind_speed, **kwargs):
        """The fully developed sea of a wind speed (m/s): Hs = vw2hs(V), PM peak period."""
        return cls(hs=float(vw2hs(wind_speed)), tp=0.0, **kwargs)

    def __post_init__(self):
        checks = (('hs', self.hs, 0.0, 30.0), ('tp', self.tp, 0.0, 40.0),
                  ('gamma', self.gamma, 0.0, 10.0), ('omega_max', self.omega_max, 0.1, 10.0),
                  ('n_frequencies', self.n_frequencies, 1, 10000),
                  ('n_directions', self.n_directions, 2, 1000))
        for name, v, lo, hi in checks:
            if not (math.isfinite(v) and lo <= v <= hi):
                raise ValueError(f'{name} = {v!r} is outside the allowed range [{lo}, {hi}]')
        if self.spectrum not in SPECTRA:
            raise ValueError(f'spectrum = {self.spectrum!r}: allowed {", ".join(SPECTRA)}')

    @property
    def calm(self):
        return self.hs == 0.0

    @property
    def peak_frequency(self):
        """w0 (rad/s)."""
        return 2.0 * math.pi / self.tp if self.tp > 0.0 else pm_peak_frequency(self.hs)

    def components(self):
        """(DirectionalSpectrum, phases N x D) drawn from the seed."""
        rng = np.random.default_rng(self.seed)
        params = [self.hs, self.peak_frequency] + ([self.gamma] if self.spectrum == 'JONSWAP'
                                                   else [])
        spec = wave_directional_spectrum(self.spectrum, params, self.n_frequencies,
                                         self.omega_max, self.spreading, self.n_directions,
                                         rng=rng)
        return spec, 2.0 * np.pi * rng.random(spec.Amp.shape)

    def describe(self):
        text = (f'Hs {self.hs:g} m, Tp {2 * math.pi / self.peak_frequency:.2f} s, '
                f'{self.spectrum}' + (f' (gamma {self.gamma:g})' if self.spectrum == 'JONSWAP'
                                      else '')
                + f', towards {math.degrees(self.direction):g} deg')
        return text + (f', cos^2 spreading over {self.n_directions} directions'
                       if self.spreading else '') + f', {self.n_frequencies} components, ' \
            f'seed {self.seed}'


def rao_table_for(model_name, length, kind='motion'):
    """The RAO table of a plant model (its card's ``rao``), scaled to ``length`` (m) if needed."""
    rao = _model_rao()
    if model_name not in rao:
        raise ValueError(f'no wave RAOs for model {model_name!r} (models with waves: '
                         f'{", ".join(rao)})')
    vessel, scaled = rao[model_name]
    table = load_rao_table(vessel, kind)
    return table.froude_scaled(length) if scaled and length != table.length else table


class ShipWaves:
    """Wave-frequency motion of one ship in one sea state (output superposition); or of a
    batch of ships, ``sea`` a sequence of SeaStates (one per ship, equal n_frequencies,
    n_directions and spreading; their own seeds, heights, periods and directions): ``motion``
    then takes and returns arrays, each ship's numbers those of its own ShipWaves to rounding
    (the same arithmetic, WaveResponse on a batch, in blocks of ships whose cost per ship does
    not grow with the batch)."""

    def __init__(self, sea, table):
        if isinstance(sea, SeaState):
            self.sea = sea
            spec, phases = sea.components()
            self.spectrum = spec
            self.direction = sea.direction
            self.response = WaveResponse(table, spec.Omega, spec.mu, spec.Amp, phases,
                                         wrap_headings=True)
            return
        self.seas = list(sea)
        if not self.seas:
            raise ValueError('a batch of ShipWaves needs at least one sea state')
        layout = {(s.n_frequencies, s.n_directions if s.spreading else 1) for s in self.seas}
        if len(layout) > 1:
            raise ValueError(f'a batch of sea states needs one component layout '
                             f'(frequencies, directions); got {sorted(layout)}')
        # Episodes of one sea state (equal SeaStates: one seed) draw its components once; their
        # RAOs are then stored once too (WaveResponse shares them between equal frequencies).
        drawn = {s: s.components() for s in dict.fromkeys(self.seas)}
        comps = [drawn[s] for s in self.seas]
        self.direction = np.array([s.direction for s in self.seas])
        self.response = WaveResponse(table, np.stack([c.Omega for c, _ in comps]),
                                     np.stack([np.atleast_1d(c.mu) for c, _ in comps]),
                                     np.stack([c.Amp for c, _ in comps]),
                                     np.stack([p for _, p in comps]), wrap_headings=True)

    def motion(self, t, U, psi, dofs=None):
        """(eta_WF, nu_WF), 6 each: [surge, sway, heave (m, down), roll, pitch, yaw (rad)] and
        their rates (FRD body axes) at time t (s), speed U (m/s), heading psi (rad); a batch:
        U and psi arrays (B), eta_WF and nu_WF 6 x B. ``dofs``: compute only those DOF
        (wave_rao.SURGE_SWAY_YAW: what ``superpose`` reads), the others NaN; the computed
        ones bit for bit those of the full computation."""
        eta, nu, _ = self.response.motion(t, U, psi, self.direction, accelerations=False,
                                          dofs=dofs)
        return eta, nu

    def peak_encounter_frequency(self, U, psi):
        """Encounter frequency (rad/s) of the spectral peak for the main direction."""
        return peak_encounter_frequency(self.sea.peak_frequency, U, self.sea.direction - psi)


def superpose(eta, nu, north, east, psi, u, v, r):
    """What a sensor sees (output superposition, Fossen 2021, Sec. 10.4): the manoeuvring
    (north, east, psi, u, v, r) (NED m, rad; body FRD m/s, rad/s) plus the wave-frequency motion
    (eta_WF, nu_WF of ``ShipWaves.motion``): position + the surge/sway displacement rotated by
    the heading, heading + yaw, body velocities + the wave-frequency rates. Floats, or arrays
    of a batch (eta_WF, nu_WF 6 x B). Reads surge, sway and yaw only (SURGE_SWAY_YAW: the
    ``dofs`` that ``ShipWaves.motion`` needs to compute for it)."""
    trig = (math.cos, math.sin) if isinstance(psi, float) else (np.cos, np.sin)
    c, s = trig[0](psi), trig[1](psi)
    return (north + c * eta[0] - s * eta[1], east + s * eta[0] + c * eta[1], psi + eta[5],
            u + nu[0], v + nu[1], r + nu[5])


def peak_encounter_frequency(w0, U, beta):
    """|w0 - w0^2 U cos(beta) / g| (rad/s): beta = wave direction - heading (0 following).
    Floats, or arrays of a batch."""
    cos = math.cos if isinstance(beta, float) else np.cos
    return abs(w0 - w0 ** 2 * U * cos(beta) / G)


def mean_drift_upper_bound(hs, length, beam, beta, rho=RHO):
    """Mean wave drift force (X, Y) (N, body axes) as an UPPER BOUND: the short-wave limit of a
    wall-sided box L x B that reflects every wave (Faltinsen 1990, Sec. 5.1: 1/2 rho g a^2
    sin^2 per unit length of wall), summed over a spectrum of m0 = Hs^2 / 16:
    X = rho g m0 B cos(beta) |cos(beta)|, Y = rho g m0 L sin(beta) |sin(beta)|, pushing the
    ship the way the waves travel (beta = wave direction - heading). Long waves pass a ship
    with little reflection, so the real drift is smaller. No plant applies it."""
    m0 = hs ** 2 / 16.0
    c, s = math.cos(beta), math.sin(beta)
    return rho * G * m0 * beam * c * abs(c), rho * G * m0 * length * s * abs(s)
