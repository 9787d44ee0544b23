"""AIS multi-target tracker (ship_guidance.tracker) against ground truth.

Reports come from the AIS sensor model (ship_guidance.ais_sensor: its intervals, losses and
noise) of known trajectories: a straight line, and a straight line followed by a steady turn
at 30 deg/min. Checked: NEES consistency (Monte Carlo, chi-square interval), RMS errors against
the raw reports' own errors, continuity through a 180 s gap with a grown covariance, deletion
after the documented silence, late reports retrodicted exactly or dropped, prediction."""
import math

import numpy as np
import pytest
from scipy import stats

from ship_guidance.ais import KNOT
from ship_guidance.ais_sensor import AisSensor, SensorConfig, Truth
from ship_guidance.tracker import (EXPIRY_INTERVALS, AisReport, Tracker, TrackerConfig,
                                   expiry_s)
from ship_guidance.ais import STALE_AFTER_S

ORIGIN = (63.44, 10.40)
MMSI = 257000001
U = 10.0 * KNOT                        # m/s: class A, 0-14 kn
CHI0 = 0.5                             # rad, initial course
RATE = math.radians(30.0) / 60.0       # rad/s: 30 deg/min, a "changing course" rate
T_TURN = 200.0                         # s, start of the turn
RUNS = 50
SENSOR = SensorConfig()


def straight(t):
    return Truth(t, U * t * math.cos(CHI0), U * t * math.sin(CHI0), CHI0, U, CHI0)


def turning(t):
    """Straight until T_TURN, then a steady turn to starboard (radius U / RATE)."""
    if t < T_TURN:
        return straight(t)
    chi, radius = CHI0 + RATE * (t - T_TURN), U / RATE
    p = straight(T_TURN)
    return Truth(t, p.north + radius * (math.sin(chi) - math.sin(CHI0)),
                 p.east - radius * (math.cos(chi) - math.cos(CHI0)), chi, U, chi, RATE)


def state(truth):
    return np.array([truth.north, truth.east, truth.sog * math.cos(truth.cog),
                     truth.sog * math.sin(truth.cog)])


def simulate(seed, trajectory, t_end, skip=None, config=SENSOR):
    """[(truth, report)] of one vessel stepped every second to t_end; reports sent within
    ``skip`` (t0, t1) are left out (a gap in reception)."""
    sensor = AisSensor(*ORIGIN, SensorConfig(**{**config.__dict__, 'seed': seed}))
    sensor.add(MMSI, 'A')
    out = []
    for k in range(int(t_end) + 1):
        truth = trajectory(float(k))
        for r in sensor.step(MMSI, truth):
            if skip is None or not skip[0] <= r.t_sent < skip[1]:
                out.append((trajectory(r.t_sent), AisReport.from_sensor(r)))
    return out


def nees(estimate, truth):
    e = estimate.x - state(truth)
    return float(e @ np.linalg.solve(estimate.P, e))


def run_nees(trajectory, config, t_check, at_report):
    """Sum over RUNS runs of the NEES at ``t_check`` (predicted to it) or, ``at_report``, at
    the first report at or after it (just updated)."""
    total = 0.0
    for seed in range(RUNS):
        tracker = Tracker(config)
        for truth, report in simulate(seed, trajectory, t_check + 30.0):
            if not at_report and report.t > t_check:
                break
            tracker.update(report)
            if at_report and report.t >= t_check:
                break
        t = report.t if at_report else t_check
        total += nees(tracker.estimate(MMSI, t), trajectory(t))
    return total


CHI2_LO, CHI2_HI = stats.chi2.ppf([0.025, 0.975], 4 * RUNS)


def test_nees_consistent_when_the_model_is_exact():
    """A straight line at constant speed is the model with q = 0: the sum of NEES over RUNS
    independent runs, at a fixed time between reports (a prediction), is chi-square with
    4 RUNS degrees of freedom; it must lie in that distribution's 95 % interval."""
    total = run_nees(straight, TrackerConfig(process_noise=0.0), 450.5, at_report=False)
    assert CHI2_LO <= total <= CHI2_HI, (total / RUNS, CHI2_LO / RUNS, CHI2_HI / RUNS)


def test_nees_consistent_in_a_turn_with_the_default_process_noise():
    """In the 30 deg/min turn (acceleration U x rate, which the default q is sized for), the
    NEES of the estimates just updated at the first report after 450 s (250 s into the turn),
    summed over RUNS runs, lies in the chi-square 95 % interval of 4 RUNS degrees of freedom."""
    total = run_nees(turning, TrackerConfig(), 450.0, at_report=True)
    assert CHI2_LO <= total <= CHI2_HI, (total / RUNS, CHI2_LO / RUNS, CHI2_HI / RUNS)


