"""What the run's plots and tables tell a mariner: compass headings, the drift over ground, the
settling window the metrics leave out, the route's waypoints, a unit and description for every
metric metrics.json writes (ship_mission.plots, ship_mission.metrics.over_ground, ship_mission.metric_info,
ship_sim.frames.yaw_to_compass_deg)."""
import math
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest
import yaml

from ship_mission import metric_info, metrics, plots, report
from ship_mission.bag import Series
from ship_sim.frames import yaw_to_compass_deg

REPO = Path(__file__).resolve().parents[2]


@pytest.mark.parametrize('yaw, compass', [(math.pi / 2, 0.0), (0.0, 90.0), (-math.pi / 2, 180.0),
                                          (math.pi, 270.0), (-math.pi, 270.0)])
def test_enu_yaw_to_compass_at_the_cardinal_points(yaw, compass):
    assert yaw_to_compass_deg(yaw) == pytest.approx(compass, abs=1e-12)


def test_compass_stays_in_0_360_and_turns_clockwise():
    yaw = math.pi / 2 - np.linspace(0.0, 2 * math.pi - 1e-9, 1001)   # from north, turning to starboard
    c = yaw_to_compass_deg(yaw)
    assert np.all((c >= 0.0) & (c < 360.0))
    assert np.all(np.diff(c) > 0)              # clockwise = increasing compass
    # a hair west of north: 360 - 1e-14 rounds to 360.0 in floating point; it reads 000
    assert yaw_to_compass_deg(np.nextafter(math.pi / 2, 4.0)) == 0.0


@pytest.mark.parametrize('set_east', [1.0, -1.0])
def test_drift_is_the_crab_angle_a_beam_current_gives(set_east):
    """Heading north at 5 m/s through the water with a 1 m/s current setting east (or west):
    the ground track runs atan(1/5) to starboard (port) of the heading, at sqrt(26) m/s."""
    t = np.arange(0.0, 60.0, 0.1)
    x, y, yaw = set_east * t, 5.0 * t, np.full(t.size, math.pi / 2)
    sog, cog, drift = metrics.over_ground(t, x, y, yaw)
    assert sog == pytest.approx(np.full(t.size, math.sqrt(26.0)))
    expected = math.degrees(math.atan2(1.0, 5.0)) * set_east
    assert yaw_to_compass_deg(cog) == pytest.approx(np.full(t.size, expected % 360.0))
    assert np.degrees(drift) == pytest.approx(np.full(t.size, expected))


def test_course_and_drift_are_undefined_when_the_ship_stops():
    t = np.arange(0.0, 10.0, 0.1)
    sog, cog, drift = metrics.over_ground(t, np.zeros(t.size), np.zeros(t.size), np.zeros(t.size))
    assert np.all(sog == 0.0) and np.all(np.isnan(cog)) and np.all(np.isnan(drift))


def _vessel(t0, n, rudder_deg=40.0):
    t = t0 + 0.1 * np.arange(n)
    rudder = Series(t, np.full(n, math.radians(rudder_deg)))
    return SimpleNamespace(t=t, x=np.zeros(n), y=5.0 * (t - t0), yaw=np.full(n, math.pi / 2),
                           route=None, rudder=rudder, rudder_cmd=rudder, heading_cmd=Series(t, np.full(n, 1.0)),
                           cross_track_error=Series(t, np.zeros(n)))


def _settle_spans(fig):
    """[(start, width)] of the shaded settling span on each axes of ``fig`` (None: no span)."""
    out = []
    for ax in fig.axes:
        spans = [p for p in ax.patches if p.get_gid() == plots.SETTLE_GID]
        assert len(spans) <= 1
        out.append((spans[0].get_x(), spans[0].get_width()) if spans else None)
    return out


def test_rudder_and_heading_plots_shade_the_window_the_metrics_exclude(tmp_path, monkeypatch):
    """Two vessels starting at different times, settle_s from the metrics' default (a fraction of
    each one's own record): each panel shades exactly that vessel's window."""
    vessels = {'/a': _vessel(3.0, 500), '/b': _vessel(10.0, 1200)}
    m = {ns: metrics.vessel_metrics(v.t, v.x, v.y, v.yaw, rudder=(v.rudder.t, v.rudder.v),
                                    rudder_limit_rad=math.radians(40.0)) for ns, v in vessels.items()}
    figs = {}
    monkeypatch.setattr(plots, 'save_figure', lambda fig, path: figs.setdefault(path.name, fig))
    plots.make_plots(vessels, tmp_path, math.radians(40.0), {ns: r['settle_s'] for ns, r in m.items()})
    t0 = 3.0
    want = [(v.t[0] - t0, m[ns]['settle_s']) for ns, v in vessels.items()]
    for name in ('rudder.png', 'heading.png'):
        panels = [s for s in _settle_spans(figs[name]) if s is not None]
        assert [(pytest.approx(a), pytest.approx(w)) for a, w in want] == panels, name
    # the rudder sits at the limit throughout: the metrics count only the samples after the span
    for ns, v in vessels.items():
        after = np.count_nonzero(v.t >= v.t[0] + m[ns]['settle_s'])
        assert m[ns]['rudder_saturated_samples'] == after < v.t.size


