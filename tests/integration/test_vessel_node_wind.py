"""vessel_node with wind (real process, lockstep): bit-identical on repeat and equal to the pure
simulator with the same WindField (so the wind_* parameters, the meteorological direction and the
gust seed reach the plant as documented); a model without wind loads is refused in one line."""
import math

import pytest

from ship_sim.environment.wind import WindField
from ship_sim.ros.conversions import make_odometry
from ship_sim.simulator import VesselSimulator

from harness import answer_each_odom

NS = '/vessel_0'
N_STEPS = 300
WIND = {'wind_speed': 18.0, 'wind_direction_deg': 300.0, 'wind_gust_sd': 2.0,
        'wind_time_constant': 20.0, 'wind_seed': 11}


def _command(k):
    return 0.05 * math.sin(0.03 * k)


def _fields(msg):
    p, o = msg.pose.pose.position, msg.pose.pose.orientation
    lin, ang = msg.twist.twist.linear, msg.twist.twist.angular
    return (msg.header.stamp.sec, msg.header.stamp.nanosec, p.x, p.y, o.z, o.w, lin.x, lin.y,
            ang.z)


def _expected():
    wind = WindField(18.0, math.radians(300.0), gust_sd=2.0, time_constant=20.0, seed=11)
    sim = VesselSimulator('container', dt=0.1, psi=0.0, wind=wind)
    out = [_fields(make_odometry(*sim.nav_state(), child_frame_id='vessel_0/base_link'))]
    for k in range(N_STEPS):
        sim.step(_command(k))
        out.append(_fields(make_odometry(*sim.nav_state(), child_frame_id='vessel_0/base_link')))
    return out


def _run(ros_graph, label):
    tn = ros_graph.test_node()
    odom, cmd = answer_each_odom(tn, NS, _command)
    sim = ros_graph.start('ship_sim', 'vessel_node', namespace=NS, label=label,
                          params={'model': 'container', 'stepping_mode': 'lockstep',
                                  'initial_yaw_deg': 90.0, 'max_steps': N_STEPS,
                                  'lockstep_timeout': 5.0, **WIND})
    assert tn.spin_until(lambda: len(odom) > N_STEPS or sim.returncode is not None,
                         timeout=60.0, poll=0.5)
    tn.spin_for(0.2)
    assert sim.wait(10.0) == 0
    assert 'wind 18 m/s from 300 deg (gust sd 2 m/s, T 20 s) (blendermann94)' in sim.stderr()
    result = [_fields(m) for m in odom.messages]
    tn.unsubscribe(odom)
    tn.node.destroy_publisher(cmd)
    return result


@pytest.mark.timeout(150)
def test_windy_lockstep_repeats_bit_for_bit_and_equals_the_pure_simulator(ros_graph):
    first = _run(ros_graph, 'wind_run1')
    second = _run(ros_graph, 'wind_run2')
    assert len(first) == N_STEPS + 1
    assert first == second
    assert first == _expected()


@pytest.mark.timeout(30)
def test_wind_on_a_model_without_wind_loads_exits_with_one_line(ros_graph):
    proc = ros_graph.start('ship_sim', 'vessel_node', namespace=NS,
                           params={'model': 'nomoto1', 'wind_speed': 10.0})
    code = proc.wait(20.0)
    assert code == 2
    lines = [line for line in proc.stderr().splitlines() if line.strip()]
    assert len(lines) == 1 and 'wind_speed' in lines[0] and 'mariner, tanker, container' in lines[0]
