"""One entry point for route files: picks the reader by file extension.

    .yaml / .yml   YAML route file          (ship_planner.yaml_route_reader)
    .wpt           waypoint table in the format of Simakis 1992 (ship_planner.waypoint_table)

Both return a RoutePlan (ship_guidance.path.Route in NED + metadata) or raise RouteError whose
message names the file and the line (or table row). Both read only regular UTF-8 files and
apply the same bounds (coordinates, route length, number of legs, file size), all defined in
ship_planner.route_data.
"""
import os

from ship_planner.route_data import RouteError, RoutePlan  # noqa: F401  (re-exported for callers)
from ship_planner.yaml_route_reader import load_route_yaml
from ship_planner.waypoint_table import load_waypoint_table

YAML_EXTENSIONS = ('.yaml', '.yml')
TABLE_EXTENSIONS = ('.wpt',)


def load_route(path, length_unit_m=None):
    """Read any supported route file. length_unit_m rescales a waypoint table (ignored for YAML,
    whose coordinates are metres or degrees already)."""
    ext = os.path.splitext(str(path))[1].lower()
    if ext in YAML_EXTENSIONS:
        return load_route_yaml(path)
    if ext in TABLE_EXTENSIONS:
        return load_waypoint_table(path, length_unit_m)
    raise RouteError(f'unknown route file type "{ext}"; use one of '
                     f'{", ".join(YAML_EXTENSIONS + TABLE_EXTENSIONS)}', file=str(path))
