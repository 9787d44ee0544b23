"""Collision avoidance in the node graph, real processes through the launcher
(scenarios/head_on_mariner_2.yaml, its first DURATION_S): two full Mariners on reciprocal courses
in lockstep, the own ship (vessel_0) with colav_node (SB-MPC), the target (target_0, `traffic:`)
holding its route.

- COLREGs Rule 14: the own ship alters to starboard, apparently (Rule 8(b): at least 30 deg of
  heading), and they pass port to port (the target on the own port side at the closest point)
  beyond the colav d_safe_m in force; on their routes alone they would meet (range 0).
- colav_node answers every own odom with one heading_cmd: heading_ref itself, byte for byte,
  while the decision in force keeps the nominal course, another value while it alters.
- The record is complete (every step of both vessels). That colav in the graph repeats is
  checked elsewhere, more strictly than a second run here would: test_imazu_graph.py compares
  the own ship's odometry and every decision bit for bit with the deterministic in-process
  runner, and test_ais_scenario.py repeats an AIS-fed run and compares the colav messages.
- Both ships with their own colav_node (scenarios/head_on_mariner_reciprocal.yaml): each
  alters to starboard, apparently, and they pass port to port beyond d_safe_m.
- colav_node alone, fed by the test: it waits for a lockstep target up to its own stamp, decides
  on the target state stamped at or before that stamp, stops waiting for a silent target.
"""
import time

import numpy as np
import pytest
import yaml

from ship_mission.bag import read_bag
from ship_mission.encounter import alteration, colav_messages, decision_rows, min_distance
from ship_guidance.colav_params import ColavParams
from ship_sim.ros.qos import STREAM_KEPT

from harness import REPO_ROOT, run_complete

SCENARIO = REPO_ROOT / 'scenarios' / 'head_on_mariner_2.yaml'
RECIPROCAL = REPO_ROOT / 'scenarios' / 'head_on_mariner_reciprocal.yaml'
# Both ships avoiding: the closest point still comes at about R0 / (2 U) = 259 s (above), a
# little earlier as both turn away; the run need not hold the return to the nominal course.
RECIPROCAL_S = 300.0
OWN, TARGET = 'vessel_0', 'target_0'
# The run must hold the closest approach and colav_node's return to the nominal course. Head-on
# from R0 = 4000 m at U = 7.7175 m/s each, the own course altered by theta: the relative velocity
# is 2 U cos(theta / 2) and its part along the line of sight U (1 + cos theta), so the closest
# point comes at R0 / (2 U) = 259 s whatever theta (plus the time the turn takes). The avoiding
# course is held while the nominal prediction comes within threat_m (1852 m); opening, that ends
# when the range passes threat_m, sqrt(threat_m^2 - d^2) / (2 U cos(theta / 2)) later: 120 s at
# most for a passing distance d >= d_safe (926 m) and theta <= 60 deg, so by ~380 s. 400 s
# leaves nominal decisions after it (the pass-through check below needs both kinds).
DURATION_S = 400.0


@pytest.mark.timeout(420)
def test_head_on_mariners_pass_port_to_port_beyond_d_safe(launch):
    scenario = yaml.safe_load(SCENARIO.read_text())
    colav = scenario['vessels'][OWN]['colav']
    d_safe = colav.get('d_safe_m', ColavParams().d_safe_m)
    dt = scenario['dt_s']
    n = int(round(DURATION_S / dt)) + 1

    first, _ = run_complete(launch, SCENARIO, DURATION_S)
    msgs = colav_messages(first / 'bag', OWN)
    data = read_bag(first / 'bag', namespaces=[f'/{OWN}', f'/{TARGET}'])
    own, tgt = data.vessels[f'/{OWN}'], data.vessels[f'/{TARGET}']
    assert len(own.t) == len(tgt.t) == n, 'every step of both vessels in the bag'

    enc = min_distance(own, tgt)
    rows = decision_rows(first / 'bag', OWN)
    alt = alteration(rows)
    print(f'head-on: {enc}, {alt}')
    # On their routes they meet: both start on y = 0 heading for each other.
    assert abs(own.y[0]) < 1.0 and abs(tgt.y[0]) < 1.0
    assert enc['t_min_s'] < own.t[-1], 'still closing at the end of the run'
    assert enc['min_distance_m'] > d_safe, enc
    assert enc['side'] == 'port', enc
    assert alt['first_avoid_s'] is not None and alt['first_offset_deg'] > 0.0, alt
    assert not alt['last_resort']
    # Apparent alteration to starboard: ENU yaw decreases by at least 30 deg before the CPA.
    before = own.t <= enc['t_min_s']
    turn = np.degrees(np.unwrap(own.yaw[before]) - own.yaw[0])
    assert turn.min() <= -30.0, f'largest starboard turn {-turn.min():.1f} deg'

    assert len(msgs['heading_cmd']) == len(msgs['heading_ref']) == n
    assert len(msgs['colav_decision']) == len(rows) == int(np.ceil(n * dt / 1.0))
    t_steps = np.arange(n) * dt
    in_force = np.searchsorted(rows[:, 0], t_steps + 1e-9, side='right') - 1
    keeps = rows[in_force, 2] == 0.0
    same = np.array([a == b for a, b in zip(msgs['heading_cmd'], msgs['heading_ref'])])
    assert keeps.any() and (~keeps).any()
    np.testing.assert_array_equal(same, keeps)



