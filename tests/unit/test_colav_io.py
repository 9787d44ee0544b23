"""colav_node's pure parts (ship_guidance.colav_io): odometry -> states, dead reckoning to a
stamp, the target table, the decision schedule and the command it publishes."""
import math

import numpy as np
import pytest

from ship_guidance import colav_io, colregs
from ship_guidance.colav import Decision, TargetAssessment
from ship_guidance.colav_methods import make_colav
from ship_sim.frames import enu_to_ned_xy, flu_to_frd_twist, psi_to_yaw, yaw_to_psi

S = colav_io.NS_PER_S


def test_course_over_ground_adds_the_drift_angle():
    # heading north, sway 1 m/s to starboard at 1 m/s surge: course 45 deg, speed sqrt(2)
    st = colav_io.ship_state(10.0, 20.0, 0.0, 1.0, 1.0)
    assert st.course == pytest.approx(math.pi / 4)
    assert st.speed == pytest.approx(math.sqrt(2))
    assert st.heading == 0.0 and (st.north, st.east) == (10.0, 20.0)


def test_enu_odometry_through_frames_gives_the_ned_target():
    # An ENU pose at x=100 (east), y=50 (north), yaw 0 (facing east), FLU twist 5 m/s forward,
    # 1 m/s to the left (port): NED heading 90 deg, course 90 - 11.3 deg.
    north, east = enu_to_ned_xy(100.0, 50.0)
    u, v, _ = flu_to_frd_twist(5.0, 1.0, 0.0)
    tg = colav_io.target_state('ais_1', north, east, float(yaw_to_psi(0.0)), u, v)
    assert (tg.north, tg.east) == (50.0, 100.0)
    assert tg.heading == pytest.approx(math.pi / 2)
    assert tg.course == pytest.approx(math.pi / 2 - math.atan2(1.0, 5.0))
    assert tg.name == 'ais_1'


def test_dead_reckoning_moves_along_the_course():
    tg = colav_io.target_state('t', 0.0, 0.0, math.radians(30.0), 4.0, 0.0)
    moved = colav_io.dead_reckon(tg, 10.0)
    assert moved.north == pytest.approx(40.0 * math.cos(math.radians(30.0)))
    assert moved.east == pytest.approx(40.0 * math.sin(math.radians(30.0)))
    assert (moved.course, moved.speed, moved.name) == (tg.course, tg.speed, 't')
    assert colav_io.dead_reckon(tg, 0.0) is tg


