"""What a route file becomes (RoutePlan), and the one error type route readers raise (RouteError).

A RoutePlan holds the geometry as a ship_guidance.path.Route in the local NED frame (metres,
x north, y east) and the metadata a node or a report needs: name, citation, source frame,
geodetic origin (if any), the corner points as written, and reader-specific extras.

Bounds every route reader applies (one place; a route beyond them is refused with a RouteError):

- MAX_COORDINATE_M: |north| and |east| of every point, 1e7 m from the origin: the bound of
  ship_guidance.path.MAX_COORDINATE_M (which the nodes apply to incoming Path messages): beyond
  the scale of the Earth a number is not a place but a fault (1e308 overflows to inf);
- MAX_ROUTE_LENGTH_M (1000 km) and MAX_ROUTE_SAMPLES (100,000 legs, i.e. curve samples), also
  from ship_guidance.path: a generated curve (ship_guidance.curves) is refused before it is
  sampled, so a typo such as ``sweep_deg: 1.0e+9`` or ``step_m: 1e-9`` cannot take the memory of
  the machine;
- ship_sim.safe_load.MAX_FILE_BYTES (10 MB): route files are read only if they are regular files (a FIFO, a
  directory or a device is refused before it is read, so nothing blocks) of at most that size,
  and only as UTF-8 text (ship_sim.safe_load.read_regular_file, the reader of every input file).
"""
from dataclasses import dataclass, field
from typing import Any, Optional

import numpy as np

# One set of bounds for route files, generated curves and Path messages.
from ship_guidance.path import MAX_COORDINATE_M, MAX_ROUTE_LENGTH_M, MAX_ROUTE_SAMPLES
# Files are read by the project's one bounded reader (names kept for the route readers).
from ship_sim.safe_load import MAX_FILE_BYTES, TextFileError, read_text_file  # noqa: F401


class RouteError(ValueError):
    """A route file (or route data) is wrong. The message says where: file, line and/or row.

    Format: ``<file>:<line>: <what is wrong>``, or ``<file>: row <n> (line <l>): ...`` for
    waypoint tables. The parts are kept as attributes for programs: ``file``, ``line`` (1-based,
    or None), ``row`` (1-based data row of a table, or None) and ``detail`` (the bare message).
    """

    def __init__(self, detail, file=None, line=None, row=None):
        self.detail = str(detail)
        self.file = file
        self.line = line
        self.row = row
        super().__init__(self._format())

    def _format(self):
        where = self.file if self.file is not None else '<route>'
        if self.row is not None:
            where += f': row {self.row}'
            if self.line is not None:
                where += f' (line {self.line})'
        elif self.line is not None:
            where += f':{self.line}'
        return f'{where}: {self.detail}'


def check_point(north, east, what):
    """None if (north, east) is within MAX_COORDINATE_M, else the text of the refusal."""
    far = max(abs(north), abs(east))
    if not far <= MAX_COORDINATE_M:
        return (f'{what} is {far:.3g} m from the origin; at most {MAX_COORDINATE_M:.0e} m is '
                'physical')
    return None


def check_route_size(route):
    """None if a built route is within the bounds (module docstring), else the refusal text."""
    if len(route.legs) > MAX_ROUTE_SAMPLES:
        return f'the route has {len(route.legs)} legs; at most {MAX_ROUTE_SAMPLES} are accepted'
    if not route.length <= MAX_ROUTE_LENGTH_M:
        return (f'the route is {route.length:.4g} m long; at most {MAX_ROUTE_LENGTH_M:.0e} m is '
                'accepted')
    for i, leg in enumerate(route.legs):
        for p in (leg.start, leg.end):
            bad = check_point(float(p[0]), float(p[1]), f'leg {i + 1}')
            if bad:
                return bad
    return None


@dataclass
class RoutePlan:
    """A route ready for guidance plus where it came from.

    route            ship_guidance.path.Route in local NED (m)
    name, source     route name and its citation / provenance (from the file)
    frame            frame the file was written in: 'enu', 'wgs84' or a reader's own (e.g. 'simakis_xy')
    origin_lat_deg, origin_lon_deg   geodetic origin of the local frame, None if not given
    waypoints_ned    (N, 2) array of the points as written (before fillets), NED m
    file             file the plan was read from (None for in-memory text)
    extras           reader-specific data (e.g. a table's per-waypoint switching columns)
    """
    route: Any
    name: str
    source: str
    frame: str
    origin_lat_deg: Optional[float] = None
    origin_lon_deg: Optional[float] = None
    waypoints_ned: np.ndarray = field(default_factory=lambda: np.zeros((0, 2)))
    file: Optional[str] = None
    extras: dict = field(default_factory=dict)
