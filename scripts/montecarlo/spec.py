"""Sweep files: a base environment, the parameters to vary, and the episodes they expand to.

A sweep file (YAML; examples in scenarios/sweeps/)::

    name: current_starts_mariner   # output folder name (default: the file's stem): a plain
                                   # file name (name_problem)
    seed: 1                        # the whole table follows from it
    episodes: 50                   # random draws per grid cell (at most MAX_EPISODES in all)
    paired: true                   # every grid cell sees the same draws (default true)
    base:                          # the environment; any PARAMETERS entry
      model: mariner
      controller: los
      route: scenarios/routes/curved_path_{model}_000.yaml
      duration_s: 1000
    vary:                          # a list = a grid axis; a mapping = a random draw
      controller: [los, ilos_lead, policy]
      current_speed_mps: [0.0, 0.9]
      current_direction_deg: {uniform: [-180, 180]}
      start_cross_m: {normal: [0, 30]}
      model: {choice: [mariner, container]}

Grid cells are the cartesian product of the list axes, in the order written; each cell gets
``episodes`` samples; episode index = cell * episodes + sample. Random parameters are drawn per
sample from ``numpy.random.SeedSequence(seed, spawn_key=(sample,))`` (the sample-th child of
``SeedSequence(seed).spawn``), in sorted parameter order, so with ``paired: true`` (common random
numbers) every controller, current, ... meets the same starts and current directions, and the
differences between cells are paired; ``paired: false`` keys the draws by episode index
instead. The same child also gives the episode's own ``seed`` (a varying current's noise).
Drawing never depends on which process runs the episode, so the table does not either.

Wind and waves: either ``condition`` (a ship_mission.conditions name: calm, wind10, wind20, the
three conditions of Table I, directions relative to the route's overall course) or the
explicit keys (WEATHER: wind speed and the direction it blows from, significant wave height,
peak period and the direction the waves travel, absolute; gusts, spectrum (Modified PM),
spreading and components as the named conditions'), not both. Each episode's gusts and waves
come from its own ``seed``, so a row does not depend on the chunking either.

Encounter sweeps: a file that names ``encounter`` (in base or vary) runs Imazu encounters with
collision avoidance instead of route following (montecarlo.encounters)::

    base: {model: mariner, encounter: 1, colav_method: sbmpc, duration_s: 2000}
    vary:
      encounter: [1, 2, 3, 4]                          # Imazu case numbers
      colav_method: [sbmpc, vo]
      encounter_speed_factor: {uniform: [0.7, 1.3]}    # targets' speeds x; same meeting point, time
      encounter_miss_m: {normal: [0, 300]}             # unmanoeuvred closest approach, m

It takes only ENCOUNTER_KEYS (its own ship is one of imazu.runner.SHIPS; duration_s defaults to
the benchmark's limit, 4000 s, runs ending once all targets have passed and the ship is back on
its route); a route-following key there, or an encounter key in a route-following
file, is refused with one line. One kind of sweep per file.
"""
import itertools
import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ship_sim.safe_load import InputError, load_yaml_file

REPO = Path(__file__).resolve().parents[2]

#: name -> (default, kind, (low, high) for numbers or None, unit/meaning).
PARAMETERS = {
    'model': ('mariner', 'model', None, 'plant model (ship_sim.models.MODEL_NAMES)'),
    'controller': ('los', 'controller', None, 'evaluate_controllers.CONTROLLERS'),
    'route': ('scenarios/routes/curved_path_{model}_000.yaml', 'path', None,
              'route file; {model} is replaced by the model name'),
    'duration_s': (1000.0, 'number', (1.0, 1e6), 'episode length, s'),
    'current_speed_mps': (0.0, 'number', (0.0, 10.0), 'current speed, m/s'),
    'current_direction_deg': (0.0, 'number', (-1e4, 1e4), 'current flowing towards, deg'),
    'current_speed_std_mps': (0.0, 'number', (0.0, 5.0),
                              'stationary std of a Gauss-Markov current speed, m/s'),
    'current_direction_std_deg': (0.0, 'number', (0.0, 180.0),
                                  'stationary std of a Gauss-Markov current direction, deg'),
    'current_time_constant_s': (600.0, 'number', (1.0, 1e7), 'Gauss-Markov time constant, s'),
    'start_along_m': (0.0, 'number', (0.0, 1e6), 'start point along the route, m'),
    'start_cross_m': (0.0, 'number', (-1e4, 1e4), 'start offset, m (+ starboard)'),
    'start_heading_deg': (0.0, 'number', (-180.0, 180.0), 'start heading - path angle, deg'),
    'condition': ('calm', 'condition', None,
                  'wind and waves of ship_mission.conditions (calm, wind10, wind20)'),
    'wind_speed_mps': (0.0, 'number', (0.0, 60.0), 'mean wind speed, m/s (gusts sd 10 %)'),
    'wind_direction_deg': (0.0, 'number', (-1e4, 1e4),
                           'wind blows from, deg clockwise from north'),
    'wave_height_m': (0.0, 'number', (0.0, 30.0), 'significant wave height, m'),
    'wave_period_s': (0.0, 'number', (0.0, 40.0),
                      'peak period, s (0: the Pierson-Moskowitz peak of that height)'),
    'wave_direction_deg': (0.0, 'number', (-1e4, 1e4),
                           'waves travel towards, deg clockwise from north'),
    # Encounter sweeps only (ENCOUNTER_KEYS; montecarlo.encounters.perturbed_case).
    'encounter': (1, 'case', None, 'Imazu case number, 1-22 (scripts/imazu/cases.py)'),
    'colav_method': ('sbmpc', 'colav', None, 'collision avoidance (imazu.runner.METHODS)'),
    'encounter_speed_factor': (1.0, 'number', (0.1, 3.0),
                               "targets' speeds x this, same meeting point and time"),
    'encounter_miss_m': (0.0, 'number', (-1e4, 1e4),
                         "targets' tracks shifted sideways: unmanoeuvred CPA, m"),
}
#: The parameters of an encounter sweep (a file naming ``encounter``); every other one is
#: route following's, and the last four belong to encounter sweeps only.
ENCOUNTER_KEYS = ('model', 'duration_s', 'encounter', 'colav_method', 'encounter_speed_factor',
                  'encounter_miss_m')
