"""Fast DDS confined to the loopback interface (ship_mission.processes.LOOPBACK_PROFILE, the
integration tests' default and `run_mission.py --loopback-only`): a node started with it binds
UDP sockets on 127.0.0.1 only, while the same node without it binds 0.0.0.0 (doc/security.md);
both still discover each other on one domain."""
import ipaddress
import re
import shutil
import subprocess

import pytest

from ship_mission.processes import LOOPBACK_PROFILE

NODE_PARAMS = {'model': 'mariner', 'stepping_mode': 'lockstep'}   # idles until a step


def _udp_local_addresses(pid):
    """Local addresses of ``pid``'s UDP sockets, from `ss -uanpH`."""
    out = subprocess.run(['ss', '-uanpH'], capture_output=True, text=True, check=True,
                         timeout=10).stdout
    addresses = []
    for line in out.splitlines():
        if re.search(rf'\bpid={pid},', line):
            local = line.split()[3]                  # State Recv-Q Send-Q Local Peer Process
            addresses.append(local.rsplit(':', 1)[0].strip('[]').split('%')[0])
    return addresses


def _is_loopback(address):
    try:
        return ipaddress.ip_address(address).is_loopback
    except ValueError:   # '*' (every address)
        return False


@pytest.mark.timeout(60)
def test_the_loopback_profile_binds_only_loopback_sockets(ros_graph):
    if shutil.which('ss') is None:
        pytest.skip('`ss` (iproute2) is not installed: cannot list the sockets of a process')
    assert ros_graph.env['FASTRTPS_DEFAULT_PROFILES_FILE'] == str(LOOPBACK_PROFILE)
    confined = ros_graph.start('ship_sim', 'vessel_node', namespace='/confined',
                               params=NODE_PARAMS)
    open_env = {k: v for k, v in ros_graph.env.items() if k != 'FASTRTPS_DEFAULT_PROFILES_FILE'}
    open_env['ROS_AUTOMATIC_DISCOVERY_RANGE'] = 'LOCALHOST'   # the launcher's default
    unconfined = ros_graph.start('ship_sim', 'vessel_node', namespace='/unconfined',
                                 params=NODE_PARAMS, env=open_env)
    tn = ros_graph.test_node()

    def both_seen():   # discovery done: every transport of both nodes is open
        namespaces = {ns for _, ns in tn.node.get_node_names_and_namespaces()}
        return {'/confined', '/unconfined'} <= namespaces
    assert tn.spin_until(both_seen, timeout=30), ros_graph.report()

    for proc in (confined, unconfined):
        assert proc.returncode is None, proc.report()
    inside = _udp_local_addresses(confined.pid)
    outside = _udp_local_addresses(unconfined.pid)
    assert inside, 'the confined node has no UDP socket at all (ss could not see it?)'
    assert all(_is_loopback(a) for a in inside), f'confined node binds {sorted(set(inside))}'
    # The control: without the profile Fast DDS listens beyond loopback, which is the point.
    assert not all(_is_loopback(a) for a in outside), f'unconfined binds {sorted(set(outside))}'
    print(f'with the profile: {sorted(set(inside))}; without: {sorted(set(outside))}')
