"""What a route file becomes (RoutePlan), and the one error type route readers raise (RouteError).

A RoutePlan holds the geometry as a ship_guidance.path.Route in the local NED frame (metres,
x north, y east) and the metadata a node or a report needs: name, citation, source frame,
geodetic origin (if any), the corner points as written, and reader-specific extras.
"""
from dataclasses import dataclass, field
from typing import Any, Optional

import numpy as np


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


@dataclass
class RoutePlan:
    """A route ready for guidance plus where it came from.

    route            ship_guidance.path.Route in local NED (m)
    name, source     route name and its citation / provenance (from the file)
    frame            frame the file was written in: 'enu', 'wgs84' or a reader's own (e.g. 'seed003_xy')
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