#: The explicit wind and sea keys (a sweep gives these or ``condition``, not both).
WEATHER = ('wind_speed_mps', 'wind_direction_deg', 'wave_height_m', 'wave_period_s',
           'wave_direction_deg')
DISTRIBUTIONS = {'uniform': 2, 'normal': 2, 'choice': None}
TOP_KEYS = ('name', 'seed', 'episodes', 'paired', 'base', 'vary')
#: Most episodes of one sweep (grid cells x episodes per cell, ``--episodes`` included): the
#: episodes are expanded up front, about 1 kB each, so the bound keeps that list (and the
#: rows) within a few hundred MB; the largest shipped sweep (table1.yaml) has 36,000. A larger
#: study is several sweeps (``--where`` runs a part of the grid).
MAX_EPISODES = 200_000
#: Largest seed: numpy's SeedSequence takes any integer, but the seed is also written to the
#: tables as a 64-bit integer.
MAX_SEED = 2**63 - 1


class SweepError(ValueError):
    """A bad sweep file: one line naming the file, the key and what is allowed."""


@dataclass(frozen=True)
class Sweep:
    """A parsed sweep file (see the module docstring)."""
    name: str
    seed: int
    episodes: int
    paired: bool
    base: dict
    grid: dict          # name -> list of values (order of the file)
    random: dict        # name -> (distribution, args)
    source: str = ''

    @property
    def n_cells(self):
        return math.prod(len(v) for v in self.grid.values())

    @property
    def n_episodes(self):
        return self.n_cells * self.episodes

    @property
    def kind(self):
        """'encounter' (a file naming ``encounter``) or 'route' (route following)."""
        return 'encounter' if 'encounter' in self.base else 'route'

    def columns(self):
        """Parameter columns of the table: the varied ones first, then the base ones."""
        varied = list(self.grid) + sorted(self.random)
        return varied + [k for k in self.base if k not in varied]


def _models():
    from ship_sim.models import MODEL_NAMES
    return MODEL_NAMES


def _controllers():
    import evaluate_controllers
    return evaluate_controllers.CONTROLLERS


def _check_value(where, name, value):
    default, kind, bounds, _ = PARAMETERS[name]
    if kind == 'model':
        if value not in _models():
            raise SweepError(f'{where}: model {value!r} unknown; allowed: '
                             f'{", ".join(_models())}')
        return value
    if kind == 'controller':
        if value not in _controllers():
            raise SweepError(f'{where}: controller {value!r} unknown; allowed: '
                             f'{", ".join(_controllers())}')
        return value
    if kind == 'case':
        from imazu.cases import load_cases
        if isinstance(value, bool) or value not in load_cases():
            raise SweepError(f'{where}: encounter {value!r} unknown; allowed: Imazu cases '
                             f'1-{len(load_cases())}')
        return int(value)
    if kind == 'colav':
        from imazu.runner import METHODS
        if value not in METHODS:
            raise SweepError(f'{where}: colav_method {value!r} unknown; allowed: '
                             f'{", ".join(METHODS)}')
        return value
    if kind == 'condition':
        from ship_mission.conditions import CONDITIONS
        if value not in CONDITIONS:
            raise SweepError(f'{where}: condition {value!r} unknown; allowed: '
                             f'{", ".join(CONDITIONS)}')
        return value
    if kind == 'path':
        if not isinstance(value, str) or not value:
            raise SweepError(f'{where}: {name} must be a file path, got {value!r}')
        return value
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
        raise SweepError(f'{where}: {name} must be a number, got {value!r}')
    lo, hi = bounds
    if not lo <= value <= hi:
        raise SweepError(f'{where}: {name} = {value!r} is outside [{lo:g}, {hi:g}]')
    return float(value)


