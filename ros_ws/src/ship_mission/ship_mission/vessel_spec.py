"""A vessel of a scenario as the launcher starts it: VesselSpec and the check of its mapping
(shared by the `vessels:` and `platoon:` sections, ship_mission.scenario and ship_mission.platoon)."""
from dataclasses import dataclass, field
from pathlib import Path

from ship_mission.fields import need, number
from ship_mission.waves import wave_parameters
from ship_mission.wind_block import check_wind

from ship_planner.route_data import MAX_COORDINATE_M


@dataclass
class VesselSpec:
    namespace: str
    model: str
    route_file: Path
    start: dict
    speed: float = None
    current: dict = field(default_factory=dict)
    vessel_params: dict = field(default_factory=dict)
    guidance_params: dict = field(default_factory=dict)
    autopilot_params: dict = field(default_factory=dict)
    # Platoon followers only (ship_mission.platoon): the predecessor's namespace and the set gap (m).
    # A follower runs follower_node (its `guidance` block holds follower_node parameters).
    predecessor: str = None
    spacing: float = None
    # Collision avoidance (ship_mission.scenario): colav_node parameters, None for no colav_node;
    # `traffic` marks a target vessel of the scenario's `traffic:` section.
    colav_params: dict = None
    traffic: bool = False
    # vessel_node's waves_* parameters from the `waves:` block (ship_mission.waves)
    wave_params: dict = field(default_factory=dict)
    # The wind (ship_mission.wind_block): the vessel's own `wind:` block, else the scenario's.
    wind: dict = field(default_factory=dict)


def parse_vessel(ns, v, route, path, where):
    """VesselSpec of one checked vessel mapping ``v`` (its keys already known to be allowed) with
    the resolved ``route`` file; ``where`` prefixes the keys in error messages."""
    need(isinstance(v.get('model'), str), path, where + 'model', 'a model name')
    start = v.get('start', {}) or {}
    need(isinstance(start, dict), path, where + 'start', 'a mapping')
    absolute = {'x_m', 'y_m', 'yaw_deg'}
    relative = {'along_m', 'cross_m', 'heading_deg'}
    need(set(start) <= absolute | relative and not (set(start) & absolute
                                                     and set(start) & relative),
          path, where + 'start', f'either {sorted(absolute)} or {sorted(relative)}')
    for k in start:   # positions as physical as route points (ship_planner.route_data);
        # along_m is checked against its route's length (ship_mission.scenario_checks.check_scenario)
        bound = MAX_COORDINATE_M if k in ('x_m', 'y_m', 'cross_m') else None
        number(start, k, path, 0.0, lo=bound and -bound, hi=bound, where=where + 'start.')
    speed = v.get('speed_mps')
    if speed is not None:
        speed = number(v, 'speed_mps', path, None, lo=0.0, hi=50.0, where=where)
    for key in ('current', 'vessel', 'guidance', 'autopilot', 'colav'):
        need(isinstance(v.get(key, {}) or {}, dict), path, where + key, 'a mapping')
    colav = None if 'colav' not in v else dict(v.get('colav') or {})
    waves = wave_parameters(v.get('waves') or {}, path, where + 'waves.')
    return VesselSpec(ns, v['model'], route, dict(start), speed,
                      dict(v.get('current') or {}), dict(v.get('vessel') or {}),
                      dict(v.get('guidance') or {}), dict(v.get('autopilot') or {}),
                      colav_params=colav, wave_params=waves, wind=check_wind(v.get('wind'), path, where + 'wind'))