def _starboard_turn_deg(vessel, until_s):
    """The largest turn to starboard (deg) from the start heading before ``until_s``: ENU yaw
    decreases turning to starboard, whatever the ship's course."""
    before = vessel.t <= until_s
    return -float(np.degrees(np.unwrap(vessel.yaw[before]) - vessel.yaw[0]).min())


@pytest.mark.timeout(300)
def test_two_mariners_each_with_its_own_colav_both_alter_to_starboard_and_pass_port_to_port(
        launch):
    """A reciprocal encounter in the node graph (issue 31 item 4): the head-on geometry of
    head_on_mariner_2 with both ships under way with colav_node, each the other's target. Rule 14
    binds both: each alters to starboard, apparently (Rule 8(b): at least 30 deg of heading),
    before the closest point, and they pass port to port beyond d_safe_m."""
    scenario = yaml.safe_load(RECIPROCAL.read_text())
    names = sorted(scenario['vessels'])
    assert all('colav' in scenario['vessels'][n] for n in names) and len(names) == 2
    d_safe = ColavParams().d_safe_m
    folder, _ = run_complete(launch, RECIPROCAL, RECIPROCAL_S)
    data = read_bag(folder / 'bag', namespaces=[f'/{n}' for n in names])
    a, b = (data.vessels[f'/{n}'] for n in names)
    enc = min_distance(a, b)
    print(f'reciprocal head-on: {enc}')
    assert enc['t_min_s'] < a.t[-1], 'still closing at the end of the run'
    assert enc['min_distance_m'] > d_safe, enc
    assert enc['side'] == 'port', enc
    for name, vessel in zip(names, (a, b)):
        alt = alteration(decision_rows(folder / 'bag', name))
        assert alt['first_avoid_s'] is not None and alt['first_offset_deg'] > 0.0, (name, alt)
        assert not alt['last_resort'], (name, alt)
        turn = _starboard_turn_deg(vessel, enc['t_min_s'])
        assert turn >= 30.0, f'{name}: largest starboard turn {turn:.1f} deg'


@pytest.mark.timeout(120)
def test_colav_node_decides_on_target_states_up_to_its_stamp_and_waits_for_lockstep_targets(
        ros_graph):
    """colav_node alone, fed by the test: started with the installed config/colav.yaml (every
    key it lists is accepted), one lockstep target topic.

    - The first own odom (a decision step) is not answered before the target's sample at that
      stamp; then it is, with heading_ref itself (no threat: the target is far off).
    - Between decisions it answers at once, without target samples.
    - A decision uses the target state stamped at or before the own stamp: a head-on sample at
      t = 1 s and a harmless one at t = 1.5 s, both there before the own odom of t = 1 s, give a
      starboard alteration and a head-on / give-way row.
    - A target silent past lockstep_target_timeout_s is no longer waited for (warned)."""
    from nav_msgs.msg import Odometry
    from std_msgs.msg import Float64, Float64MultiArray

    from ship_guidance import colregs
    from ship_guidance.colav_io import ROLE_CODES, TARGET_COLUMNS
    from ship_sim.frames import yaw_to_psi
    from ship_sim.ros.conversions import make_odometry
    config = REPO_ROOT / 'ros_ws' / 'install' / 'ship_guidance' / 'share' / 'ship_guidance' / \
        'config' / 'colav.yaml'
    node = ros_graph.start('ship_guidance', 'colav_node', namespace='/vessel_0',
                           params_file=config,
                           params={'target_topics': ['/v1/odom'],
                                   'lockstep_target_timeout_s': 2.0, 'use_sim_time': True})
    tn = ros_graph.test_node()
    odom = tn.publisher('/vessel_0/odom', Odometry)
    ref = tn.publisher('/vessel_0/heading_ref', Float64, STREAM_KEPT)   # as guidance_node's
    tgt = tn.publisher('/v1/odom', Odometry)
    cmd = tn.subscribe('/vessel_0/heading_cmd', Float64)
    rows = tn.subscribe('/vessel_0/colav_targets', Float64MultiArray)
    for pub in (odom, ref, tgt):
        assert tn.wait_for_subscribers(pub, timeout=20.0), node.report()
    U, east = 7.7, float(yaw_to_psi(0.0))     # own ship heading east (ENU yaw 0)
    nominal = 0.0123456789012345

    def own(t):
        odom.publish(make_odometry(t, 0.0, U * t, east, U, 0.0, 0.0, 'vessel_0/base_link'))
        ref.publish(Float64(data=nominal))

    def target(t, north, east_m, psi):
        tgt.publish(make_odometry(t, north, east_m, psi, U, 0.0, 0.0, 'v1/base_link'))

    own(0.0)
    tn.spin_for(1.0)
    assert len(cmd) == 0, 'answered before the lockstep target reached the stamp'
    target(0.0, 20000.0, 0.0, 0.0)                     # 20 km north, heading north
    assert tn.wait_for_message(cmd, 5.0) is not None, node.report()
    assert cmd[0].data == nominal                      # passed through, the same float
    for k in range(1, 10):                             # no decision due: answered at once
        own(0.1 * k)
    assert tn.wait_for_message(cmd, 5.0, count=10) is not None, node.report()
    assert all(m.data == nominal for m in cmd.messages)
    # head-on 4 km ahead, stamped 1.0; a harmless sample stamped 1.5 arrives before the own 1.0
    target(1.0, 0.0, 4000.0, float(yaw_to_psi(3.141592653589793)))
    target(1.5, 30000.0, 0.0, 0.0)
    tn.spin_for(0.3)
    own(1.0)
    m = tn.wait_for_message(cmd, 5.0, count=11)
    assert m is not None, node.report()
    assert m.data < nominal - 0.2, 'no starboard alteration (ENU yaw must decrease)'
    row = tn.wait_for_message(rows, 5.0, count=2)
    assert row is not None and len(row.data) == len(TARGET_COLUMNS)
    assert int(row.data[2]) == colregs.HEAD_ON and int(row.data[3]) == ROLE_CODES['give-way']
    # t = 2.0: the target's newest sample is 1.5 s; silent, it is waited for 2 s, then dropped
    t0 = time.monotonic()
    own(2.0)
    assert tn.wait_for_message(cmd, 10.0, count=12) is not None, node.report()
    assert cmd.times[11] - t0 >= 1.5
    assert node.wait_for_output('silent', 5.0), node.report()


