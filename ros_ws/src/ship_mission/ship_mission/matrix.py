"""Scenario matrices: one file that expands to the scenarios of a grid, which differ in a few keys.

A matrix file holds the one key ``matrix`` (scenarios/course_changes_004.yaml)::

    matrix:
      axes:                            # the scenarios: every combination, the first axis slowest
        ship: [mariner, tanker]
        controller: [fuzzy, pd]
      rules:                           # applied in order to the combinations each one matches
        - set:                         #   no `when`: every combination
            name: 'turn_{ship}_{controller}'
            duration_s: '{duration}'   #   a string that is one {variable} alone takes its value
            vessels: {vessel_0: {model: '{ship}', route: routes/x.yaml}}
        - when: {ship: tanker}         #   an axis -> one of its values, or a list of them
          vars: {duration: 1200.0}     #   variables, beside each axis's own value
        - when: {ship: mariner}
          vars: {duration: 400.0}
        - when: {controller: pd}
          set: {vessels: {vessel_0: {autopilot: {controller: pd}}}}

``set`` merges into the scenario being built (a mapping key by key, anything else replaced);
``vars`` adds or replaces variables (a later rule wins). Then every string of the scenario is
filled in from the variables (``str.format``: ``{angle}``, ``{speed:.1f}``), a variable's own
strings too, so one variable may use others; a string that is a single ``{name}`` becomes the
variable's value itself (a number, a list). Braces in a string always name a variable.

Each combination gives one complete scenario mapping, read and checked by ship_mission.scenario as if
it had been a file of its own (relative paths are relative to the matrix file); the names must
differ. Expanding is pure data: the same file gives the same scenarios in the same order.
"""
import copy
import itertools
import re

from ship_mission.fields import ScenarioError, need, unknown

MATRIX_KEYS = {'axes', 'rules'}
RULE_KEYS = {'when', 'vars', 'set'}
_WHOLE = re.compile(r'\{(\w+)\}')


def is_matrix(data):
    """True for the parsed content of a matrix file."""
    return isinstance(data, dict) and 'matrix' in data


def _listed(v):
    return v if isinstance(v, list) else [v]


def _check(data, path):
    """(axes, rules) of a matrix file's content, checked."""
    extra = sorted(str(k) for k in data if k != 'matrix')
    need(not extra, path, extra[0] if extra else 'matrix',
         'a matrix file holds only `matrix` (its rules build every key of the scenarios)')
    m = data['matrix']
    need(isinstance(m, dict), path, 'matrix', 'must be a mapping with axes and rules')
    unknown(m, MATRIX_KEYS, path, 'matrix.')
    axes = m.get('axes')
    need(isinstance(axes, dict) and axes, path, 'matrix.axes', 'a mapping axis -> list of values')
    for name, values in axes.items():
        where = f'matrix.axes.{name}'
        need(isinstance(name, str) and name.isidentifier(), path, where, 'an axis is a plain name')
        need(isinstance(values, list) and values, path, where, 'a non-empty list of values')
        need(all(isinstance(v, (str, int, float)) for v in values), path, where,
             f'values are strings or numbers, got {values!r}')
        need(len(set(values)) == len(values), path, where, f'values repeat: {values!r}')
    rules = m.get('rules', [])
    need(isinstance(rules, list), path, 'matrix.rules', 'a list of rules (when, vars, set)')
    for i, rule in enumerate(rules):
        where = f'matrix.rules[{i}]'
        need(isinstance(rule, dict), path, where, 'a mapping with when, vars and set')
        unknown(rule, RULE_KEYS, path, where + '.')
        for key in RULE_KEYS:
            need(isinstance(rule.get(key, {}), dict), path, f'{where}.{key}', 'must be a mapping')
        for axis, value in rule.get('when', {}).items():
            need(axis in axes, path, f'{where}.when.{axis}', f'not an axis ({", ".join(axes)})')
            for v in _listed(value):
                need(v in axes[axis], path, f'{where}.when.{axis}',
                     f'{v!r} is not one of its values {axes[axis]}')
    return axes, rules


def _merge(into, patch):
    for key, value in patch.items():
        if isinstance(value, dict) and isinstance(into.get(key), dict):
            _merge(into[key], value)
        else:
            into[key] = copy.deepcopy(value)


class _Filler:
    """Fills in the strings of one combination from its variables (each variable filled once)."""

    def __init__(self, variables, path, label):
        self.raw, self.done, self.busy = variables, {}, []
        self.path, self.label, self.where = path, label, 'scenario'

    def __getitem__(self, name):        # str.format_map looks the names up here
        if name not in self.done:
            at = f'{self.label}: {self.where}'
            need(name in self.raw, self.path, at,
                 f'no variable {name!r} (axes and vars give: {", ".join(sorted(self.raw))})')
            need(name not in self.busy, self.path, at,
                 f'variables fill each other in a loop: {" -> ".join(self.busy + [name])}')
            self.busy.append(name)
            self.done[name] = self.fill(self.raw[name], f'vars.{name}')
            self.busy.pop()
        return self.done[name]

    def fill(self, obj, where):
        if isinstance(obj, dict):
            return {k: self.fill(v, f'{where}.{k}') for k, v in obj.items()}
        if isinstance(obj, list):
            return [self.fill(v, f'{where}[{i}]') for i, v in enumerate(obj)]
        if not isinstance(obj, str):
            return obj
        outer, self.where = self.where, where
        try:
            whole = _WHOLE.fullmatch(obj)
            if whole:
                return copy.deepcopy(self[whole.group(1)])
            return obj.format_map(self)
        except ScenarioError:
            raise
        except (ValueError, KeyError, IndexError, AttributeError, TypeError) as exc:
            raise ScenarioError(f'{self.path}: {self.label}: {where}: cannot fill in {obj!r}: '
                                f'{exc}') from None
        finally:
            self.where = outer


def expand(data, path):
    """The scenario mappings of a matrix file's content ``data`` (see the module docstring), in
    the order of the axes' product. ScenarioError names the file, the combination and the key."""
    axes, rules = _check(data, path)
    out = []
    for combo in itertools.product(*axes.values()):
        point = dict(zip(axes, combo))
        label = 'matrix (' + ', '.join(f'{a}={v}' for a, v in point.items()) + ')'
        variables, scenario = dict(point), {}
        for rule in rules:
            if all(point[a] in _listed(v) for a, v in rule.get('when', {}).items()):
                variables.update(rule.get('vars', {}))
                _merge(scenario, rule.get('set', {}))
        out.append(_Filler(variables, path, label).fill(scenario, 'scenario'))
    names = [s.get('name') for s in out]
    twice = sorted({str(n) for n in names if names.count(n) > 1})
    need(not twice, path, 'matrix', f'the scenarios must have distinct names; repeated: {", ".join(twice)}')
    return out
