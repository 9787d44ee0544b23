"""scripts/plan_route.py end to end on an image chart: route file + PNG, and the error exit."""
import numpy as np

import plan_route as cli
from ship_planner.route_yaml import load_route_yaml


def write_island_png(path):
    import imageio.v3 as iio

    img = np.full((80, 120), 255, dtype=np.uint8)           # 25 m pixels: 2 km x 3 km
    yy, xx = np.mgrid[0:80, 0:120]
    img[(yy - 40) ** 2 + (xx - 60) ** 2 < 15 ** 2] = 0        # an island of radius 375 m in the middle
    iio.imwrite(path, img)


def test_cli_plans_on_an_image_chart_and_writes_a_route_file_and_a_picture(tmp_path, capsys):
    png = tmp_path / 'island.png'
    write_island_png(png)
    out = tmp_path / 'route.yaml'
    rc = cli.main(['--chart', str(png), '--resolution', '25', '--start', '1000', '200', '--goal', '1000', '2800',
                   '--clearance', '100', '--fillet-radius', '300', '--generations', '80', '--candidates', '1',
                   '--out', str(out), '--quiet'])
    assert rc == 0
    plan = load_route_yaml(out)
    assert plan.frame == 'enu'
    assert np.allclose(plan.waypoints_ned[0], [1000.0, 200.0]) and np.allclose(plan.waypoints_ned[-1], [1000.0, 2800.0])
    assert plan.route.length > 2600.0                       # it goes round the island
    assert (tmp_path / 'route.png').stat().st_size > 10_000
    printed = capsys.readouterr().out
    assert 'length_ratio:' in printed and 'planning_time_s:' in printed


def test_cli_error_exits_2_with_one_line_that_says_what_to_change(tmp_path, capsys):
    png = tmp_path / 'island.png'
    write_island_png(png)
    rc = cli.main(['--chart', str(png), '--resolution', '25', '--start', '1000', '1500', '--goal', '1000', '2800',
                   '--quiet'])
    assert rc == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith('error: start') and 'is on land: move it into open water' in err[0]
