"""ship_mission.integrity: missing steps are counted from the stamps, wherever they are."""
import numpy as np
from types import SimpleNamespace

from ship_mission.bag import Series
from ship_mission.integrity import record_integrity, stamp_gaps, summary_line

DT = 0.1


def test_contiguous_stamps_have_nothing_missing():
    t = np.arange(1000) * DT
    g = stamp_gaps(t)
    assert (g['expected'], g['received'], g['missing'], g['gaps']) == (1000, 1000, 0, [])
    assert abs(g['period_s'] - DT) < 1e-12


def test_holes_are_counted_and_located():
    k = np.arange(1000)
    keep = (k < 300) | (k >= 400)  # 100 steps lost in one burst (a keep-last-100 overwrite)
    keep[700] = False              # and one more
    g = stamp_gaps(k[keep] * DT)
    assert g['expected'] == 1000 and g['missing'] == 101
    assert np.allclose(g['gaps'], [[30.0, 39.9], [70.0, 70.0]])


def vessel(n_odom_steps, drop=(), answers=None):
    k = np.setdiff1d(np.arange(n_odom_steps), drop)
    t = k * DT
    n = n_odom_steps if answers is None else answers
    s = Series(np.arange(n) * DT, np.zeros(n))
    return SimpleNamespace(t=t, rudder=s, rudder_cmd=s, heading_cmd=s, cross_track_error=s,
                           progress=Series.empty())


def test_record_integrity_over_vessels_and_clock():
    data = SimpleNamespace(vessels={'/v0': vessel(500)}, clock=np.arange(500) * DT)
    r = record_integrity(data)
    assert r['complete'] and r['missing'] == 0
    assert 'complete' in summary_line(r)
    # the last step's answers may still be in flight at the stop: not a loss
    r = record_integrity(SimpleNamespace(vessels={'/v0': vessel(500, answers=499)}, clock=None))
    assert r['complete'] and r['vessels']['/v0']['rudder_cmd']['in_flight'] == 1
    # lost odom, /clock and answers are all counted
    clock = np.delete(np.arange(500) * DT, [10, 11, 12])
    r = record_integrity(SimpleNamespace(vessels={'/v0': vessel(500, drop=[50, 51], answers=480)},
                                         clock=clock))
    assert not r['complete']
    assert r['clock']['missing'] == 3 and r['vessels']['/v0']['odom']['missing'] == 2
    assert r['vessels']['/v0']['rudder_cmd']['missing'] == 20
    assert 'progress' not in r['vessels']['/v0']  # not published: not a loss
    assert r['missing'] == 3 + 2 + 4 * 20
    assert 'INCOMPLETE' in summary_line(r) and '/v0/odom 2' in summary_line(r)