@pytest.mark.parametrize('at_report', [True, False])
def test_default_process_noise_not_overconfident_on_a_straight_line(at_report):
    """On a straight line the default q is more than the truth needs: the filter may be
    conservative there (NEES low) but never overconfident (above the interval)."""
    assert run_nees(straight, TrackerConfig(), 450.5, at_report) <= CHI2_HI


@pytest.mark.parametrize('trajectory', [straight, turning], ids=['straight', 'turning'])
def test_rms_errors_below_the_raw_reports(trajectory):
    """After the first minute, the tracks' RMS position and velocity errors at the reports
    are below those of the reports themselves: sqrt(2) sigma_p per position, and for the
    velocity from SOG and COG sqrt(sigma_sog^2 + (U sigma_cog)^2) (SensorConfig's sigmas)."""
    pos, vel = [], []
    for seed in range(20):
        tracker = Tracker()
        for truth, report in simulate(seed, trajectory, 600.0):
            tracker.update(report)
            if report.t > 60.0:
                e = tracker.estimate(MMSI, report.t).x - state(truth)
                pos.append(e[:2] @ e[:2])
                vel.append(e[2:] @ e[2:])
    raw_pos = math.sqrt(2.0) * SENSOR.position_sigma_m
    raw_vel = math.hypot(SENSOR.sog_sigma_kn * KNOT, U * math.radians(SENSOR.cog_sigma_deg))
    assert math.sqrt(np.mean(pos)) < raw_pos
    assert math.sqrt(np.mean(vel)) < raw_vel


def test_track_continues_through_a_180_s_gap_with_grown_covariance():
    """No report for 180 s (class A under way, every 10 s): the same track (not deleted, not
    opened again: its report count goes on), its position covariance grown over the gap,
    and the truth at the gap's end inside the predicted 99.9 % ellipse in every run."""
    gap = (300.0, 480.0)
    limit = stats.chi2.ppf(0.999, 2)
    for seed in range(20):
        tracker = Tracker()
        results = []
        before = at_end = None
        for truth, report in simulate(seed, straight, 600.0, skip=gap):
            if report.t >= gap[1] and at_end is None:
                at_end = tracker.estimate(MMSI, gap[1])
                before_gap = tracker.estimate(MMSI, before.t)
                e = at_end.x[:2] - state(straight(gap[1]))[:2]
                assert e @ np.linalg.solve(at_end.P[:2, :2], e) < limit
            results.append(tracker.update(report))
            if report.t < gap[0]:
                before = report
        assert results[0] == 'new' and set(results[1:]) == {'updated'}
        assert np.linalg.eigvalsh(at_end.P[:2, :2]).min() > \
            np.linalg.eigvalsh(before_gap.P[:2, :2]).max()
        assert at_end.n_reports == before_gap.n_reports
        assert tracker.estimate(MMSI, 600.0).n_reports == len(results)


@pytest.mark.parametrize('klass,sog_kn,moored', [('A', 10.0, False), ('A', 0.5, True),
                                                 ('B', 1.0, False), ('B', 8.0, False)])
def test_deleted_after_the_documented_silence(klass, sog_kn, moored):
    """A track lives exactly max(ais.STALE_AFTER_S, EXPIRY_INTERVALS x its report interval)
    after its last report: 360 s under way, 540 s for a 3-min reporter."""
    from ship_guidance.ais_sensor import report_interval
    expected = max(STALE_AFTER_S, EXPIRY_INTERVALS * report_interval(klass, sog_kn, moored=moored))
    report = AisReport(MMSI, 100.0, 0.0, 0.0, sog_kn * KNOT, 0.0, klass=klass, moored=moored)
    assert expiry_s(report) == expected
    assert expected == (540.0 if report_interval(klass, sog_kn, moored=moored) == 180.0 else 360.0)
    tracker = Tracker()
    tracker.update(report)
    assert [tr.mmsi for tr in tracker.tracks(100.0 + expected)] == [MMSI]
    assert tracker.tracks(100.0 + expected + 0.1) == [] and tracker.deleted == 1
    assert tracker.update(report) == 'new'        # heard again: a new track


