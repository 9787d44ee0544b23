"""The three wind-and-wave conditions of the controller study (issue 14, item 4), defined once.

The flagship and the platoon (node graph: ``scenario_blocks`` -> a scenario's `wind:` and
`waves:` blocks) and Table I (in process: ``wind_field`` and ``sea_state`` -> the plant's wind
loads and the wave-frequency motion superposed on what the controllers measure) use these
definitions, so every table of the study means the same sea.

- ``calm``: no wind, no waves (every run equals the undisturbed one bit for bit).
- ``wind10``: 10 m/s wind and its fully developed sea: Hs = vw2hs(10) = 0.21 V^2 / g = 2.14 m
  (MSS vw2hs / hs2vw, Pierson-Moskowitz), peak period of the Pierson-Moskowitz spectrum of that
  Hs (7.30 s), spectrum 'Modified PM' (ITTC two-parameter form: the Pierson-Moskowitz sea with
  that Hs and Tp, the textbook model of a fully developed sea; Fossen 2021, Sec. 10.2).
- ``wind20``: 20 m/s wind and a Torsethaugen sea of Hs 6 m, Tp 10 s: a gale that has not yet
  raised its fully developed sea (vw2hs(20) = 8.6 m at Tp 14.6 s) over a swell. The
  Torsethaugen spectrum is double-peaked only for w0 > 0.6 rad/s (MSS warns otherwise), which
  Tp 10 s (0.63 rad/s) keeps; Tp < 6.6 Hs^(1/3) = 12 s makes it the wind-sea-dominated form.

Directions are relative to the route's overall course ``course`` (rad, clockwise from north;
``route_course``: from the route's start to its end): the wind blows FROM 45 deg on the port
bow (course - 45 deg), the waves travel downwind (towards course + 135 deg, i.e. they meet a
ship on the course from 45 deg on the port bow), cos^2 spreading over 8 directions, 100
frequencies up to 3 rad/s. Gusts: Gauss-Markov speed, sd 10 % of the mean, time constant 60 s.
Blendermann 1994 coefficients. Seeds: the waves and gusts of vessel or episode i use seed
``SEED + i`` (the same for every controller: paired comparisons).
"""
import math
from dataclasses import dataclass

from ship_sim.environment.sea_state import SeaState, pm_peak_frequency
from ship_sim.environment.sea_state_relations import vw2hs
from ship_sim.environment.wind import WindField

WIND_FROM_RELATIVE = math.radians(-45.0)   # wind from 45 deg on the port bow of the course
GUST_FRACTION = 0.1
GUST_TIME_CONSTANT = 60.0
COEFFICIENTS = 'blendermann94'
N_FREQUENCIES = 100
N_DIRECTIONS = 8
SEED = 1


@dataclass(frozen=True)
class Condition:
    """Wind speed (m/s) and sea (spectrum name of ship_sim.environment, Hs m, Tp s; Tp 0 = the
    Pierson-Moskowitz peak of that Hs). Directions relative to the route's course (module
    docstring) unless ``wind_from_deg`` (deg, clockwise from north, where the wind comes from)
    or ``waves_towards_deg`` (where the waves travel) fix them (``custom``: sweeps)."""
    name: str
    wind_speed: float
    spectrum: str
    hs: float
    tp: float
    wind_from_deg: float | None = None
    waves_towards_deg: float | None = None

    @classmethod
    def custom(cls, wind_speed=0.0, wind_from_deg=0.0, hs=0.0, tp=0.0, waves_towards_deg=0.0,
               spectrum='Modified PM'):
        """A condition of given wind and sea, fixed directions; gusts, spreading and
        components as the named conditions'. ValueError (one line) for values out of range."""
        cond = cls('custom', float(wind_speed), spectrum, float(hs), float(tp),
                   float(wind_from_deg), float(waves_towards_deg))
        wind_field(cond, 0.0)          # the same checks as the runs make
        sea_state(cond, 0.0)
        return cond

    @property
    def calm(self):
        return self.wind_speed == 0.0 and self.hs == 0.0

    def describe(self):
        if self.calm:
            return 'calm (no wind, no waves)'
        if self.wind_from_deg is not None:
            return (f'{self.wind_speed:g} m/s wind from {self.wind_from_deg:g} deg, '
                    f'{self.spectrum} sea Hs {self.hs:.2f} m, Tp {self.tp:.2f} s, towards '
                    f'{self.waves_towards_deg:g} deg')
        return (f'{self.wind_speed:g} m/s wind from 45 deg on the port bow, {self.spectrum} sea '
                f'Hs {self.hs:.2f} m, Tp {self.tp:.2f} s, travelling downwind')


