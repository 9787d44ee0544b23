"""Checked fields of the launcher's YAML files: the error type and the small checks that name
the file and the key (ship_mission.scenario, ship_mission.vessel_spec and ship_mission.platoon share them)."""
import math


class ScenarioError(ValueError):
    """A scenario file that cannot run; the message names the file and the key."""


def need(cond, file, key, what):
    if not cond:
        raise ScenarioError(f'{file}: {key}: {what}')


def number(d, key, file, default, lo=None, hi=None, where=''):
    v = d.get(key, default)
    name = f'{where}{key}'
    need(isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v), file,
          name, f'must be a number, got {v!r}')
    need(lo is None or v >= lo, file, name, f'must be >= {lo}, got {v}')
    need(hi is None or v <= hi, file, name, f'must be <= {hi}, got {v}')
    return float(v)


def unknown(d, allowed, file, where):
    extra = sorted(set(d) - allowed)
    need(not extra, file, where + extra[0] if extra else where,
          f"unknown key; allowed: {', '.join(sorted(allowed))}")