def test_late_report_gives_the_time_ordered_estimate():
    """Reports delivered out of order (each pair swapped: a 10 s latency on every other) give
    the same estimate as in time order; one older than the reprocessing window is dropped and
    changes nothing; a repeated report is a duplicate."""
    reports = [r for _, r in simulate(3, turning, 400.0)]
    in_order, shuffled = Tracker(), Tracker()
    for r in reports:
        in_order.update(r)
    swapped = list(reports)
    for i in range(1, len(swapped) - 1, 2):
        swapped[i], swapped[i + 1] = swapped[i + 1], swapped[i]
    results = [shuffled.update(r) for r in swapped]
    assert results.count('late') == (len(reports) - 2) // 2 and shuffled.reprocessed > 0
    a, b = in_order.estimate(MMSI, 400.0), shuffled.estimate(MMSI, 400.0)
    np.testing.assert_allclose(b.x, a.x, rtol=0, atol=1e-9)
    np.testing.assert_allclose(b.P, a.P, rtol=0, atol=1e-9)
    window = TrackerConfig().reprocess_window_s
    stale = AisReport(MMSI, reports[-1].t - window - 30.0, 1e4, 1e4, 1.0, 0.0)
    assert shuffled.update(stale) == 'late_dropped' and shuffled.late_dropped == 1
    np.testing.assert_array_equal(shuffled.estimate(MMSI, 400.0).x, b.x)
    assert shuffled.update(reports[-1]) == 'duplicate' and shuffled.duplicates == 1


def test_prediction_covariance_grows_and_position_moves_with_the_velocity():
    tracker = Tracker()
    tracker.update(AisReport(MMSI, 0.0, 100.0, 200.0, 5.0, math.pi / 2))
    p0 = tracker.estimate(MMSI, 0.0)
    traces = [np.trace(tracker.estimate(MMSI, t).P) for t in (0.0, 10.0, 60.0, 300.0)]
    assert all(b > a for a, b in zip(traces, traces[1:]))
    p = tracker.estimate(MMSI, 60.0)
    np.testing.assert_allclose(p.x, p0.x + [0.0, 5.0 * 60.0 * 1.0, 0.0, 0.0], atol=1e-9)
    assert p.position_sigma_m > p0.position_sigma_m
    assert tracker.estimate(MMSI, -5.0).t == 0.0           # never back in time


def test_initial_covariance_is_the_sensor_noise_and_velocity_less_reports():
    """The first report's covariance is R: sigma_p^2 on the position; along the course
    sigma_sog^2, across it (U sigma_cog)^2. A report without SOG/COG opens a track with the
    wide INITIAL_SPEED_SIGMA velocity and updates the position only."""
    c = TrackerConfig()
    tracker = Tracker()
    tracker.update(AisReport(MMSI, 0.0, 0.0, 0.0, 5.0, 0.0))          # north-going
    P = tracker.estimate(MMSI, 0.0).P
    np.testing.assert_allclose(np.diag(P), [c.position_sigma_m ** 2, c.position_sigma_m ** 2,
                                            c.sog_sigma_mps ** 2, (5.0 * c.cog_sigma_rad) ** 2])
    tracker.update(AisReport(MMSI + 1, 0.0, 0.0, 0.0))
    tracker.update(AisReport(MMSI + 1, 10.0, 30.0, 0.0))
    est = tracker.estimate(MMSI + 1, 10.0)
    assert 0.0 < est.x[2] < 3.0 and est.P[2, 2] < 15.0 ** 2     # velocity learnt from positions
    assert [t.mmsi for t in tracker.tracks(10.0)] == [MMSI, MMSI + 1]


def test_bad_config_and_report_refused():
    with pytest.raises(ValueError, match='process_noise'):
        TrackerConfig(process_noise=-1.0).check()
    with pytest.raises(ValueError, match='position_sigma_m'):
        Tracker(TrackerConfig(position_sigma_m=0.0))
    with pytest.raises(ValueError, match='non-finite'):
        Tracker().update(AisReport(MMSI, 0.0, math.nan, 0.0))


def test_odometry_covariances_are_enu_and_body_frame():
    """Pose: x is east, y north, so the NED position block is swapped; the largest axis is
    kept (colav_io.position_sigma reads what the tracker's estimate holds). Twist: for a ship
    heading east the forward velocity is v_east and FLU's left is north."""
    from ship_guidance.colav_io import position_sigma
    from ship_guidance.tracker import TrackEstimate, odometry_covariances
    P = np.diag([4.0, 25.0, 0.01, 0.09])
    P[0, 1] = P[1, 0] = 3.0
    est = TrackEstimate(MMSI, 0.0, np.array([0.0, 0.0, 0.0, 5.0]), P, 0.0, None, 'A', 1)
    pose, twist = odometry_covariances(est, math.pi / 2)
    assert (pose[0], pose[7], pose[1], pose[6]) == (25.0, 4.0, 3.0, 3.0)
    assert position_sigma(pose) == pytest.approx(est.position_sigma_m)
    assert twist[0] == pytest.approx(0.09) and twist[7] == pytest.approx(0.01)
    # no reported heading: the yaw variance is the COG's, cross-track variance / speed^2
    assert pose[35] == pytest.approx(0.01 / 25.0)