@pytest.mark.timeout(120)
def test_colav_node_keeps_off_a_charted_coast_in_a_head_on(ros_graph):
    """colav_node with `chart_topic`: a latched nav_msgs/OccupancyGrid puts a coast 500 m to the
    own ship's starboard (south of it, heading east), the widened clearance included. The same
    head-on that gives a starboard alteration without a chart (the test above) must now not
    turn to starboard: every starboard scenario held over the horizon runs aground."""
    from nav_msgs.msg import OccupancyGrid, Odometry
    from std_msgs.msg import Float64

    from ship_sim.frames import yaw_to_psi
    from ship_sim.ros.conversions import make_odometry
    from ship_sim.ros.qos import LATCHED
    config = REPO_ROOT / 'ros_ws' / 'install' / 'ship_guidance' / 'share' / 'ship_guidance' / \
        'config' / 'colav.yaml'
    node = ros_graph.start('ship_guidance', 'colav_node', namespace='/vessel_0',
                           params_file=config,
                           params={'target_topics': ['/v1/odom'], 'chart_topic': '/map',
                                   'use_sim_time': True})
    tn = ros_graph.test_node()
    chart = tn.publisher('/map', OccupancyGrid, LATCHED)
    grid = OccupancyGrid()
    grid.header.frame_id = 'map'
    res, width, height = 100.0, 200, 100            # 20 km east-west, 10 km south of y = 0
    grid.info.resolution, grid.info.width, grid.info.height = res, width, height
    grid.info.origin.position.x, grid.info.origin.position.y = -10_000.0, -10_000.0
    grid.info.origin.orientation.w = 1.0
    cells = np.zeros((height, width), dtype=np.int8)
    cells[:95, :] = 100                             # land south of y = -500 m
    grid.data = cells.ravel().tolist()
    chart.publish(grid)
    odom = tn.publisher('/vessel_0/odom', Odometry)
    ref = tn.publisher('/vessel_0/heading_ref', Float64, STREAM_KEPT)   # as guidance_node's
    tgt = tn.publisher('/v1/odom', Odometry)
    cmd = tn.subscribe('/vessel_0/heading_cmd', Float64)
    for pub in (odom, ref, tgt):
        assert tn.wait_for_subscribers(pub, timeout=20.0), node.report()
    assert node.wait_for_output(r'chart 200 x 100 cells of 100 m', 20.0), node.report()
    U, east, nominal = 7.7, float(yaw_to_psi(0.0)), 0.0
    tgt.publish(make_odometry(0.0, 0.0, 4000.0, float(yaw_to_psi(3.141592653589793)), U, 0.0,
                              0.0, 'v1/base_link'))          # head-on, 4 km ahead
    tn.spin_for(0.3)
    odom.publish(make_odometry(0.0, 0.0, 0.0, east, U, 0.0, 0.0, 'vessel_0/base_link'))
    ref.publish(Float64(data=nominal))
    m = tn.wait_for_message(cmd, 10.0)
    assert m is not None, node.report()
    assert m.data >= nominal, f'turned to starboard into the charted coast (ENU yaw {m.data})'
