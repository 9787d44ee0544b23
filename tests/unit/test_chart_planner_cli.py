"""scripts/plan_route.py end to end on an image chart: route file + PNG, and the error exit."""
import json
import math

import numpy as np

import plan_route as cli
from ship_planner.yaml_route_reader import load_route_yaml


RES = 25.0  # m per pixel of the test chart


def island_image(upsample=1):
    """The test chart: 25 m pixels, 2 km x 3 km, an island of radius 375 m in the middle;
    ``upsample`` splits every pixel into upsample x upsample pixels (the same land, finer)."""
    img = np.full((80, 120), 255, dtype=np.uint8)
    yy, xx = np.mgrid[0:80, 0:120]
    img[(yy - 40) ** 2 + (xx - 60) ** 2 < 15 ** 2] = 0
    return np.kron(img, np.ones((upsample, upsample), dtype=np.uint8))


def write_island_png(path, upsample=1):
    import imageio.v3 as iio

    iio.imwrite(path, island_image(upsample))


def route_samples(route, step=2.0):
    """(n, 2) NED points along every leg of a path.Route, at most ``step`` m apart."""
    out = []
    for leg in route.legs:
        t = np.linspace(0.0, leg.length, max(2, int(math.ceil(leg.length / step)) + 1))
        n, e, _ = leg.point_at(t)
        out.append(np.column_stack([n, e]))
    return np.vstack(out)


def distance_to_land_squares(points):
    """Exact distance (m) from NED points to the land of the test chart: the union of its dark
    pixels' squares (image_chart: north up, lower-left pixel centre at (RES/2, RES/2))."""
    img = island_image()
    yy, xx = np.nonzero(img < 128)
    centres = np.column_stack([(img.shape[0] - 1 - yy + 0.5) * RES, (xx + 0.5) * RES])
    gap = np.maximum(np.abs(points[:, None, :] - centres[None]) - 0.5 * RES, 0.0)
    return np.hypot(gap[..., 0], gap[..., 1]).min(axis=1)


def test_cli_plans_on_an_image_chart_and_writes_a_route_file_and_a_picture(tmp_path, capsys):
    png = tmp_path / 'island.png'
    write_island_png(png)
    out = tmp_path / 'route.yaml'
    rc = cli.main(['--chart', str(png), '--resolution', '25', '--start', '1000', '200', '--goal', '1000', '2800',
                   '--clearance', '100', '--fillet-radius', '300', '--generations', '80', '--candidates', '1',
                   '--out', str(out), '--results', str(tmp_path / 'plan.json'), '--quiet'])
    assert rc == 0
    plan = load_route_yaml(out)
    assert plan.frame == 'enu'
    assert np.allclose(plan.waypoints_ned[0], [1000.0, 200.0]) and np.allclose(plan.waypoints_ned[-1], [1000.0, 2800.0])
    assert plan.route.length > 2600.0                       # it goes round the island
    # The route (fillets included) keeps the clearance: exactly, from the land pixels' squares,
    # and on a 5x finer raster of the same land, as the library tests check it (nearest fine
    # cell's distance to land, less the fine cell's diagonal).
    from ship_planner.chart import image_chart

    pts = route_samples(plan.route, step=2.0)
    assert distance_to_land_squares(pts).min() >= 100.0
    fine_png = tmp_path / 'island_fine.png'
    write_island_png(fine_png, upsample=5)
    fine = image_chart(fine_png, RES / 5)
    i, j, inside = fine.cell_index(pts)
    assert inside.all(), 'the route leaves the chart'
    assert fine.water[i, j].all()
    assert fine.distance_to_land()[i, j].min() >= 100.0 - math.sqrt(2.0) * fine.resolution_m
    assert (tmp_path / 'route.png').stat().st_size > 10_000
    printed = capsys.readouterr().out
    assert 'length_ratio:' in printed and 'planning_time_s:' in printed
    # the results file holds what the run printed, with the command and the clearance
    record = json.loads((tmp_path / 'plan.json').read_text())
    assert '--clearance 100' in record['provenance']['command'] and record['clearance_m'] == 100.0
    for key in ('route_length_m', 'shortest_path_length_m', 'length_ratio', 'waypoints'):
        assert f'{key}: {record[key]}\n' in printed


def test_cli_error_exits_2_with_one_line_that_says_what_to_change(tmp_path, capsys):
    png = tmp_path / 'island.png'
    write_island_png(png)
    rc = cli.main(['--chart', str(png), '--resolution', '25', '--start', '1000', '1500', '--goal', '1000', '2800',
                   '--quiet'])
    assert rc == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith('error: start') and 'is on land: move it into open water' in err[0]
