"""Navigable-water charts as rasters in a local (north, east) frame, and the clearance they allow.

Source: Lee 2004, Chapter 3 (optimal route on an electronic chart): the
chart is turned into an image of navigable water before closing and thinning. The chapter reads
the land areas of an S-57 ENC (Table 3.1, object LNDARE); its equations are not legible in the
OCR. Here a chart comes from one of:

- real shoreline: GSHHG full resolution (Wessel & Smith 1996, v2.3.7) or OpenStreetMap land
  polygons, both shipped inside the roaring-landmask wheel (works offline); each cell centre is
  tested point-in-polygon (``Shapes.contains_many``);
- an S-57 ENC cell (.000) through GDAL's S-57 driver (fiona wheel): LNDARE areas are land and
  DEPARE areas whose minimum depth DRVAL1 is below the draft are too shallow;
- synthetic charts for tests: land polygons in metres, or an image file (dark = land).

Grid: cell [i, j] has its centre at north = north0 + i * res, east = east0 + j * res (metres,
NED as every pure module; row index grows northward). A cell is water when its centre is water.
Geodetic charts use the tangent plane at ``origin`` (ship_sim.geodetic).

Clearance. ``distance_to_land`` is the Euclidean distance transform (scipy.ndimage) from each
cell centre to the nearest land cell centre (m). ``free_mask(C)`` marks cells where a ship keeps
at least C metres from land; it asks for C + ``grid_margin`` with grid_margin = sqrt(2) res,
because a point may be res / sqrt(2) from the centre of the cell it lies in and the land's edge
res / sqrt(2) from a land cell centre. Paths are checked exactly: a straight leg is clear when
every cell it passes through is free (segments_clear: exact grid traversal), an arc when the
chords of at most half a cell that approximate it are (their sagitta, < res^2 / (32 R), is
negligible). With that margin every point of a clear path is at least C from every land cell;
land thinner than a cell that covers no cell centre is invisible to any raster, so choose the
resolution finer than the smallest islet that matters. Outside the raster counts as not free.

Errors: every problem raises ChartError, one class for charts and planning, whose message says
what is wrong and how to fix it.
"""
import hashlib
import json
import os
from dataclasses import dataclass, field

import numpy as np
from scipy import ndimage

from ship_sim.geodetic import geodetic_to_ned, ned_to_geodetic

#: Default upper limit on raster cells (a 2000 x 2000 grid: ~100 MB of working arrays).
DEFAULT_MAX_CELLS = 4_000_000
#: Grid margin added to the clearance, in cells (see the module docstring).
GRID_MARGIN_CELLS = np.sqrt(2.0)
#: Arcs are checked as chords this many cells long (their sagitta is negligible).
SAMPLE_STEP_CELLS = 0.5
CACHE_FORMAT = 1
PROVIDERS = ('gshhg', 'osm')
IMAGE_EXTENSIONS = ('.png', '.jpg', '.jpeg', '.tif', '.tiff', '.bmp', '.gif')


class ChartError(ValueError):
    """A chart cannot be built or read, or no route can be planned on it. The message says which
    and suggests the fix (move a point, lower the clearance, coarser resolution, ...)."""


def default_cache_dir():
    """$SHIPNAV_CACHE, else $XDG_CACHE_HOME/shipnav, else ~/.cache/shipnav."""
    if os.environ.get('SHIPNAV_CACHE'):
        return os.environ['SHIPNAV_CACHE']
    base = os.environ.get('XDG_CACHE_HOME') or os.path.join(os.path.expanduser('~'), '.cache')
    return os.path.join(base, 'shipnav')


