"""Collision avoidance in the node graph, real processes through the launcher
(scenarios/head_on_mariner_2.yaml): two full Mariners on reciprocal courses in lockstep, the own
ship (vessel_0) with colav_node (SB-MPC), the target (target_0, `traffic:`) holding its route.

- COLREGs Rule 14: the own ship alters to starboard, apparently (Rule 8(b): at least 30 deg of
  heading), and they pass port to port (the target on the own port side at the closest point)
  beyond the colav d_safe_m in force; on their routes alone they would meet (range 0).
- colav_node answers every own odom with one heading_cmd: heading_ref itself, byte for byte,
  while the decision in force keeps the nominal course, another value while it alters.
- The record is complete (every step of both vessels) and two runs give identical metrics
  (vessels sections) and identical heading_cmd / colav_targets / colav_decision messages.
"""
import json

import numpy as np
import pytest
import yaml

from mission.bag import read_bag
from mission.encounter import alteration, colav_messages, decision_rows, min_distance
from ship_guidance.colav_params import ColavParams

from harness import REPO_ROOT

SCENARIO = REPO_ROOT / 'scenarios' / 'head_on_mariner_2.yaml'
OWN, TARGET = 'vessel_0', 'target_0'


def _run(launch):
    run = launch(SCENARIO, '--wall-timeout', 150)
    assert run.wait(170.0) == 0, run.report()
    run_dir = run.run_dir()
    info = yaml.safe_load((run_dir / 'run.json').read_text())
    assert info['outcome'] == 'duration reached', info
    return run_dir


@pytest.mark.timeout(420)
def test_head_on_mariners_pass_port_to_port_beyond_d_safe_identically_twice(launch):
    scenario = yaml.safe_load(SCENARIO.read_text())
    colav = scenario['vessels'][OWN]['colav']
    d_safe = colav.get('d_safe_m', ColavParams().d_safe_m)
    dt = scenario['dt_s']
    n = int(round(scenario['duration_s'] / dt)) + 1

    runs = [_run(launch) for _ in range(2)]
    first = runs[0]
    data = read_bag(first / 'bag', namespaces=[f'/{OWN}', f'/{TARGET}'])
    own, tgt = data.vessels[f'/{OWN}'], data.vessels[f'/{TARGET}']
    assert len(own.t) == len(tgt.t) == n, 'every step of both vessels in the bag'

    enc = min_distance(own, tgt)
    rows = decision_rows(first / 'bag', OWN)
    alt = alteration(rows)
    print(f'head-on: {enc}, {alt}')
    # On their routes they meet: both start on y = 0 heading for each other.
    assert abs(own.y[0]) < 1.0 and abs(tgt.y[0]) < 1.0
    assert enc['min_distance_m'] > d_safe, enc
    assert enc['side'] == 'port', enc
    assert alt['first_avoid_s'] is not None and alt['first_offset_deg'] > 0.0, alt
    assert not alt['last_resort']
    # Apparent alteration to starboard: ENU yaw decreases by at least 30 deg before the CPA.
    before = own.t <= enc['t_min_s']
    turn = np.degrees(np.unwrap(own.yaw[before]) - own.yaw[0])
    assert turn.min() <= -30.0, f'largest starboard turn {-turn.min():.1f} deg'

    msgs = colav_messages(first / 'bag', OWN)
    assert len(msgs['heading_cmd']) == len(msgs['heading_ref']) == n
    assert len(msgs['colav_decision']) == len(rows) == int(np.ceil(n * dt / 1.0))
    t_steps = np.arange(n) * dt
    in_force = np.searchsorted(rows[:, 0], t_steps + 1e-9, side='right') - 1
    keeps = rows[in_force, 2] == 0.0
    same = np.array([a == b for a, b in zip(msgs['heading_cmd'], msgs['heading_ref'])])
    assert keeps.any() and (~keeps).any()
    np.testing.assert_array_equal(same, keeps)

    second = runs[1]
    m1, m2 = (json.loads((r / 'metrics.json').read_text()) for r in runs)
    assert m1['vessels'] == m2['vessels']
    msgs2 = colav_messages(second / 'bag', OWN)
    for topic in ('heading_cmd', 'colav_targets', 'colav_decision'):
        assert msgs[topic] == msgs2[topic], topic