def test_radar_plot_goes_to_the_gated_nearest_track():
    """Two tracks 400 m apart (east-going at 5 m/s); a radar plot at t = 10 s with sigma 20 m:
    near one track's prediction it updates that track (position covariance shrinks) and not
    the other; its Mahalanobis distance decides the gate: a plot just inside the chi-square
    99 % gate (d^2 = 9.21 of 2 dof) is used, one just outside is returned unused."""
    from ship_guidance.tracker import predict
    c = TrackerConfig()
    tracker = Tracker()
    for mmsi, north in ((MMSI, 0.0), (MMSI + 1, 400.0)):
        tracker.update(AisReport(mmsi, 0.0, north, 0.0, 5.0, math.pi / 2))
    a0, b0 = tracker.estimate(MMSI, 10.0), tracker.estimate(MMSI + 1, 10.0)
    assert tracker.associate_radar(10.0, 30.0, 50.0, 20.0) == MMSI
    a1, b1 = tracker.estimate(MMSI, 10.0), tracker.estimate(MMSI + 1, 10.0)
    assert a1.position_sigma_m < a0.position_sigma_m
    np.testing.assert_array_equal(b1.P, b0.P)
    # The gate, along north from track b's prediction at t = 20 s: S = P_pos + R.
    _, x, P = tracker._tracks[MMSI + 1].newest
    x, P = predict(x, P, 20.0 - 0.0, c.process_noise)
    s_nn = P[0, 0] + 20.0 ** 2
    assert abs(P[0, 1]) < 1e-9 * P[0, 0]           # north and east independent
    edge = math.sqrt(c.radar_gate * s_nn)          # d^2 = gate at this offset
    assert edge < 200.0                            # the plot above b: far outside a's gate
    assert tracker.associate_radar(20.0, x[0] + 1.02 * edge, x[1], 20.0) is None
    assert tracker.associate_radar(20.0, x[0] + 0.98 * edge, x[1], 20.0) == MMSI + 1


def test_a_confirmed_track_keeps_the_plots_a_stray_tentative_track_beside_it_would_win():
    """A stray plot opens a tentative track 150 m from a confirmed radar track (20 plots of
    sigma 20 m, east-going at 5 m/s; the stray track's covariance is its one plot's, 75 m, and
    the unknown velocity's). The next plot, 100 m off the confirmed track towards the stray one,
    is inside both gates and nearer the stray track by Mahalanobis distance (its covariance is
    the larger): plain nearest neighbour gives it to the stray track, which then takes the
    target's plots until the confirmed track starves. With ``confirmed_reports`` it goes to the
    confirmed track; a plot outside every confirmed gate still goes to the tentative one."""
    from ship_guidance.tracker import predict
    c = TrackerConfig()
    confirm = 20

    def tracks():
        tr = Tracker()
        for k in range(confirm):
            tr.update(AisReport(MMSI, 2.5 * k, 0.0, 12.5 * k, position_sigma_m=20.0))
        t0 = 2.5 * confirm
        tr.update(AisReport(MMSI + 1, t0, 150.0, 12.5 * confirm, position_sigma_m=75.0))
        return tr, t0 + 2.5

    def d2(tr, mmsi, t, z, sigma):
        _, x, P = tr._tracks[mmsi].newest
        x, P = predict(x, P, t - tr._tracks[mmsi].newest[0].t, c.process_noise)
        y = np.asarray(z) - x[:2]
        return float(y @ np.linalg.solve(P[:2, :2] + sigma ** 2 * np.eye(2), y)), x

    tr, t = tracks()
    _, x = d2(tr, MMSI, t, (0.0, 0.0), 75.0)
    near = (x[0] + 100.0, x[1])
    d_conf, _ = d2(tr, MMSI, t, near, 75.0)
    d_tent, _ = d2(tr, MMSI + 1, t, near, 75.0)
    assert d_tent < d_conf < c.radar_gate        # the premise: in both gates, nearer the stray
    assert tr.associate_radar(t, *near, 75.0) == MMSI + 1
    tr, t = tracks()
    assert tr.associate_radar(t, *near, 75.0, confirmed_reports=confirm) == MMSI
    far = (x[0] + 300.0, x[1])
    tr, t = tracks()
    assert d2(tr, MMSI, t, far, 75.0)[0] > c.radar_gate > d2(tr, MMSI + 1, t, far, 75.0)[0]
    assert tr.associate_radar(t, *far, 75.0, confirmed_reports=confirm) == MMSI + 1