def _check_name(where, name):
    if name not in PARAMETERS:
        raise SweepError(f'{where}: unknown parameter {name!r}; allowed: '
                         f'{", ".join(PARAMETERS)}')


def _sweep_kind(source, names):
    """'encounter' or 'route' for a file naming ``names`` (base and vary); SweepError for a
    parameter of the other kind."""
    if 'encounter' in names:
        wrong = [n for n in names if n not in ENCOUNTER_KEYS]
        if wrong:
            raise SweepError(f'{source}: {wrong[0]!r} is not a parameter of an encounter sweep '
                             f"(a file naming 'encounter'); allowed: {', '.join(ENCOUNTER_KEYS)}")
        return 'encounter'
    wrong = [n for n in names if n in ENCOUNTER_KEYS[3:]]
    if wrong:
        raise SweepError(f"{source}: {wrong[0]!r} belongs to an encounter sweep; name "
                         "'encounter' (an Imazu case) in base or vary to make one")
    return 'route'


def _check_own_ships(source, base, grid, rand):
    """An encounter sweep's own ships are those the Imazu runner knows."""
    from imazu.runner import SHIPS
    models = [base['model'], *grid.get('model', []), *rand.get('model', (None, []))[1]]
    bad = [m for m in models if m not in SHIPS]
    if bad:
        raise SweepError(f'{source}: model {bad[0]!r} cannot be an encounter\'s own ship; '
                         f'allowed: {", ".join(SHIPS)}')


def _random_spec(where, name, spec):
    if len(spec) != 1 or next(iter(spec)) not in DISTRIBUTIONS:
        raise SweepError(f'{where}: a random parameter is one of {{uniform: [low, high]}}, '
                         f'{{normal: [mean, std]}}, {{choice: [a, b, ...]}}; got {spec!r}')
    dist, args = next(iter(spec.items()))
    if not isinstance(args, list) or not args:
        raise SweepError(f'{where}: {dist} needs a list, got {args!r}')
    if dist == 'choice':
        return dist, [_check_value(where, name, a) for a in args]
    if len(args) != 2 or PARAMETERS[name][1] != 'number':
        raise SweepError(f'{where}: {dist} needs two numbers and a numeric parameter, got '
                         f'{name}: {spec!r}')
    a, b = (_check_value(f'{where} ({dist} argument)', name, v) if dist == 'uniform' else v
            for v in args)
    if dist == 'uniform' and not a <= b:
        raise SweepError(f'{where}: uniform needs low <= high, got {args!r}')
    if dist == 'normal' and not (isinstance(b, (int, float)) and b >= 0):
        raise SweepError(f'{where}: normal needs a standard deviation >= 0, got {args!r}')
    return dist, [float(a), float(b)]


