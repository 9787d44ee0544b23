"""vessel_node with waves, a real process in lockstep (ship_sim.ros.waves).

The container ship (its own S-175 RAOs) runs straight (rudder 0) into head seas. Checked:
- two runs give bit-identical odom messages, and every heave (odom z = -heave) equals the pure
  ShipWaves motion at that step's time, speed and heading (the pure simulator's), bit for bit:
  the manoeuvring state is untouched and the wave-frequency motion is added to the output;
- the heave record's spectral peak is at the encounter frequency of the component with the
  largest heave response, w_e = w + w^2 U / g in head seas, and not at its wave frequency w.
  Tolerance: the record of T s resolves frequencies 2 pi / T apart; with a Hann window a single
  sinusoid's periodogram peaks within half a bin of it, and a neighbouring component (the sea
  has few, well-separated components here) moves it by less than another half: one bin.
- the latched sea_state topic carries the sea state.
"""
import math

import numpy as np
import pytest
from nav_msgs.msg import Odometry
from std_msgs.msg import Float64, Float64MultiArray

from ship_sim.environment.sea_state import SeaState, ShipWaves, rao_table_for
from ship_sim.models import make_model
from ship_sim.ros.qos import LATCHED
from ship_sim.simulator import VesselSimulator

NS = '/vessel_0'
RATE_HZ, N_STEPS = 2.0, 1200            # 600 s of sim time
SEA = {'waves_hs': 2.5, 'waves_tp': 10.0, 'waves_spectrum': 'jonswap', 'waves_gamma': 7.0,
       'waves_direction_deg': 180.0, 'waves_n_frequencies': 12, 'waves_omega_max': 1.8,
       'waves_seed': 7}


def _run(ros_graph, label):
    tn = ros_graph.test_node()
    cmd = tn.publisher(f'{NS}/rudder_cmd', Float64)
    zero = Float64(data=0.0)
    odom = tn.subscribe(f'{NS}/odom', Odometry, callback=lambda m: cmd.publish(zero))
    sea = tn.subscribe(f'{NS}/sea_state', Float64MultiArray, qos=LATCHED)
    sim = ros_graph.start('ship_sim', 'vessel_node', namespace=NS, label=label,
                          params={'model': 'container', 'stepping_mode': 'lockstep',
                                  'publish_rate': RATE_HZ, 'max_steps': N_STEPS,
                                  'initial_yaw_deg': 90.0, **SEA})
    assert tn.spin_until(lambda: len(odom) > N_STEPS or sim.returncode is not None,
                         timeout=120.0, poll=0.5)
    tn.spin_for(0.2)
    assert sim.wait(10.0) == 0, 'vessel_node did not end cleanly after max_steps'
    assert '0 lockstep timeouts' in sim.stderr() and 'waves Hs 2.5 m' in sim.stderr()
    assert len(odom) == N_STEPS + 1
    assert len(sea) == 1 and sea[0].data[0] == 2.5 and sea[0].data[1] == 10.0
    out = [(m.header.stamp.sec, m.header.stamp.nanosec, m.pose.pose.position.x,
            m.pose.pose.position.y, m.pose.pose.position.z, m.pose.pose.orientation.z,
            m.pose.pose.orientation.w, m.twist.twist.linear.x, m.twist.twist.angular.z)
           for m in odom.messages]
    for inbox in (odom, sea):
        tn.unsubscribe(inbox)
    tn.node.destroy_publisher(cmd)
    return out


@pytest.mark.timeout(300)
def test_waves_in_odom_are_deterministic_at_the_encounter_frequency(ros_graph):
    first = _run(ros_graph, 'waves_run1')
    second = _run(ros_graph, 'waves_run2')
    assert first == second

    # The pure side: the same sea state, the pure simulator's speed and heading at each step.
    model = make_model('container')
    sea = SeaState(hs=2.5, tp=10.0, gamma=7.0, direction=math.pi, n_frequencies=12,
                   omega_max=1.8, seed=7)
    waves = ShipWaves(sea, rao_table_for('container', model.length))
    pure = VesselSimulator(model, dt=0.1, psi=0.0)
    n_sub = int(round(1.0 / (RATE_HZ * 0.1)))
    heave = []
    for k in range(N_STEPS + 1):
        t, _, _, psi, *_ = pure.nav_state()
        heave.append(-waves.motion(t, pure.speed_water(), psi)[0][2])
        for _ in range(n_sub):
            pure.step(0.0)
    z = np.array([row[4] for row in first])
    assert z.tolist() == heave, 'odom heave differs from the pure wave motion'

    # Spectral peak of the heave record at the dominant component's encounter frequency.
    U = pure.speed_water()
    Oe, amp = waves.response.response_amplitudes(U, 0.0, math.pi)
    i = int(np.argmax(amp[2, :, 0]))
    w_e, w = Oe[i, 0], waves.response.Omega[i]
    T = N_STEPS / RATE_HZ
    spec = np.abs(np.fft.rfft((z - z.mean()) * np.hanning(z.size))) ** 2
    freqs = 2.0 * np.pi * np.fft.rfftfreq(z.size, d=1.0 / RATE_HZ)
    peak = freqs[np.argmax(spec)]
    bin_width = 2.0 * np.pi / T
    print(f'heave peak {peak:.4f} rad/s; dominant component w {w:.4f}, w_e {w_e:.4f} rad/s, '
          f'U {U:.2f} m/s, bin {bin_width:.4f} rad/s')
    assert abs(peak - w_e) <= bin_width
    assert abs(peak - w) > 3.0 * bin_width      # the encounter shift is resolved
    assert w_e == pytest.approx(w + w ** 2 * U / 9.8100004, rel=1e-12)   # head sea
