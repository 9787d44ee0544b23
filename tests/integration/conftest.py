"""Fixtures of the integration tests (real node processes; see harness.py)."""
import pytest

from harness import RosGraph
from mission.domain import DomainLease
from mission.processes import install_env
from test_launcher import Launch


def pytest_collection_modifyitems(items):
    for item in items:
        if 'tests/integration/' in str(item.fspath).replace('\\', '/'):
            item.add_marker(pytest.mark.integration)


@pytest.fixture
def ros_graph(tmp_path, monkeypatch):
    """A fresh ROS graph for one test: own domain, localhost discovery, all ended at teardown."""
    lease = DomainLease()
    try:
        for var in ('ROS_LOCALHOST_ONLY', 'ROS_STATIC_PEERS', 'FASTRTPS_DEFAULT_PROFILES_FILE'):
            monkeypatch.delenv(var, raising=False)
        monkeypatch.setenv('ROS_DOMAIN_ID', str(lease.domain_id))
        monkeypatch.setenv('ROS_AUTOMATIC_DISCOVERY_RANGE', 'LOCALHOST')
        env = install_env()
        env['PYTHONUNBUFFERED'] = '1'
        env['RCUTILS_COLORIZED_OUTPUT'] = '0'
        graph = RosGraph(tmp_path, lease.domain_id, env)
        try:
            yield graph
        finally:
            graph.close()
    finally:
        lease.close()


@pytest.fixture
def launch(ros_graph, tmp_path):
    """launch(scenario, *args, own_domain=False) -> Launch; every launch is ended at teardown."""
    launches = []

    def start(scenario, *args, own_domain=False):
        folder = tmp_path / f'launch{len(launches)}'
        folder.mkdir()
        launches.append(Launch(ros_graph, folder, scenario, args, own_domain=own_domain))
        return launches[-1]

    yield start
    for run in launches:
        run.close()
        print(run.report())
