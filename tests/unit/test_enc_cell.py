"""A real S-57 ENC cell through the project's S-57 path (ship_planner.chart.enc_chart): GDAL's
test cell 1B5X02NE.000 (tests/data/enc/README.md), read by fiona's GDAL S-57 driver.

The expectations on what GDAL reads are those of GDAL's own test of the cell
(autotest/ogr/ogr_s57.py: the layers, their feature counts, the coastline's first points, the
quality area's extent); the chart built from it is checked against the cell's own polygons
taken to the local frame: land and shallow water where the cell has them, and a raster land
area within the band a raster of that resolution can get wrong around the outline.
"""
import math
from pathlib import Path

import fiona
import numpy as np
import pytest
import shapely.geometry as shapely_geometry

from ship_planner.chart import enc_chart
from ship_sim.geodetic import geodetic_to_ned

CELL = Path(__file__).resolve().parents[1] / 'data' / 'enc' / '1B5X02NE.000'
#: (layer, features) as GDAL's test lists them, in its order.
GDAL_LAYERS = [('DSID', 1), ('COALNE', 1), ('DEPARE', 4), ('DEPCNT', 4), ('LNDARE', 1),
               ('LNDELV', 2), ('SBDARE', 2), ('SLCONS', 1), ('SLOTOP', 1), ('SOUNDG', 2),
               ('M_COVR', 1), ('M_NSYS', 1), ('M_QUAL', 1)]
#: The coastline's first three points (lon, lat) and the quality area's extent (lon min, lat
#: min, lon max, lat max), from GDAL's test.
COAST_START = [(60.976834, -32.494426), (60.977182, -32.494538), (60.977424, -32.494774)]
M_QUAL_BOUNDS = (60.976834, -32.498666, 60.983166, -32.4935)
RESOLUTION_M = 2.0


def test_gdal_reads_the_cell_as_gdals_own_test_expects():
    assert CELL.is_file(), 'tests/data/enc/1B5X02NE.000 is missing (tests/data/enc/README.md)'
    assert [(n, len(_polygons(n))) for n in fiona.listlayers(CELL)] == GDAL_LAYERS
    with fiona.open(CELL, layer='COALNE') as src:
        coast = next(iter(src))
    assert coast['properties']['LNAM'] == 'FFFF7F4F0FB002D3'
    assert np.allclose(coast['geometry']['coordinates'][:3], COAST_START, atol=1e-6)
    with fiona.open(CELL, layer='M_QUAL') as src:
        quality = shapely_geometry.shape(next(iter(src))['geometry'])
    assert np.allclose(quality.bounds, M_QUAL_BOUNDS, atol=1e-6)


def _polygons(layer):
    """(properties, shapely geometry in lon/lat or None) of every feature of ``layer``."""
    with fiona.open(CELL, layer=layer) as src:
        return [(dict(f['properties']),
                 None if f['geometry'] is None else shapely_geometry.shape(f['geometry']))
                for f in src]


def _inside(area):
    """A point of ``area`` at least two cells from its outline (a raster of RESOLUTION_M
    classifies it as the area wherever the outline runs)."""
    core = area.buffer(-2.0 * RESOLUTION_M)
    assert not core.is_empty
    return core.representative_point()


def _ned(chart, polygon):
    lon, lat = np.asarray(polygon.exterior.coords).T
    n, e = geodetic_to_ned(lat, lon, *chart.origin)
    return shapely_geometry.Polygon(np.column_stack([n, e]))


def _water_at(chart, point):
    i, j, inside = chart.cell_index(np.array([point.x, point.y]))
    assert inside
    return bool(chart.water[i, j])


@pytest.fixture(scope='module')
def charts():
    return enc_chart(CELL, RESOLUTION_M), enc_chart(CELL, RESOLUTION_M, draft_m=3.0)


def test_the_chart_covers_the_cell_in_the_local_frame(charts):
    chart, _ = charts
    lon0, lat0, lon1, lat1 = M_QUAL_BOUNDS
    assert chart.origin == pytest.approx((0.5 * (lat0 + lat1), 0.5 * (lon0 + lon1)))
    north_min, north_max, east_min, east_max = chart.extent()
    for lat, lon in ((lat0, lon0), (lat0, lon1), (lat1, lon0), (lat1, lon1)):
        n, e = geodetic_to_ned(lat, lon, *chart.origin)
        assert north_min <= n <= north_max and east_min <= e <= east_max
    assert 'S-57 ENC 1B5X02NE.000' in chart.source


def test_land_is_where_the_cell_has_it_and_of_its_area(charts):
    chart, _ = charts
    [(_, land)] = _polygons('LNDARE')
    land = _ned(chart, land)
    # a point well inside the land area is land, the coastline's
    # first vertex moved a few cells to sea (east) is water
    assert not _water_at(chart, _inside(land))
    n, e = geodetic_to_ned(COAST_START[1][1], COAST_START[1][0], *chart.origin)
    assert _water_at(chart, shapely_geometry.Point(n, e + 4.0 * RESOLUTION_M))
    assert not _water_at(chart, shapely_geometry.Point(n, e - 4.0 * RESOLUTION_M))
    # a cell is land when its centre is inside: only cells the outline crosses can differ
    # from the polygon, by at most a cell each, and they lie within a cell diagonal of the
    # outline: in a band of 2 diagonals x the perimeter
    raster_area = np.count_nonzero(~chart.water) * RESOLUTION_M ** 2
    band = land.length * 2.0 * math.sqrt(2.0) * RESOLUTION_M
    assert abs(raster_area - land.area) <= band
    assert band < land.area / 4.0                     # the bound is a small part of the area


def test_depth_areas_shallower_than_the_draft_are_blocked(charts):
    chart, deep_enough = charts
    [(_, land)] = _polygons('LNDARE')
    land = _ned(chart, land)
    depths = [(p['DRVAL1'], _ned(chart, g)) for p, g in _polygons('DEPARE')]
    assert sorted(d for d, _ in depths) == [-5.0, 0.0, 2.0, 5.0]
    for drval1, area in depths:
        point = _inside(area.difference(land))
        assert _water_at(chart, point)                 # without a draft depth is not read
        assert _water_at(deep_enough, point) == (drval1 >= 3.0)
