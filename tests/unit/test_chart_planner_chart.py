"""Charts for the optimal-route planner (ship_planner.chart): rasters, clearance, exact leg checks,
image and ENC files, cache, and the errors that tell the user what to change."""
import math

import numpy as np
import pytest

from ship_planner import chart as chart_mod
from ship_planner.chart import (ChartError, Chart, box_grid, chart_from_file, enc_chart, image_chart, polygon_chart,
                                segments_clear, shoreline_chart)


def square(n0, e0, size):
    return np.array([[n0, e0], [n0 + size, e0], [n0 + size, e0 + size], [n0, e0 + size]], dtype=float)


def test_polygon_raster_marks_cell_centres_inside_and_respects_holes():
    outer = square(0.0, 0.0, 1000.0)
    hole = square(300.0, 300.0, 400.0)
    c = polygon_chart([[outer, hole]], (-500.0, 1500.0, -500.0, 1500.0), 100.0)
    # cell centres at -450, -350, ..., 1450: a centre at 50 m lies inside the outline
    i, j, _ = c.cell_index(np.array([[50.0, 50.0], [950.0, 950.0], [-50.0, 50.0], [450.0, 450.0], [350.0, 350.0]]))
    assert not c.water[i[0], j[0]] and not c.water[i[1], j[1]]       # land inside the outline
    assert c.water[i[2], j[2]]                                          # outside
    assert c.water[i[3], j[3]] and c.water[i[4], j[4]]                  # inside the hole: water
    assert np.count_nonzero(~c.water) == 100 - 16                       # 10 x 10 cells minus a 4 x 4 hole


def test_free_mask_is_clearance_plus_grid_margin_from_land_cells():
    water = np.ones((41, 41), dtype=bool)
    water[20, 20] = False                                               # one land cell at (0, 0)
    c = Chart(water, 10.0, north0=-200.0, east0=-200.0)
    free = c.free_mask(50.0)
    need = 50.0 + math.sqrt(2.0) * 10.0                                 # clearance + sqrt(2) cells
    ii, jj = np.mgrid[0:41, 0:41]
    dist = np.hypot(ii - 20, jj - 20) * 10.0
    assert np.array_equal(free, dist >= need)


def test_segments_clear_is_the_exact_cell_traversal():
    water = np.ones((10, 10), dtype=bool)
    water[5, 5] = False
    c = Chart(water, 1.0)                                               # cell (i, j) centre at (i, j) m
    # a horizontal leg through row 5 hits the blocked cell; one along the row edge at 4.5 grazes
    # it (counts as touching), one at 4.49 does not
    assert not segments_clear(c, water, [[5.0, 0.0]], [[5.0, 9.0]])[0]
    assert not segments_clear(c, water, [[4.5, 0.0]], [[4.5, 9.0]])[0]
    assert segments_clear(c, water, [[4.49, 0.0]], [[4.49, 9.0]])[0]
    # a diagonal through the corner shared by cells (4, 4) and (5, 5) counts both cells beside it
    assert not segments_clear(c, water, [[0.5, 0.5]], [[8.5, 8.5]])[0]
    # a sub-segment of a clear segment is clear
    p0, p1 = np.array([1.2, 0.3]), np.array([4.2, 9.4])
    assert segments_clear(c, water, p0[None], p1[None])[0]
    for t0, t1 in ((0.1, 0.7), (0.33, 0.34), (0.5, 1.0)):
        assert segments_clear(c, water, (p0 + t0 * (p1 - p0))[None], (p0 + t1 * (p1 - p0))[None])[0]
    # leaving the raster is not clear
    assert not segments_clear(c, water, [[1.0, 1.0]], [[1.0, 12.0]])[0]


def test_image_chart_is_north_up_with_dark_land(tmp_path):
    import imageio.v3 as iio

    img = np.full((20, 30), 255, dtype=np.uint8)
    img[0:5, 0:3] = 0                                   # top-left corner of the picture: north-west land
    path = tmp_path / 'chart.png'
    iio.imwrite(path, img)
    c = image_chart(path, 10.0)
    assert c.shape == (20, 30)
    assert not c.water[19, 0] and not c.water[15, 2]    # row 19 = northernmost
    assert c.water[14, 0] and c.water[19, 3] and c.water[0, 0]
    n0, n1, e0, e1 = c.extent()
    assert (n0, n1, e0, e1) == (0.0, 200.0, 0.0, 300.0)


def test_unreadable_chart_files_are_refused_with_a_clear_message(tmp_path):
    bad = tmp_path / 'chart.png'
    bad.write_bytes(b'not a picture')
    with pytest.raises(ChartError, match='cannot read the chart image'):
        image_chart(bad, 10.0)
    with pytest.raises(ChartError, match='does not exist'):
        image_chart(tmp_path / 'missing.png', 10.0)
    with pytest.raises(ChartError, match='unknown chart file type ".txt"'):
        chart_from_file(tmp_path / 'chart.txt', 10.0)
    enc = tmp_path / 'US5XX01M.000'
    enc.write_bytes(b'\x00garbage, not ISO 8211' * 10)
    with pytest.raises(ChartError, match='cannot read .* as an S-57 ENC cell'):
        chart_from_file(enc, 50.0)
    with pytest.raises(ChartError, match='does not exist'):
        enc_chart(tmp_path / 'missing.000', 50.0)


