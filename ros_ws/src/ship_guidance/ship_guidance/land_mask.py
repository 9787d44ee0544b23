"""Where the own ship must not go: a chart raster of land, widened by a clearance (pure).

``LandMask`` holds a boolean grid in the local NED frame: row i covers north in
[origin_north + i res, origin_north + (i + 1) res), column j east likewise (the layout of a
nav_msgs/OccupancyGrid with an unrotated origin, whose rows run along the ENU y axis, north).
A cell is blocked when it is land or its centre lies within ``clearance_m`` of a land cell's
centre (scipy's exact Euclidean distance transform). ``hits`` looks points up, vectorised; a
point off the grid is not blocked (the chart says nothing there). SB-MPC's grounding cost
(ship_guidance.sbmpc) scores the predicted tracks with it. A grid whose origin is not finite
or that reaches beyond MAX_COORDINATE_M from the map origin (ship_sim.bounds) is refused: such a
chart is a fault, and a NaN origin would put every point off the grid (never blocked).
"""
import numpy as np
from scipy.ndimage import distance_transform_edt

from ship_sim.bounds import MAX_COORDINATE_M


class LandMask:
    def __init__(self, land, origin_north, origin_east, resolution, clearance_m=0.0):
        land = np.asarray(land, dtype=bool)
        if land.ndim != 2 or 0 in land.shape:
            raise ValueError(f'land must be a non-empty 2-D grid, got shape {land.shape}')
        if not (np.isfinite(resolution) and resolution > 0.0):
            raise ValueError(f'resolution must be > 0 m, got {resolution}')
        if not (np.isfinite(clearance_m) and clearance_m >= 0.0):
            raise ValueError(f'clearance_m must be >= 0 m, got {clearance_m}')
        self.origin = np.array([origin_north, origin_east], dtype=float)
        far = np.abs(self.origin) + np.array(land.shape) * float(resolution)
        if not far.max() <= MAX_COORDINATE_M:      # also NaN
            raise ValueError(f'the grid (origin north, east {origin_north:.3g}, '
                             f'{origin_east:.3g} m, {land.shape[0]} x {land.shape[1]} cells of '
                             f'{resolution:.3g} m) reaches beyond {MAX_COORDINATE_M:.0e} m from '
                             'the origin')
        self.resolution, self.clearance_m = float(resolution), float(clearance_m)
        if clearance_m > 0.0 and land.any():
            land = distance_transform_edt(~land, sampling=self.resolution) <= clearance_m
        self.blocked = land

    @classmethod
    def from_occupancy(cls, data, width, height, resolution, origin_x, origin_y, *,
                       occupied=50, clearance_m=0.0):
        """From a nav_msgs/OccupancyGrid's fields (ENU map frame, unrotated origin): ``data``
        row-major from the origin, a cell is land when its value is >= ``occupied`` (unknown,
        -1, is not land)."""
        grid = np.asarray(data, dtype=np.int16)
        if grid.size != width * height:
            raise ValueError(f'occupancy data has {grid.size} cells, not {width} x {height}')
        return cls(grid.reshape(height, width) >= occupied, origin_y, origin_x, resolution,
                   clearance_m)

    def hits(self, points):
        """Blocked or not, for NED points (..., 2) (north, east) in metres: bool (...)."""
        p = np.asarray(points, dtype=float)
        idx = np.floor((p - self.origin) / self.resolution)
        rows, cols = self.blocked.shape
        inside = ((idx[..., 0] >= 0) & (idx[..., 0] < rows)
                  & (idx[..., 1] >= 0) & (idx[..., 1] < cols))
        out = np.zeros(p.shape[:-1], dtype=bool)
        i, j = idx[inside].astype(np.intp).T
        out[inside] = self.blocked[i, j]
        return out
