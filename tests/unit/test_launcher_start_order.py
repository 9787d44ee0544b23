"""The launcher's start order of the simulators (ship_mission.launcher.simulator_start_plan) and its
wait for a simulator's step 0 (ship_mission.launcher.wait_for_ready), without DDS."""
import dataclasses
import time
from pathlib import Path
from types import SimpleNamespace

import pytest

from ship_mission.launcher import MissionFailed, wait_for_ready, simulator_start_plan
from ship_mission.scenario import load_scenario

SCENARIOS = Path(__file__).resolve().parents[2] / 'scenarios'


class Proc:
    def __init__(self, label, returncode=None):
        self.label, self.returncode, self.log_path = label, returncode, f'{label}.log'

    def output(self):
        return 'lockstep: waiting for the graph'


def wait(proc, others, seconds=0.3):
    group = SimpleNamespace(failed=lambda: [p for p in [proc, *others] if p.returncode is not None])
    monitor = SimpleNamespace(ready={'vessel_1': False}, spin=time.sleep)
    t0 = time.monotonic()
    wait_for_ready(proc, 'vessel_1', {'lockstep_start_timeout': seconds - 15.0}, monitor, group)
    return time.monotonic() - t0


def test_a_leader_that_finished_does_not_end_the_wait_for_its_follower():
    """A leader's simulator that ran its whole run (exit 0) before a slow follower published
    step 0 must not release that follower's own followers: they would start first and wait for
    a predecessor that has not begun (a platoon run was then not deterministic)."""
    follower, leader = Proc('vessel_1/vessel_node'), Proc('vessel_0/vessel_node', returncode=0)
    with pytest.raises(MissionFailed, match='did not publish step 0'):
        wait(follower, [leader])


def test_a_failed_process_or_the_awaited_one_exiting_ends_the_wait_at_once():
    follower = Proc('vessel_1/vessel_node')
    assert wait(follower, [Proc('vessel_0/autopilot_node', returncode=1)], seconds=5.0) < 1.0
    assert wait(Proc('vessel_1/vessel_node', returncode=1), [], seconds=5.0) < 1.0


def test_traffic_simulators_start_first_and_the_colav_vessel_waits_for_their_step_0():
    """colav_node waits for every target's sample from step 0 on and gives up on a silent one
    after lockstep_target_timeout_s; a target whose step 0 is out before the own ship starts
    cannot be that silent target."""
    scenario = load_scenario(SCENARIOS / 'head_on_mariner_2.yaml')
    assert simulator_start_plan(scenario) == [('target_0', ()), ('vessel_0', ('target_0',))]


def test_platoon_predecessors_start_first_and_are_waited_for():
    scenario = load_scenario(SCENARIOS / 'platoon_mariner_5.yaml')
    plan = simulator_start_plan(scenario)
    started = set()
    for ns, awaited in plan:
        spec = next(s for s in scenario.vessels if s.namespace == ns)
        assert awaited == (() if spec.predecessor is None else (spec.predecessor,))
        assert set(awaited) <= started
        started.add(ns)
    assert started == {s.namespace for s in scenario.vessels}


def test_in_realtime_nobody_waits_and_the_scenario_order_holds():
    scenario = dataclasses.replace(load_scenario(SCENARIOS / 'head_on_mariner_2.yaml'),
                                   stepping='realtime')
    assert simulator_start_plan(scenario) == [('vessel_0', ()), ('target_0', ())]