@dataclass
class Chart:
    """Navigable water on a regular grid (see the module docstring for the frame).

    water           (ny, nx) bool, True where the cell centre is navigable water
    resolution_m    cell size (m)
    north0, east0   centre of cell [0, 0] in the local frame (m)
    origin          (lat_deg, lon_deg) of the local frame's (0, 0), or None for a synthetic chart
    source          text saying where the chart comes from (for reports and route files)
    """
    water: np.ndarray
    resolution_m: float
    north0: float = 0.0
    east0: float = 0.0
    origin: tuple = None
    source: str = 'synthetic'
    _dist: np.ndarray = field(default=None, repr=False)
    _free: dict = field(default_factory=dict, repr=False)

    def __post_init__(self):
        self.water = np.ascontiguousarray(self.water, dtype=bool)
        if self.water.ndim != 2 or min(self.water.shape) < 2:
            raise ChartError(f'a chart needs a 2-D grid of at least 2 x 2 cells, got shape {self.water.shape}')
        r = float(self.resolution_m)
        if not np.isfinite(r) or r <= 0.0:
            raise ChartError(f'chart resolution must be a positive number of metres, got {self.resolution_m}')
        self.resolution_m = r

    # ---- geometry --------------------------------------------------------------------------
    @property
    def shape(self):
        return self.water.shape

    @property
    def grid_margin(self):
        """Metres added to a clearance for the raster's discretisation (module docstring)."""
        return GRID_MARGIN_CELLS * self.resolution_m

    @property
    def sample_step(self):
        """Longest chord (m) used to check an arc against the raster."""
        return SAMPLE_STEP_CELLS * self.resolution_m

    def extent(self):
        """(north_min, north_max, east_min, east_max) of the cell edges (m)."""
        h = 0.5 * self.resolution_m
        ny, nx = self.shape
        return (self.north0 - h, self.north0 + (ny - 1) * self.resolution_m + h,
                self.east0 - h, self.east0 + (nx - 1) * self.resolution_m + h)

    def cell_index(self, points):
        """Nearest cell (i, j) of (..., 2) NED points and whether it lies inside the raster."""
        p = np.asarray(points, dtype=float)
        i = np.rint((p[..., 0] - self.north0) / self.resolution_m).astype(np.int64)
        j = np.rint((p[..., 1] - self.east0) / self.resolution_m).astype(np.int64)
        ny, nx = self.shape
        inside = (i >= 0) & (i < ny) & (j >= 0) & (j < nx)
        return i, j, inside

    def cell_centers(self, i, j):
        """NED coordinates (m) of cell centres, as an (..., 2) array."""
        return np.stack([self.north0 + np.asarray(i) * self.resolution_m,
                         self.east0 + np.asarray(j) * self.resolution_m], axis=-1)

    def lookup(self, mask, points):
        """mask value of the nearest cell of each point; False outside the raster."""
        i, j, inside = self.cell_index(points)
        out = np.zeros(np.shape(i), dtype=bool)
        out[inside] = mask[i[inside], j[inside]]
        return out

    # ---- clearance -------------------------------------------------------------------------
    def distance_to_land(self):
        """(ny, nx) distance (m) from each cell centre to the nearest land cell centre (0 on land;
        +inf everywhere when the chart has no land)."""
        if self._dist is None:
            if self.water.all():
                self._dist = np.full(self.shape, np.inf)
            else:
                self._dist = ndimage.distance_transform_edt(self.water) * self.resolution_m
        return self._dist

    def free_mask(self, clearance_m):
        """Cells where the ship keeps clearance_m (m) from land, grid margin included."""
        c = float(clearance_m)
        if not np.isfinite(c) or c < 0.0:
            raise ChartError(f'clearance must be a number of metres >= 0, got {clearance_m}')
        key = round(c, 6)
        if key not in self._free:
            self._free[key] = self.water & (self.distance_to_land() >= c + self.grid_margin)
        return self._free[key]

    def to_ned(self, lat_deg, lon_deg):
        """Latitude/longitude (deg) -> local (north, east) m; needs a geodetic chart."""
        if self.origin is None:
            raise ChartError('this chart has no geodetic origin; give positions in metres (north, east)')
        return geodetic_to_ned(lat_deg, lon_deg, *self.origin)

    def to_geodetic(self, north, east):
        if self.origin is None:
            raise ChartError('this chart has no geodetic origin; positions stay in metres')
        return ned_to_geodetic(north, east, *self.origin)

    def describe_point(self, p):
        """A point for messages: lat/lon when the chart is geodetic, else metres."""
        if self.origin is not None:
            lat, lon = self.to_geodetic(float(p[0]), float(p[1]))
            return f'{lat:.5f} N, {lon:.5f} E (north {p[0]:.0f} m, east {p[1]:.0f} m)'
        return f'(north {p[0]:.1f} m, east {p[1]:.1f} m)'