def test_box_too_large_for_resolution_names_a_resolution_that_fits():
    # 0.5 deg x 0.5 deg at 35 N: ~55.5 km x ~45.6 km; at 5 m that is ~1.0e8 cells
    with pytest.raises(ChartError) as err:
        box_grid(34.75, 35.25, 128.75, 129.25, 5.0, max_cells=4_000_000)
    msg = str(err.value)
    assert 'more than the limit of 4,000,000' in msg
    coarser = float(msg.split('resolution of at least ')[1].split(' m')[0])
    # the suggested resolution makes the grid fit, and is not absurdly coarse
    o, n0, e0, ny, nx = box_grid(34.75, 35.25, 128.75, 129.25, coarser, max_cells=4_000_000)
    assert ny * nx <= 4_000_000                          # the suggested resolution fits
    assert 24.0 < coarser < 27.0                         # sqrt(1.0e8 / 4e6) * 5 m = 25 m


class _FakeShapes:
    """Stands in for roaring_landmask.Shapes: land north of a latitude."""

    def __init__(self, lat_land):
        self.lat_land = lat_land
        self.calls = 0

    def contains_many(self, lon, lat):
        self.calls += 1
        return np.asarray(lat) > self.lat_land


def test_shoreline_raster_is_cached_on_disk(tmp_path, monkeypatch):
    fake = _FakeShapes(35.0)
    monkeypatch.setattr(chart_mod, '_landmask_shapes', lambda provider: fake)
    box = (34.98, 35.02, 129.0, 129.05)
    c1 = shoreline_chart(*box, 100.0, cache_dir=str(tmp_path))
    assert fake.calls > 0
    calls = fake.calls
    c2 = shoreline_chart(*box, 100.0, cache_dir=str(tmp_path))
    assert fake.calls == calls                           # from the cache: no point tested again
    assert np.array_equal(c1.water, c2.water) and c1.origin == c2.origin
    rows = np.arange(c1.shape[0])
    centres = c1.cell_centers(rows, np.zeros_like(rows))
    lat, _ = c1.to_geodetic(centres[:, 0], centres[:, 1])
    assert np.array_equal(c1.water[:, 0], lat <= 35.0)   # land north of 35 N, as the fake says
    assert c1.water[:, 0].any() and not c1.water[:, 0].all()
    # another resolution is another key; a damaged cache file is rebuilt
    shoreline_chart(*box, 200.0, cache_dir=str(tmp_path))
    assert fake.calls > calls
    files = list(tmp_path.glob('shoreline-*.npz'))
    assert len(files) == 2
    files[0].write_bytes(b'damaged')
    calls = fake.calls
    shoreline_chart(*box, 100.0, cache_dir=str(tmp_path))
    shoreline_chart(*box, 200.0, cache_dir=str(tmp_path))
    assert fake.calls == calls + 1


class _FakeCollection:
    def __init__(self, feats, bounds):
        self.feats, self.bounds = feats, bounds

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        return False

    def __iter__(self):
        return iter(self.feats)


class _FakeFiona:
    """Stands in for fiona reading an S-57 cell: what GDAL's S57 driver gives for LNDARE / DEPARE."""
    supported_drivers = {'S57': 'r'}

    def __init__(self, layers):
        self.layers = layers

    def listlayers(self, path):
        return list(self.layers) + ['DSID', 'SOUNDG']

    def open(self, path, layer):
        feats = self.layers[layer]
        return _FakeCollection(feats, (129.0, 35.0, 129.02, 35.02))


def _lonlat_square(lon0, lat0, d):
    return {'type': 'Polygon', 'coordinates': [[(lon0, lat0), (lon0 + d, lat0), (lon0 + d, lat0 + d),
                                                 (lon0, lat0 + d), (lon0, lat0)]]}


def test_enc_land_and_areas_shallower_than_the_draft_are_blocked(tmp_path, monkeypatch):
    layers = {
        'LNDARE': [{'geometry': _lonlat_square(129.000, 35.000, 0.005), 'properties': {}}],
        'DEPARE': [{'geometry': _lonlat_square(129.010, 35.010, 0.005), 'properties': {'DRVAL1': 2.0}},
                   {'geometry': _lonlat_square(129.010, 35.000, 0.005), 'properties': {'DRVAL1': 20.0}}],
    }
    monkeypatch.setattr(chart_mod, '_fiona', lambda: _FakeFiona(layers))
    path = tmp_path / 'TEST.000'
    path.write_bytes(b'x')
    c = enc_chart(path, 25.0, draft_m=8.0)

    def water_at(lat, lon):
        n, e = c.to_ned(lat, lon)
        i, j, inside = c.cell_index(np.array([n, e]))
        assert inside
        return bool(c.water[i, j])

    assert not water_at(35.0025, 129.0025)       # LNDARE
    assert not water_at(35.0125, 129.0125)       # DEPARE 2 m < draft 8 m
    assert water_at(35.0025, 129.0125)           # DEPARE 20 m: deep enough
    assert water_at(35.0125, 129.0025)           # no feature: water
    c2 = enc_chart(path, 25.0)                   # no draft given: depth areas are ignored
    n, e = c2.to_ned(35.0125, 129.0125)
    i, j, _ = c2.cell_index(np.array([n, e]))
    assert c2.water[i, j]