def parse(doc, source='<sweep>'):
    """A Sweep from a loaded YAML mapping; SweepError (one line) for anything wrong."""
    if not isinstance(doc, dict):
        raise SweepError(f'{source}: a sweep file is a mapping with keys {", ".join(TOP_KEYS)}')
    extra = sorted(set(doc) - set(TOP_KEYS))
    if extra:
        raise SweepError(f'{source}: unknown key(s) {", ".join(extra)}; allowed: '
                         f'{", ".join(TOP_KEYS)}')
    seed, episodes = doc.get('seed', 0), doc.get('episodes', 1)
    for key, v, hi in (('seed', seed, MAX_SEED), ('episodes', episodes, MAX_EPISODES)):
        lo = 0 if key == 'seed' else 1
        if isinstance(v, bool) or not isinstance(v, int) or not lo <= v <= hi:
            raise SweepError(f'{source}: {key} must be an integer in [{lo}, {hi}], got {v!r}')
    paired = doc.get('paired', True)
    if not isinstance(paired, bool):
        raise SweepError(f'{source}: paired must be true or false, got {paired!r}')
    for key in ('base', 'vary'):
        if not isinstance(doc.get(key) or {}, dict):
            raise SweepError(f'{source}: {key} must be a mapping of parameter: value, got '
                             f'{doc[key]!r}')
    base = dict(doc.get('base') or {})
    vary = dict(doc.get('vary') or {})
    kind = _sweep_kind(source, [*base, *vary])
    for name, value in base.items():
        _check_name(f'{source}: base', name)
        base[name] = _check_value(f'{source}: base', name, value)
    grid, rand = {}, {}
    for name, spec in vary.items():
        where = f'{source}: vary.{name}'
        _check_name(f'{source}: vary', name)
        if isinstance(spec, list):
            if not spec:
                raise SweepError(f'{where}: a grid axis needs at least one value')
            grid[name] = [_check_value(where, name, v) for v in spec]
        elif isinstance(spec, dict):
            rand[name] = _random_spec(where, name, spec)
        else:
            raise SweepError(f'{where}: give a list (grid) or a distribution mapping '
                             f'(random), got {spec!r}')
    weather = [k for k in WEATHER if k in base or k in vary]
    if weather and ('condition' in base or 'condition' in vary):
        raise SweepError(f'{source}: give condition or the wind and wave keys '
                         f'({", ".join(weather)}), not both')
    if kind == 'encounter':
        from imazu.runner import LIMIT_S
        full_base = {k: PARAMETERS[k][0] for k in ENCOUNTER_KEYS}
        full_base['duration_s'] = LIMIT_S
    else:
        full_base = {k: v[0] for k, v in PARAMETERS.items() if k not in ENCOUNTER_KEYS[2:]}
    full_base.update(base)
    if kind == 'encounter':
        _check_own_ships(source, full_base, grid, rand)
    name = doc.get('name') or Path(source).stem
    bad = name_problem(name)
    if bad:
        raise SweepError(f'{source}: name {bad} (it names the output folder), got {name!r}')
    sweep = Sweep(name, seed, episodes, paired, full_base, grid, rand, source)
    check_size(sweep, episodes, source)
    return sweep


def name_problem(name):
    """None if ``name`` is a plain, safe file name (it names a folder under runs/sweeps), else
    what is wrong: not '.' or '..', no path separator, no leading dot or dash (a hidden file, an
    option), no control character."""
    if not isinstance(name, str) or not name:
        return 'must be non-empty text'
    if name in ('.', '..') or any(c in name for c in '/\\'):
        return "must be a plain file name (not '.' or '..', no '/' or '\\')"
    if name[0] in '.-':
        return 'must not start with a dot or a dash'
    if any(ord(c) < 32 or ord(c) == 127 for c in name):
        return 'must not hold control characters'
    return None


def check_size(sweep, episodes, source):
    """SweepError if the sweep has more than MAX_EPISODES episodes (``episodes`` per cell)."""
    total = sweep.n_cells * episodes
    if total > MAX_EPISODES:
        raise SweepError(f'{source}: {sweep.n_cells} grid cells x {episodes} episodes = {total} '
                         f'episodes; at most {MAX_EPISODES} in one sweep (split it with --where)')


def load(path):
    """Parse a sweep file; SweepError naming the file for a missing file or bad YAML (read by
    ship_sim.safe_load: bounded size, nesting, aliases and numbers, no key given twice)."""
    path = Path(path)
    try:
        doc = load_yaml_file(path)
    except InputError as exc:
        raise SweepError(str(exc)) from None
    return parse(doc, str(path))


def _draw(rng, dist, args):
    if dist == 'uniform':
        return float(rng.uniform(args[0], args[1]))
    if dist == 'normal':
        return float(rng.normal(args[0], args[1]))
    return args[int(rng.integers(len(args)))]


def expand(sweep, episodes=None):
    """The sweep's episodes as dicts (episode, cell, sample, seed and every PARAMETERS entry),
    in episode order; ``episodes`` overrides the samples per cell."""
    n = sweep.episodes if episodes is None else int(episodes)
    cells = list(itertools.product(*sweep.grid.values())) if sweep.grid else [()]
    out = []
    for c, values in enumerate(cells):
        for j in range(n):
            index = c * n + j
            ss = np.random.SeedSequence(sweep.seed, spawn_key=(j if sweep.paired else index,))
            rng = np.random.default_rng(ss)
            ep = dict(sweep.base)
            ep.update(zip(sweep.grid, values))
            for name in sorted(sweep.random):
                ep[name] = _draw(rng, *sweep.random[name])
            ep.update(episode=index, cell=c, sample=j, seed=int(ss.generate_state(1)[0]))
            out.append(ep)
    return out


def resolve_route(template, model, sweep_file=None):
    """Path of the route file: ``{model}`` substituted, relative to the sweep file's folder
    if it exists there, else to the repository root."""
    rel = Path(template.format(model=model))
    if rel.is_absolute():
        return rel
    if sweep_file:
        near = Path(sweep_file).resolve().parent / rel
        if near.exists():
            return near
    return REPO / rel