# ---- grids ------------------------------------------------------------------------------------
def check_cells(ny, nx, resolution_m, max_cells, what):
    """Refuse a grid larger than max_cells with the resolution that would fit."""
    n = int(ny) * int(nx)
    if n > max_cells:
        coarser = resolution_m * np.sqrt(n / max_cells)
        raise ChartError(f'{what} at {resolution_m:g} m resolution needs {ny} x {nx} = {n:,} cells, more than the '
                         f'limit of {max_cells:,}; use a resolution of at least {np.ceil(coarser):.0f} m, a smaller '
                         f'box, or raise the cell limit (max_cells / --max-cells)')


def grid_for_extent(north_min, north_max, east_min, east_max, resolution_m, max_cells=DEFAULT_MAX_CELLS,
                    what='the chart'):
    """(north0, east0, ny, nx) of a grid whose cells cover the rectangle."""
    r = float(resolution_m)
    if not np.isfinite(r) or r <= 0.0:
        raise ChartError(f'resolution must be a positive number of metres, got {resolution_m}')
    if not (north_max > north_min and east_max > east_min):
        raise ChartError(f'empty chart extent: north {north_min:g}..{north_max:g} m, east {east_min:g}..{east_max:g} m')
    ny = int(np.ceil((north_max - north_min) / r))
    nx = int(np.ceil((east_max - east_min) / r))
    check_cells(ny, nx, r, max_cells, what)
    if ny < 2 or nx < 2:
        raise ChartError(f'{what} is only {ny} x {nx} cells at {r:g} m resolution; use a finer resolution')
    return north_min + 0.5 * r, east_min + 0.5 * r, ny, nx


def box_grid(lat_min, lat_max, lon_min, lon_max, resolution_m, origin=None, max_cells=DEFAULT_MAX_CELLS):
    """Grid covering a latitude/longitude box in the tangent plane at origin (default: box centre).

    Returns (origin, north0, east0, ny, nx). The grid is the rectangle around the box's outline."""
    for name, v in (('lat_min', lat_min), ('lat_max', lat_max), ('lon_min', lon_min), ('lon_max', lon_max)):
        if not np.isfinite(v):
            raise ChartError(f'box {name} must be a finite number of degrees, got {v}')
    if not (-80.0 <= lat_min < lat_max <= 80.0):
        raise ChartError(f'box latitudes must satisfy -80 <= lat_min < lat_max <= 80, got {lat_min}, {lat_max}')
    if not (-180.0 <= lon_min < lon_max <= 180.0):
        raise ChartError(f'box longitudes must satisfy -180 <= lon_min < lon_max <= 180, got {lon_min}, {lon_max}')
    if origin is None:
        origin = (0.5 * (lat_min + lat_max), 0.5 * (lon_min + lon_max))
    t = np.linspace(0.0, 1.0, 21)
    lats = np.concatenate([lat_min + 0 * t, lat_max + 0 * t, lat_min + (lat_max - lat_min) * t,
                           lat_min + (lat_max - lat_min) * t])
    lons = np.concatenate([lon_min + (lon_max - lon_min) * t, lon_min + (lon_max - lon_min) * t,
                           lon_min + 0 * t, lon_max + 0 * t])
    n, e = geodetic_to_ned(lats, lons, *origin)
    if np.hypot(n, e).max() > 60e3:
        raise ChartError(f'box reaches {np.hypot(n, e).max() / 1e3:.0f} km from its origin; the local plane is good '
                         'to < 1 m only within 60 km: use a box smaller than about 120 km across')
    north0, east0, ny, nx = grid_for_extent(n.min(), n.max(), e.min(), e.max(), resolution_m, max_cells,
                                            what=f'the box {lat_min:g}..{lat_max:g} N, {lon_min:g}..{lon_max:g} E')
    return tuple(float(v) for v in origin), north0, east0, ny, nx