def _fully_developed(wind_speed):
    hs = float(vw2hs(wind_speed))
    return hs, 2.0 * math.pi / pm_peak_frequency(hs)


CONDITIONS = {
    'calm': Condition('calm', 0.0, 'Modified PM', 0.0, 0.0),
    'wind10': Condition('wind10', 10.0, 'Modified PM', *_fully_developed(10.0)),
    'wind20': Condition('wind20', 20.0, 'Torsethaugen', 6.0, 10.0),
}


def condition(name):
    """The Condition of a name; ValueError naming the allowed ones."""
    try:
        return CONDITIONS[name]
    except KeyError:
        raise ValueError(f'condition {name!r}: allowed {", ".join(CONDITIONS)}') from None


def route_course(route):
    """Overall course (rad, clockwise from north) of a ship_guidance Route: start to end."""
    (n0, e0), (n1, e1) = route.start, route.end
    return math.atan2(float(e1) - float(e0), float(n1) - float(n0))


def wind_from(course):
    """Direction the wind blows FROM (rad) for a route of this course."""
    return course + WIND_FROM_RELATIVE


def wave_direction(course):
    """Main direction the waves travel TOWARDS (rad): downwind."""
    return wind_from(course) + math.pi


def wind_field(cond, course, seed=SEED, shape=()):
    """The WindField of a condition (None when there is no wind); ``seed`` one int, or one per
    element of ``shape`` (a stream per vessel: ship_sim.current.ElementStreams)."""
    if cond.wind_speed == 0.0:
        return None
    direction = (wind_from(course) if cond.wind_from_deg is None
                 else math.radians(cond.wind_from_deg))
    return WindField(cond.wind_speed, direction, gust_sd=GUST_FRACTION * cond.wind_speed,
                     time_constant=GUST_TIME_CONSTANT, seed=seed, shape=shape)


def sea_state(cond, course, seed=SEED):
    """The SeaState of a condition (None for a calm sea)."""
    if cond.hs == 0.0:
        return None
    direction = (wave_direction(course) if cond.waves_towards_deg is None
                 else math.radians(cond.waves_towards_deg))
    return SeaState(hs=cond.hs, tp=cond.tp, spectrum=cond.spectrum, direction=direction,
                    spreading=True, n_frequencies=N_FREQUENCIES, n_directions=N_DIRECTIONS,
                    seed=seed)


#: ship_sim spectrum name -> the scenario's `waves: spectrum` key (ship_mission.waves)
SCENARIO_SPECTRUM = {'Modified PM': 'modified_pm', 'Torsethaugen': 'torsethaugen',
                     'JONSWAP': 'jonswap'}


def scenario_blocks(cond, course, seed=SEED):
    """(wind block, waves block) of a scenario vessel (ship_mission.wind_block, ship_mission.waves), each
    None when absent: the same wind and sea as ``wind_field`` / ``sea_state``."""
    wind = sea = None
    if cond.wind_speed > 0.0:
        wind = {'speed_mps': cond.wind_speed, 'direction_deg': math.degrees(wind_from(course)),
                'gust_sd_mps': GUST_FRACTION * cond.wind_speed,
                'time_constant_s': GUST_TIME_CONSTANT, 'seed': seed,
                'coefficients': COEFFICIENTS}
    if cond.hs > 0.0:
        sea = {'hs_m': cond.hs, 'tp_s': cond.tp, 'spectrum': SCENARIO_SPECTRUM[cond.spectrum],
               'direction_deg': math.degrees(wave_direction(course)), 'spreading': True,
               'n_frequencies': N_FREQUENCIES, 'n_directions': N_DIRECTIONS, 'seed': seed}
    return wind, sea