def test_tracks_use_the_latest_state_not_after_the_stamp_whatever_the_arrival_order():
    a = colav_io.TargetTracks(stale_after_s=30.0)
    b = colav_io.TargetTracks(stale_after_s=30.0)
    states = {k: colav_io.target_state('v1', 100.0 * k, 0.0, 0.0, 10.0, 0.0) for k in range(4)}
    for k in (0, 1, 2, 3):
        a.add('v1', k * S, states[k])
    for k in (3, 1, 0, 2):      # other order, one sample ahead of the query already there
        b.add('v1', k * S, states[k])
    for tracks in (a, b):
        (tg,) = tracks.at(S + S // 2)            # t = 1.5 s: sample 1 moved on 0.5 s
        assert tg.north == pytest.approx(100.0 + 5.0)
    assert a.at(S + S // 2) == b.at(S + S // 2)


def test_tracks_leave_out_future_only_and_stale_targets():
    tracks = colav_io.TargetTracks(stale_after_s=5.0)
    tracks.add('late', 10 * S, colav_io.target_state('late', 0, 0, 0, 1, 0))
    tracks.add('old', 0, colav_io.target_state('old', 0, 0, 0, 1, 0))
    tracks.add('ok', 4 * S, colav_io.target_state('ok', 0, 0, 0, 1, 0))
    assert [t.name for t in tracks.at(5 * S)] == ['ok', 'old']   # 'old' 5 s old: still in
    assert [t.name for t in tracks.at(5 * S + 1)] == ['ok']   # 'old' beyond 5 s: out


def test_stale_targets_are_forgotten_and_the_table_stays_small():
    """100,000 names heard once each, then silence: a decision past the staleness limit forgets
    them all (the table does not keep every name ever heard), a live one stays."""
    tracks = colav_io.TargetTracks(stale_after_s=30.0, max_targets=10**6)
    for i in range(100_000):
        tracks.add(f'ais_{i}', 0, colav_io.target_state(f'ais_{i}', i, 0, 0, 1, 0))
    tracks.add('live', 31 * S, colav_io.target_state('live', 0, 0, 0, 1, 0))
    assert len(tracks) == 100_001
    assert [t.name for t in tracks.at(31 * S)] == ['live']
    assert len(tracks) == 1 and tracks.names() == ['live'] and len(tracks.last_heard) == 1


def test_the_table_is_bounded_keeping_the_targets_nearest_the_own_ship():
    n = 60
    k = int(n * colav_io.EVICT_FRACTION)          # left out at once when full
    assert k >= 2
    tracks = colav_io.TargetTracks(stale_after_s=30.0, max_targets=n)
    tracks.reference = (1000.0, 0.0)
    tracks.add('/v1/odom', 0, colav_io.target_state('/v1/odom', 9e6, 0, 0, 1, 0), lockstep=True)
    # Targets at distances 1 .. 500 m from the own ship, nearest last: each newcomer is nearer
    # than every kept one, so the farthest are left out each time the table is full.
    for d in range(500, 0, -1):
        assert tracks.add(f'ais_{d}', 0, colav_io.target_state(f'ais_{d}', 1000.0 + d, 0, 0, 1,
                                                               0)) is None
        assert len(tracks) <= n
    kept = set(tracks.names())
    m = len(kept) - 1
    # The lockstep vessel is never left out, however far; the rest are the m nearest.
    assert n - k <= m <= n - 1
    assert kept == {'/v1/odom'} | {f'ais_{d}' for d in range(1, m + 1)}
    assert tracks.n_evicted == 500 - m
    # Full again, a newcomer farther than every kept (non-lockstep) target gets no place, and
    # the k - 1 farthest kept ones leave with it.
    for i in range(n - len(tracks)):
        tracks.add(f'near_{i}', 0, colav_io.target_state(f'near_{i}', 1000.0, 0, 0, 1, 0))
    assert len(tracks) == n
    assert tracks.add('far', 0, colav_io.target_state('far', 2000.0, 0, 0, 1, 0)) == 'evicted'
    assert 'far' not in tracks.names() and len(tracks) == n - (k - 1)
    assert '/v1/odom' in tracks.names() and f'ais_{m}' not in tracks.names()
    assert len(tracks.at(0)) == len(tracks)


def test_a_target_keeps_at_most_max_samples_the_oldest_going_first():
    tracks = colav_io.TargetTracks(stale_after_s=1e5)
    n = colav_io.MAX_SAMPLES_PER_TARGET
    for k in range(n + 500):                      # stamps 1 ns apart, all in the future of t=0
        tracks.add('x', 1000 + k, colav_io.target_state('x', float(k), 0, 0, 1, 0))
    assert len(tracks._stamps['x']) == n and tracks._stamps['x'][0] == 1000 + 500
    (tg,) = tracks.at(1000 + 600)                 # the newest state at or before the stamp
    assert tg.north == pytest.approx(600.0)


@pytest.mark.parametrize('north, east, speed, reason', [
    (math.nan, 0.0, 1.0, 'non_finite'),
    (0.0, math.inf, 1.0, 'non_finite'),
    (0.0, 0.0, math.nan, 'non_finite'),
    (1e300, 0.0, 1.0, 'out_of_range'),
    (0.0, -1.0001e7, 1.0, 'out_of_range'),
    (0.0, 0.0, 1e300, 'out_of_range'),
    (0.0, 0.0, 50.01, 'out_of_range'),
])
def test_states_no_ship_can_have_are_refused_and_counted(north, east, speed, reason):
    tracks = colav_io.TargetTracks(stale_after_s=30.0)
    state = colav_io.target_state('x', north, east, 0.0, speed, 0.0)
    assert tracks.add('x', 0, state) == reason
    assert tracks.refused[reason] == 1 and sum(tracks.refused.values()) == 1
    assert tracks.names() == [] and tracks.last_refused[0] == 'x'
    at_bounds = colav_io.target_state('ok', 1e7, -1e7, 0.0, 50.0, 0.0)
    assert tracks.add('ok', 0, at_bounds) is None and tracks.names() == ['ok']


def test_a_non_finite_heading_ref_is_refused_counted_and_the_last_good_held():
    hold = colav_io.RefHold()
    assert hold.update(math.nan) is None and hold.n_refused == 1     # nothing to hold yet
    assert hold.update(0.5) == 0.5
    for bad in (math.nan, math.inf, -math.inf):
        assert hold.update(bad) == 0.5
    assert hold.n_refused == 4
    assert hold.update(-1.0) == -1.0 and hold.update(math.nan) == -1.0 and hold.n_refused == 5


def test_lockstep_targets_are_waited_for_until_a_sample_at_or_after_the_stamp():
    tracks = colav_io.TargetTracks(30.0)
    assert tracks.waiting_for(0, expected=['/v1/odom']) == ['/v1/odom']   # never heard
    tracks.add('/v1/odom', 0, colav_io.target_state('/v1/odom', 0, 0, 0, 1, 0), lockstep=True)
    tracks.add('ais_9', 0, colav_io.target_state('ais_9', 0, 0, 0, 1, 0))
    assert tracks.waiting_for(0, expected=['/v1/odom']) == []
    assert tracks.waiting_for(S // 10) == ['/v1/odom']                     # AIS never waited for


def test_schedule_decides_every_period_on_integer_nanoseconds():
    sch = colav_io.DecisionSchedule(1.0)
    due = []
    for k in range(31):                  # 0.1 s steps as the stamps carry them
        t_ns = colav_io.to_ns(k * 0.1)
        if sch.due(t_ns):
            sch.decided(t_ns)
            due.append(k)
    assert due == [0, 10, 20, 30]


def _decision(offset, mode='avoid', mult=1.0):
    return Decision(0.0, mult, mode, offset, mult, mode != 'nominal', ())


def test_command_passes_the_nominal_float_through_unless_the_course_is_altered():
    ref = 0.123456789012345
    assert colav_io.command_yaw(ref, None) is ref
    assert colav_io.command_yaw(ref, _decision(0.0, 'nominal')) is ref
    assert colav_io.command_yaw(ref, _decision(0.0, 'avoid', 0.5)) is ref   # speed only
    # 30 deg to starboard: ENU yaw decreases by 30 deg
    assert colav_io.command_yaw(ref, _decision(math.radians(30.0))) == pytest.approx(
        ref - math.radians(30.0))
    # wrapped into [-pi, pi)
    yaw = colav_io.command_yaw(-3.0, _decision(math.radians(60.0)))
    assert -math.pi <= yaw < math.pi
    assert math.cos(yaw) == pytest.approx(math.cos(-3.0 - math.radians(60.0)))
    assert colav_io.speed_factor(1.0, _decision(0.0, 'avoid', 0.5)) == 0.5
    assert colav_io.speed_factor(1.0, None) == 1.0


def test_head_on_rows_and_the_starboard_command_from_enu_messages():
    """Two ships on reciprocal courses, as the node sees them (ENU odometry, heading_ref):
    the row says head-on / give-way at the range and TCPA of the geometry, and the command
    turns to starboard (ENU yaw decreases)."""
    U, R = 7.7, 4000.0
    own = colav_io.ship_state(*enu_to_ned_xy(0.0, 0.0), float(yaw_to_psi(0.0)), U, 0.0)  # east
    tgt = colav_io.target_state('/vessel_1/odom', *enu_to_ned_xy(R, 0.0),
                                float(yaw_to_psi(math.pi)), U, 0.0)                     # west
    col = make_colav('sbmpc')
    d = col.decide(0.0, own, [tgt], yaw_to_psi(0.0), 1.0)
    rows = colav_io.target_rows(own, [tgt], d)
    assert len(rows) == len(colav_io.TARGET_COLUMNS)
    tcpa, dcpa, sit, role, rng, beta = rows
    assert tcpa == pytest.approx(R / (2 * U)) and dcpa == pytest.approx(0.0, abs=1e-6)
    assert int(sit) == colregs.HEAD_ON and int(role) == colav_io.ROLE_CODES['give-way']
    assert rng == pytest.approx(R) and beta == pytest.approx(0.0, abs=1e-12)
    assert d.course_offset > 0.0
    assert colav_io.command_yaw(0.0, d) < 0.0
    assert psi_to_yaw(yaw_to_psi(0.0) + d.course_offset) == pytest.approx(
        colav_io.command_yaw(0.0, d))


def test_decision_row_codes():
    a = TargetAssessment('x', 1.0, 2.0, 'crossing-stand-on', 'stand-on', True, 3.0)
    d = Decision(0.0, 1.0, 'stand-on', 0.0, 1.0, True, (a,))
    own = colav_io.ship_state(0.0, 0.0, 0.0, 5.0, 0.0)
    tg = colav_io.target_state('x', 0.0, -1000.0, math.pi / 2, 5.0, 0.0)   # to port
    rows = colav_io.target_rows(own, [tg], d)
    assert rows[2] == colregs.CROSSING_STAND_ON and rows[3] == 2.0
    assert rows[5] == pytest.approx(1.5 * math.pi)
    assert colav_io.decision_row(3.0, d, 1) == [3.0, 1.0, 0.0, 1.0, 1.0, 1.0]
    assert np.isfinite(rows).all()


def test_colav_yaml_lists_exactly_the_node_parameters():
    """config/colav.yaml is the launcher's list of colav_node's parameters (scenario keys are
    checked against it): it must hold every parameter the node declares, with its default."""
    import yaml

    from ship_guidance import colav_node
    from ship_guidance.colav_params import ColavParams
    config = (colav_node.__file__.rsplit('/ship_guidance/', 1)[0]
              + '/config/colav.yaml')
    listed = yaml.safe_load(open(config).read())['/**']['ros__parameters']
    declared = {name: default for name, default, *_ in colav_node.SCALARS}
    declared.update({name: default for name, default, _ in colav_node.LISTS})
    declared.update(method='sbmpc', decision_period_s=1.0, pairing='sequence', targets_topic='targets',
                    target_stale_s=30.0, lockstep_target_timeout_s=10.0, has_shaft=True,
                    targets_sync_topic='', chart_topic='',
                    max_targets=colav_io.DEFAULT_MAX_TARGETS,
                    heading_cmd_readers=[''], speed_factor_cmd_readers=[''])
    assert set(listed) == set(declared)
    for key, value in listed.items():
        numeric = not isinstance(value, (str, bool, list))
        assert value == (pytest.approx(declared[key], rel=1e-4) if numeric else declared[key]), key
    assert set(declared) - {f for f in ColavParams.__dataclass_fields__} >= colav_io.NODE_KEYS


def test_markers_put_the_safe_circle_on_the_target_and_the_arrow_on_the_command_in_enu():
    from visualization_msgs.msg import Marker

    from ship_guidance.ros.colav_markers import colav_markers
    from ship_sim.ros.conversions import quaternion_to_yaw
    own = colav_io.ship_state(0.0, 0.0, math.pi / 2, 7.7, 0.0)                  # heading east
    tgt = colav_io.target_state('t', 0.0, 4000.0, -math.pi / 2, 7.7, 0.0)       # 4 km east
    d = make_colav('sbmpc').decide(0.0, own, [tgt], math.pi / 2, 1.0)
    markers = colav_markers(12.5, own, [tgt], d, 926.0).markers
    assert markers[0].action == Marker.DELETEALL
    (circle,) = [m for m in markers if m.ns == 'safe_distance']
    assert (circle.pose.position.x, circle.pose.position.y) == (4000.0, 0.0)   # ENU x = east
    assert circle.scale.x == circle.scale.y == 2 * 926.0
    cpa_points = [m for m in markers if m.ns == 'cpa']
    # head-on at equal speeds: both CPA points at the middle, 2000 m east
    assert [m.pose.position.x for m in cpa_points] == pytest.approx([2000.0, 2000.0])
    (arrow,) = [m for m in markers if m.ns == 'course']
    assert quaternion_to_yaw(arrow.pose.orientation) == pytest.approx(psi_to_yaw(d.course))
    assert d.course_offset > 0.0 and quaternion_to_yaw(arrow.pose.orientation) < 0.0
    assert arrow.header.stamp.sec == 12 and arrow.header.stamp.nanosec == 500_000_000
    # per-target radii: an uncertain target's circle is its widened safe distance
    from ship_guidance.colav_params import ColavParams
    p = ColavParams()
    fuzzy = colav_io.target_state('u', 0.0, 4000.0, -math.pi / 2, 7.7, 0.0, 100.0)
    radii = [p.safe_distance(t.position_sigma_m) for t in (tgt, fuzzy)]
    d = make_colav('sbmpc').decide(0.0, own, [tgt, fuzzy], math.pi / 2, 1.0)
    circles = [m for m in colav_markers(0.0, own, [tgt, fuzzy], d, radii).markers
               if m.ns == 'safe_distance']
    assert [c.scale.x for c in circles] == [2 * 926.0, 2 * (926.0 + p.uncertainty_k * 100.0)]
    assert all(m.header.frame_id == 'map' for m in markers[1:])


def test_position_sigma_is_the_largest_axis_of_the_covariance():
    """sqrt of the largest eigenvalue of the x-y block of a 6x6 row-major pose covariance:
    a diagonal one gives its larger sigma, a rotated ellipse its major axis, zeros 0; a
    non-finite one is nan and the target is refused."""
    from ship_guidance.colav_io import position_sigma, target_problem, target_state
    cov = [0.0] * 36
    assert position_sigma(cov) == 0.0
    cov[0], cov[7] = 9.0, 400.0
    assert position_sigma(cov) == pytest.approx(20.0)
    a, b, th = 30.0, 5.0, 0.7                     # major, minor sigma, rotation
    c, s = math.cos(th), math.sin(th)
    cov[0] = a * a * c * c + b * b * s * s
    cov[7] = a * a * s * s + b * b * c * c
    cov[1] = cov[6] = (a * a - b * b) * c * s
    assert position_sigma(cov) == pytest.approx(a)
    cov[1] = math.nan
    state = target_state('t', 0.0, 0.0, 0.0, 1.0, 0.0, position_sigma(cov))
    assert target_problem(state)[0] == 'non_finite'
    assert target_problem(target_state('t', 0.0, 0.0, 0.0, 1.0, 0.0, 20.0)) is None