# ---- real shoreline ---------------------------------------------------------------------------
_SHAPES = {}


def _landmask_shapes(provider):
    """The roaring-landmask polygon set, loaded once per process (loading the wheel's data is slow)."""
    if provider not in PROVIDERS:
        raise ChartError(f'unknown shoreline source "{provider}"; use one of {", ".join(PROVIDERS)}')
    if provider not in _SHAPES:
        try:
            import roaring_landmask
        except ImportError:
            raise ChartError('the real shoreline needs the roaring-landmask package '
                             '(pip install -r requirements.txt)') from None
        p = roaring_landmask.LandmaskProvider.Gshhg if provider == 'gshhg' else roaring_landmask.LandmaskProvider.Osm
        _SHAPES[provider] = roaring_landmask.Shapes.new(p)
    return _SHAPES[provider]


def _landmask_version():
    try:
        from importlib.metadata import version
        return version('roaring-landmask')
    except Exception:  # noqa: BLE001 (the key only has to change when the data may change)
        return 'unknown'


def shoreline_chart(lat_min, lat_max, lon_min, lon_max, resolution_m, origin=None, provider='gshhg',
                    cache_dir=None, max_cells=DEFAULT_MAX_CELLS, use_cache=True, progress=None):
    """Navigable water of a latitude/longitude box from real shoreline data (GSHHG or OSM).

    The raster is cached as an .npz under cache_dir (default: default_cache_dir()) keyed by box,
    resolution, origin, provider and the roaring-landmask version, so a repeated plan on the same
    box does not rebuild it. progress(text) gets a line per step.
    """
    say = progress or (lambda text: None)
    origin, north0, east0, ny, nx = box_grid(lat_min, lat_max, lon_min, lon_max, resolution_m, origin, max_cells)
    key = {'kind': 'shoreline', 'format': CACHE_FORMAT, 'provider': provider, 'landmask': _landmask_version(),
           'box': [round(float(v), 7) for v in (lat_min, lat_max, lon_min, lon_max)],
           'resolution_m': round(float(resolution_m), 6), 'origin': [round(v, 7) for v in origin]}
    source = (f'{"GSHHG full resolution" if provider == "gshhg" else "OpenStreetMap land polygons"} '
              f'(roaring-landmask {key["landmask"]}), box {lat_min:g}..{lat_max:g} N, {lon_min:g}..{lon_max:g} E, '
              f'{resolution_m:g} m cells')
    path = None
    if use_cache:
        digest = hashlib.sha1(json.dumps(key, sort_keys=True).encode()).hexdigest()[:16]
        path = os.path.join(cache_dir or default_cache_dir(), f'shoreline-{provider}-{digest}.npz')
        water = _read_cache(path, (ny, nx), say)
        if water is not None:
            say(f'chart: {ny} x {nx} cells from cache {path}')
            return Chart(water, resolution_m, north0, east0, origin, source)
    say(f'chart: loading the {provider} shoreline (a few seconds, once per process)')
    shapes = _landmask_shapes(provider)
    say(f'chart: testing {ny} x {nx} = {ny * nx:,} cell centres against the shoreline')
    water = np.empty((ny, nx), dtype=bool)
    east = east0 + np.arange(nx) * resolution_m
    rows_per_block = max(1, 250_000 // nx)
    for i0 in range(0, ny, rows_per_block):
        i = np.arange(i0, min(ny, i0 + rows_per_block))
        nn, ee = np.meshgrid(north0 + i * resolution_m, east, indexing='ij')
        lat, lon = ned_to_geodetic(nn.ravel(), ee.ravel(), *origin)
        land = shapes.contains_many(np.ascontiguousarray(lon, dtype=float), np.ascontiguousarray(lat, dtype=float))
        water[i0:i0 + len(i)] = ~np.asarray(land, dtype=bool).reshape(len(i), nx)
    if path is not None:
        _write_cache(path, water, key, say)
    return Chart(water, resolution_m, north0, east0, origin, source)


def _read_cache(path, shape, say):
    if not os.path.exists(path):
        return None
    try:
        with np.load(path, allow_pickle=False) as z:
            water = np.unpackbits(z['water_bits'])[:shape[0] * shape[1]].reshape(shape).astype(bool)
        return water
    except Exception as exc:  # noqa: BLE001 (a damaged cache file is rebuilt, not fatal)
        say(f'chart: ignoring unreadable cache file {path} ({exc}); rebuilding')
        return None


def _write_cache(path, water, key, say):
    try:
        os.makedirs(os.path.dirname(path), exist_ok=True)
        tmp = path + f'.{os.getpid()}.tmp.npz'
        np.savez_compressed(tmp, water_bits=np.packbits(water.ravel()), key=json.dumps(key, sort_keys=True))
        os.replace(tmp, path)
        say(f'chart: cached as {path}')
    except OSError as exc:
        say(f'chart: could not write the cache {path} ({exc.strerror}); continuing without it')


# ---- synthetic charts -------------------------------------------------------------------------
def rasterize_polygons(polygons, north0, east0, ny, nx, resolution_m):
    """(ny, nx) bool: cells whose centre is inside any polygon.

    polygons: list of polygons; a polygon is an (N, 2) NED array (m) or a list of rings (the
    first the outline, the others holes; even-odd rule inside one polygon).
    """
    from skimage.draw import polygon as fill

    inside = np.zeros((ny, nx), dtype=bool)
    for poly in polygons:
        rings = _rings(poly)
        mask = np.zeros((ny, nx), dtype=bool)
        for ring in rings:
            ring = np.asarray(ring, dtype=float)
            if ring.ndim != 2 or ring.shape[1] != 2 or len(ring) < 3 or not np.all(np.isfinite(ring)):
                raise ChartError(f'a polygon ring must be >= 3 finite (north, east) points, got shape {ring.shape}')
            rr, cc = fill((ring[:, 0] - north0) / resolution_m, (ring[:, 1] - east0) / resolution_m, (ny, nx))
            mask[rr, cc] ^= True
        inside |= mask
    return inside


def _rings(poly):
    """A polygon given as one (N, 2) ring or as a list of rings -> list of (N, 2) arrays."""
    try:
        a = np.asarray(poly, dtype=float)
        if a.ndim == 2:
            return [a]
    except ValueError:           # rings of different lengths
        pass
    return [np.asarray(r, dtype=float) for r in poly]


def polygon_chart(land_polygons, extent, resolution_m, origin=None, max_cells=DEFAULT_MAX_CELLS, source=None):
    """Synthetic chart: land polygons (NED m) inside extent = (north_min, north_max, east_min, east_max)."""
    north0, east0, ny, nx = grid_for_extent(*extent, resolution_m, max_cells)
    land = rasterize_polygons(land_polygons, north0, east0, ny, nx, resolution_m)
    return Chart(~land, resolution_m, north0, east0, origin,
                 source or f'synthetic chart: {len(land_polygons)} land polygon(s), {resolution_m:g} m cells')


def image_chart(path, resolution_m, north0=None, east0=None, origin=None, max_cells=DEFAULT_MAX_CELLS):
    """Chart from an image file: north up, light pixels water, dark pixels land (threshold at half
    the grey range), one pixel = one cell of resolution_m. The lower-left pixel's centre is at
    (north0, east0), default (res / 2, res / 2) so the image covers [0, H res] x [0, W res]."""
    path = str(path)
    if os.path.exists(path):
        _check_regular(path)
    try:
        from PIL import Image
        with Image.open(path) as im:
            # The size is in the header: a huge image is refused before it is decoded.
            check_cells(im.height, im.width, resolution_m, max_cells, f'the image {path}')
            img = np.asarray(im.convert('L'), dtype=float)
    except ChartError:
        raise
    except FileNotFoundError:
        raise ChartError(f'chart image {path} does not exist; check the path') from None
    except Exception as exc:  # noqa: BLE001 (any decoder failure means the same to the user)
        raise ChartError(f'cannot read the chart image {path}: {exc}; give a PNG/JPEG/TIFF '
                         'with dark land and light water') from None
    lo, hi = img.min(), img.max()
    water = img > 0.5 * (lo + hi) if hi > lo else np.full(img.shape, hi > 0)
    r = float(resolution_m)
    return Chart(water[::-1].copy(), r, 0.5 * r if north0 is None else north0, 0.5 * r if east0 is None else east0,
                 origin, f'image {os.path.basename(path)}, {r:g} m per pixel')


def _check_regular(path):
    """ChartError unless ``path`` is a regular file (a FIFO would block the reader)."""
    from ship_sim.safe_load import InputError, check_regular_file
    try:
        check_regular_file(path)
    except InputError as exc:
        raise ChartError(f'cannot read the chart {path}: {exc.detail}') from None


# ---- S-57 ENC ---------------------------------------------------------------------------------
def _fiona():
    try:
        import fiona
    except ImportError:
        raise ChartError('reading an S-57 ENC cell (.000) needs fiona with GDAL\'s S-57 driver '
                         '(pip install -r requirements.txt)') from None
    if 'S57' not in fiona.supported_drivers:
        raise ChartError('this fiona build has no S-57 driver; use the shoreline source (--source gshhg) '
                         'or a fiona wheel that bundles GDAL with S57')
    return fiona


def _polygon_rings(geometry):
    """GeoJSON-like Polygon / MultiPolygon -> list of polygons, each a list of (lon, lat) rings."""
    if geometry is None:
        return []
    kind, coords = geometry['type'], geometry['coordinates']
    if kind == 'Polygon':
        return [[np.asarray(r, dtype=float)[:, :2] for r in coords]]
    if kind == 'MultiPolygon':
        return [[np.asarray(r, dtype=float)[:, :2] for r in poly] for poly in coords]
    return []


def enc_chart(path, resolution_m, draft_m=None, box=None, origin=None, max_cells=DEFAULT_MAX_CELLS, progress=None):
    """Chart from an S-57 ENC cell: LNDARE areas are land; with draft_m, DEPARE areas whose
    DRVAL1 (shallowest depth, m) is less than the draft are not navigable either.

    box = (lat_min, lat_max, lon_min, lon_max), default the cell's own bounds.
    """
    say = progress or (lambda text: None)
    path = str(path)
    if not os.path.exists(path):
        raise ChartError(f'ENC cell {path} does not exist; check the path')
    _check_regular(path)
    fiona = _fiona()
    try:
        layers = fiona.listlayers(path)
    except Exception as exc:  # noqa: BLE001 (GDAL reports damaged files in many ways)
        raise ChartError(f'cannot read {path} as an S-57 ENC cell: {exc}; give an unzipped ENC base cell '
                         '(.000) with its update files next to it') from None
    if 'LNDARE' not in layers and 'DEPARE' not in layers:
        raise ChartError(f'{path} has neither land areas (LNDARE) nor depth areas (DEPARE) '
                         f'(layers: {", ".join(layers) or "none"}); it cannot make a navigable-water chart')
    land, shallow, bounds = [], [], None
    for layer in ('LNDARE', 'DEPARE'):
        if layer not in layers or (layer == 'DEPARE' and draft_m is None):
            continue
        try:
            with fiona.open(path, layer=layer) as src:
                b = src.bounds
                bounds = b if bounds is None else (min(bounds[0], b[0]), min(bounds[1], b[1]),
                                                   max(bounds[2], b[2]), max(bounds[3], b[3]))
                for feat in src:
                    geom = feat['geometry']
                    geom = dict(geom) if geom is not None else None
                    if layer == 'LNDARE':
                        land.extend(_polygon_rings(geom))
                    else:
                        drval1 = feat['properties'].get('DRVAL1')
                        if drval1 is None or float(drval1) < float(draft_m):
                            shallow.extend(_polygon_rings(geom))
        except Exception as exc:  # noqa: BLE001
            raise ChartError(f'cannot read layer {layer} of the ENC cell {path}: {exc}') from None
    say(f'chart: ENC {os.path.basename(path)}: {len(land)} land areas, {len(shallow)} areas shallower than the draft')
    if box is None:
        if bounds is None:
            raise ChartError(f'{path}: no geometry to take a box from; give the box explicitly')
        box = (bounds[1], bounds[3], bounds[0], bounds[2])
    origin, north0, east0, ny, nx = box_grid(*box, resolution_m, origin, max_cells)

    def to_ned(polys):
        out = []
        for poly in polys:
            rings = []
            for ring in poly:
                n, e = geodetic_to_ned(ring[:, 1], ring[:, 0], *origin)
                rings.append(np.column_stack([n, e]))
            out.append(rings)
        return out

    blocked = rasterize_polygons(to_ned(land) + to_ned(shallow), north0, east0, ny, nx, resolution_m)
    return Chart(~blocked, resolution_m, north0, east0, origin,
                 f'S-57 ENC {os.path.basename(path)} (LNDARE{", DEPARE < %g m" % draft_m if draft_m else ""}), '
                 f'{resolution_m:g} m cells')


def chart_from_file(path, resolution_m, **kwargs):
    """Any chart file by extension: .000 (S-57 ENC) or an image. Other types are refused."""
    ext = os.path.splitext(str(path))[1].lower()
    if ext == '.000':
        return enc_chart(path, resolution_m, **kwargs)
    if ext in IMAGE_EXTENSIONS:
        allowed = {k: v for k, v in kwargs.items() if k in ('north0', 'east0', 'origin', 'max_cells')}
        return image_chart(path, resolution_m, **allowed)
    raise ChartError(f'unknown chart file type "{ext}" ({path}); give an S-57 ENC cell (.000) or an image '
                     f'({", ".join(IMAGE_EXTENSIONS)})')


# ---- checking paths against a mask ------------------------------------------------------------
def segment_cells(chart, p0, p1, guard=1e-6):
    """(i, j) of every cell the segment p0 -> p1 (NED m) passes through: the exact grid traversal,
    from the parameters where it crosses cell edges, taken for the segment and for two copies
    shifted sideways by ``guard`` cells, so a segment that grazes a cell corner counts both cells
    beside it and rounding cannot make a sub-segment disagree with its parent."""
    a = np.array([(p0[0] - chart.north0) / chart.resolution_m, (p0[1] - chart.east0) / chart.resolution_m])
    b = np.array([(p1[0] - chart.north0) / chart.resolution_m, (p1[1] - chart.east0) / chart.resolution_m])
    d = b - a
    length = np.hypot(d[0], d[1])
    normal = np.array([-d[1], d[0]]) / length if length > 0.0 else np.zeros(2)
    cells_i, cells_j = [], []
    for off in (0.0, guard, -guard):
        a_k = a + off * normal
        ts = [np.array([0.0, 1.0])]
        for k in range(2):
            if d[k] != 0.0:
                lo, hi = sorted((a_k[k], a_k[k] + d[k]))
                edges = np.arange(np.floor(lo - 0.5) + 0.5, hi, 1.0)
                edges = edges[(edges > lo) & (edges < hi)]
                ts.append((edges - a_k[k]) / d[k])
        t = np.unique(np.concatenate(ts))
        mid = np.concatenate([[0.0], 0.5 * (t[:-1] + t[1:]), [1.0]])
        q = a_k + mid[:, None] * d
        cells_i.append(np.rint(q[:, 0]))
        cells_j.append(np.rint(q[:, 1]))
    return np.concatenate(cells_i).astype(np.int64), np.concatenate(cells_j).astype(np.int64)


def segments_clear(chart, mask, p0, p1):
    """For each segment p0[k] -> p1[k] ((K, 2) NED m): True when every cell it passes through is
    True in mask (inside the raster). With mask = chart.free_mask(C), every point of the segment
    then lies in a free cell and keeps C from land (module docstring)."""
    p0 = np.atleast_2d(np.asarray(p0, dtype=float))
    p1 = np.atleast_2d(np.asarray(p1, dtype=float))
    ny, nx = mask.shape
    out = np.zeros(len(p0), dtype=bool)
    for k in range(len(p0)):
        i, j = segment_cells(chart, p0[k], p1[k])
        inside = (i >= 0) & (i < ny) & (j >= 0) & (j < nx)
        out[k] = bool(inside.all() and mask[i, j].all())
    return out