def test_route_waypoints_are_the_route_files_own_points(tmp_path):
    route_file = REPO / 'scenarios' / 'routes' / 'flagship_mariner.yaml'
    (tmp_path / 'params').mkdir()
    (tmp_path / 'params' / 'vessel_0.route_node.yaml').write_text(
        yaml.safe_dump({'/**': {'ros__parameters': {'route_file': str(route_file)}}}))
    x, y = report.route_waypoints(tmp_path, '/vessel_0')
    written = yaml.safe_load(route_file.read_text())['waypoints']
    assert np.column_stack([x, y]) == pytest.approx(np.array([(w['x_m'], w['y_m']) for w in written]))
    assert report.route_waypoints(tmp_path, '/vessel_1') is None   # no params: no waypoints


def test_track_plot_marks_and_numbers_the_waypoints(tmp_path, monkeypatch):
    figs = {}
    monkeypatch.setattr(plots, 'save_figure', lambda fig, path: figs.setdefault(path.name, fig))
    wp = (np.array([0.0, 0.0, 1800.0]), np.array([0.0, 2000.0, 3500.0]))
    plots.plot_track({'/a': _vessel(0.0, 100)}, tmp_path / 'track.png', waypoints={'/a': wp})
    ax = figs['track.png'].axes[0]
    marks = [ln for ln in ax.lines if ln.get_label() == 'waypoint']
    assert len(marks) == 1
    assert np.array_equal(marks[0].get_xdata(), wp[0]) and np.array_equal(marks[0].get_ydata(), wp[1])
    labels = {t.get_text(): t.xy for t in ax.texts}
    assert labels == {'WP1': (0.0, 0.0), 'WP2': (0.0, 2000.0), 'WP3': (1800.0, 3500.0)}


def _every_input(n=400):
    t = 0.1 * np.arange(n)
    x, y, yaw = 5.0 * t, 3.0 * np.sin(t / 5.0), np.full(n, 0.0)
    s = (t, np.sin(t))
    return metrics.vessel_metrics(t, x, y, yaw, xte=s, rudder=s, rudder_cmd=s, heading_cmd=s,
                                  route=([0.0, 1000.0, 2000.0], [0.0, 0.0, 0.0]), rudder_limit_rad=0.5,
                                  finished=(t, (t > 30.0).astype(float)), remaining=(t, 2000.0 - 5.0 * t))


def test_every_metric_a_vessel_gets_has_a_unit_and_a_description():
    keys = set(_every_input()) | {'missing_topics', 'computed_over_gaps', 'completion_cut'}
    assert keys - set(metric_info.VESSEL) == set()
    for key, (unit, text) in metric_info.VESSEL.items():
        assert text and unit in ('', 'm', 's', 'rad', 'rad/s', 'm/s'), key
        suffix = {'rad': '_rad', 'rad/s': '_rad_per_s', 'm': '_m', 's': '_s', 'm/s': '_mps'}.get(unit)
        assert suffix is None or key.endswith(suffix), f'{key}: unit {unit} but not its suffix'


def test_every_traffic_and_platoon_metric_has_a_unit_and_a_description():
    t = np.arange(0.0, 100.0, 1.0)
    track = metrics.track_metrics(t, t, t)
    assert set(track) | {'source', 'closest_approach'} <= set(metric_info.TRAFFIC)
    vm = {'/a': {'xte_max_abs_m': 2.0, 'xte_rms_m': 1.0, 'time_to_complete_s': 50.0,
                 'completion_source': 'route', 'start_time_s': 0.0},
          '/b': {'xte_max_abs_m': 3.0, 'xte_rms_m': 1.5}}
    rows = report.platoon_metrics(vm, {'/b': Series(t, np.sin(t))}, {'/a': None, '/b': '/a'})
    assert set().union(*rows.values()) <= set(metric_info.PLATOON)


def test_angles_are_shown_in_degrees_and_other_units_unchanged():
    assert metric_info.shown(math.pi, 'rad') == (pytest.approx(180.0), 'deg')
    assert metric_info.shown(0.1, 'rad/s') == (pytest.approx(math.degrees(0.1)), 'deg/s')
    assert metric_info.shown(12.5, 'm') == (12.5, 'm')
    assert metric_info.shown(None, 'rad') == (None, 'deg')
    assert metric_info.plain_name('rudder_total_variation_rad_per_s', 'rad/s') == 'rudder_total_variation'
