"""The terminal's progress lines and closing summary (ship_mission.console; issue 27 item 5).

Metrics come from ship_mission.metrics.vessel_metrics on synthetic straight-line runs (the same
function the launcher's analysis uses), so the lines are checked against what a run gives:
- no nan, inf or None in any line; "n/a" until a value is defined, with the reason (a run
  shorter than its settling window, a route not completed);
- *_rad metrics shown as *_deg, equal to the radians converted; the metrics dict unchanged;
- a Gaussian reward far from the path (20 sigma: exp(-200) per step) shows as 0.0 with a note,
  a reward close to the path to 0.1.
"""
import copy
import math
import re

import numpy as np
import pytest

from ship_mission.console import NA, metric_text, progress_line, summary_line
from ship_mission.metrics import vessel_metrics

UNDEFINED_WORDS = re.compile(r'\b(nan|inf|infinity|none)\b', re.IGNORECASE)
ROUTE = ([0.0, 2000.0], [0.0, 0.0])     # a straight route east (ENU), done at 260 s
SPEED = 7.7                              # m/s


def straight_run(duration_s, offset_m, rudder_rad, settle_s, dt=0.1):
    """Metrics of a vessel going east along the route at ``offset_m`` to its left (north),
    with a constant rudder angle."""
    t = np.arange(0.0, duration_s + dt / 2, dt)
    x, y, yaw = SPEED * t, np.full_like(t, offset_m), np.zeros_like(t)
    rudder = (t, np.full_like(t, rudder_rad))
    return vessel_metrics(t, x, y, yaw, rudder=rudder, rudder_cmd=rudder, route=ROUTE,
                          settle_s=settle_s, rudder_limit_rad=math.radians(35.0))


def assert_readable(line):
    assert not UNDEFINED_WORDS.search(line), line


@pytest.mark.parametrize('xte, rtf, eta', [(math.nan, 0.0, math.inf), (None, 0.0, None),
                                            (math.nan, math.nan, math.nan)])
def test_progress_before_anything_is_known_says_n_a(xte, rtf, eta):
    line = progress_line(0.0, 1250.0, {'vessel_0': xte, 'vessel_1': 3.0}, rtf, eta)
    assert_readable(line)
    assert line.count(NA) == 3              # vessel_0's xte, the pace, the time left
    assert 'vessel_1 xte     +3.0 m' in line


def test_progress_once_running_shows_the_numbers():
    line = progress_line(69.4, 1250.0, {'vessel_0': 92.7}, 8.1, 145.8)
    assert_readable(line)
    assert NA not in line
    assert '+92.7 m' in line and 'x  8.1 real time' in line and 'at most  146 s left' in line
    assert 't =    69.4 / 1250 s' in line


def test_a_run_shorter_than_the_settling_window_reads_n_a_with_the_reason():
    m = straight_run(30.0, 200.0, 0.05, settle_s=200.0)
    before = copy.deepcopy(m)
    # what ship_mission.metrics gives such a run: no windowed statistics, a vanishing reward
    assert m['xte_rms_m'] is None and m['rudder_mean_abs_rad'] is None
    assert 0.0 < m['reward_gaussian_integral_s'] < 1e-80     # 30 s of exp(-200)
    line = summary_line('/vessel_0', m)
    assert_readable(line)
    assert m == before                       # the data (metrics.json) keeps its keys and radians
    assert 'xte_rms_m = n/a' in line and 'rudder_mean_abs_deg = n/a' in line
    assert 'time_to_complete_s = n/a' in line
    assert 'shorter than the settling window (200 s)' in line and 'route not completed' in line
    assert 'reward_gaussian_integral_s = 0.0,' in line and 'shows as 0.0' in line
    assert '_rad' not in line


def test_a_long_run_shows_degrees_and_the_reward_to_its_resolution():
    rudder = 0.1
    m = straight_run(400.0, 5.0, rudder, settle_s=100.0)
    line = summary_line('/vessel_0', m)
    assert_readable(line)
    assert NA not in line and '_rad' not in line and 'shows as' not in line
    # degrees are the radians converted (about 5.73 deg for 0.1 rad), 4 significant digits
    deg = math.degrees(m['rudder_mean_abs_rad'])
    assert abs(deg - math.degrees(rudder)) < 1e-9
    assert f'rudder_mean_abs_deg = {deg:.4g}' in line
    # 5 m off with sigma 10 m: exp(-1/8) per step of 0.1 s, over the whole 400 s episode
    r = m['reward_gaussian_integral_s']
    assert r == pytest.approx(math.exp(-25.0 / 200.0) * 400.0, rel=1e-3)
    assert f'reward_gaussian_integral_s = {r:.1f}' in line
    assert f'xte_rms_m = {m["xte_rms_m"]:.4g}' in line and m['xte_rms_m'] == pytest.approx(5.0)
    assert f'time_to_complete_s = {m["time_to_complete_s"]:.4g}' in line


@pytest.mark.parametrize('key, value, shown', [
    ('rudder_total_variation_rad_per_s', math.pi / 180, ('rudder_total_variation_deg_per_s', '1')),
    ('heading_error_max_abs_rad', None, ('heading_error_max_abs_deg', NA)),
    ('xte_rms_m', math.nan, ('xte_rms_m', NA)),
    ('xte_rms_m', math.inf, ('xte_rms_m', NA)),
    ('reward_steps', 11501, ('reward_steps', '11501')),
])
def test_metric_text(key, value, shown):
    assert metric_text(key, value) == shown
