"""vessel_node acting on colav_node's speed_factor_cmd (speed_factor_input), real processes.

1. Container in lockstep: a test node answers each odom with rudder_cmd 0 and a speed factor
   (1, then 0 = stop from step 100 on). Each step waits for its factor (the node does not
   advance while a factor is withheld, though the rudder_cmd is there); the odometry equals the
   pure simulator run with the shaft at factor x the nominal (ship_sim.speed_factor), every
   field, every step; after the stop the ship slows steadily.
2. Mariner (no shaft input in MSS): speed_factor_cmd is ignored with one info line, and the node
   does not wait for it.
"""
import pytest
from nav_msgs.msg import Odometry
from std_msgs.msg import Float64

from ship_sim.ros.conversions import make_odometry
from ship_sim.simulator import VesselSimulator
from ship_sim.speed_factor import scaled_shaft

from test_vessel_node import _odom_fields

NS = '/vessel_0'
N_STEPS = 300
STOP_AT = 100        # factor 0 from this step on
HOLD_AT = 150        # the factor of this step is withheld for a while


def _factor(k):
    return 1.0 if k < STOP_AT else 0.0


def _expected_odoms(model, n_steps, factor):
    sim = VesselSimulator(model, dt=0.1)
    base = sim.shaft_command
    out = [_odom_fields(make_odometry(*sim.nav_state(), child_frame_id='vessel_0/base_link'))]
    for k in range(n_steps):
        sim.step(0.0, scaled_shaft(base, factor(k)))
        out.append(_odom_fields(make_odometry(*sim.nav_state(),
                                              child_frame_id='vessel_0/base_link')))
    return out


def _start(ros_graph, model):
    tn = ros_graph.test_node()
    cmd = tn.publisher(f'{NS}/rudder_cmd', Float64)
    factor = tn.publisher(f'{NS}/speed_factor_cmd', Float64)
    held = []

    def answer(msg):
        k = len(odom) - 1                  # this odom is step k
        cmd.publish(Float64(data=0.0))     # the rudder first: the node must still wait
        if k == HOLD_AT and model == 'container':
            held.append(k)
        elif model == 'container' or k % 50 == 0:
            factor.publish(Float64(data=_factor(k)))

    odom = tn.subscribe(f'{NS}/odom', Odometry, callback=answer)
    sim = ros_graph.start('ship_sim', 'vessel_node', namespace=NS, label=model,
                          params={'model': model, 'stepping_mode': 'lockstep',
                                  'speed_factor_input': True, 'max_steps': N_STEPS,
                                  'lockstep_timeout': 5.0})
    assert tn.wait_for_subscribers(factor, timeout=20.0), sim.report()
    return tn, odom, factor, held, sim


@pytest.mark.timeout(120)
def test_container_stops_on_speed_factor_zero_each_step_waiting_for_its_factor(ros_graph):
    tn, odom, factor, held, sim = _start(ros_graph, 'container')
    assert tn.spin_until(lambda: held, timeout=60.0, poll=0.05), sim.report()
    tn.spin_for(1.0)
    assert len(odom) == HOLD_AT + 1, 'advanced without the step\'s speed factor'
    factor.publish(Float64(data=_factor(HOLD_AT)))
    assert tn.spin_until(lambda: len(odom) > N_STEPS or sim.returncode is not None,
                         timeout=60.0, poll=0.2), sim.report()
    assert sim.wait(10.0) == 0, sim.report()
    assert '0 lockstep timeouts' in sim.stderr()
    got = [_odom_fields(m) for m in odom.messages]
    assert got == _expected_odoms('container', N_STEPS, _factor)
    u = [m.twist.twist.linear.x for m in odom.messages]
    # Before the stop the trim speed holds; after it the ship coasts down, every step slower.
    assert max(u[:STOP_AT + 1]) - min(u[:STOP_AT + 1]) < 1e-6
    after = u[STOP_AT + 2:]
    assert all(b < a for a, b in zip(after, after[1:]))
    assert u[-1] < u[STOP_AT] - 0.1


@pytest.mark.timeout(120)
def test_mariner_ignores_the_speed_factor_with_one_info_line(ros_graph):
    tn, odom, _factor_pub, _held, sim = _start(ros_graph, 'mariner')
    assert tn.spin_until(lambda: len(odom) > N_STEPS or sim.returncode is not None,
                         timeout=60.0, poll=0.2), sim.report()
    assert sim.wait(10.0) == 0, sim.report()
    assert sim.output().count('speed_factor_cmd ignored: mariner has no shaft input') == 1
    got = [_odom_fields(m) for m in odom.messages]
    assert got == _expected_odoms('mariner', N_STEPS, lambda k: 1.0)
