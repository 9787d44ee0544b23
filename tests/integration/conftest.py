"""Fixtures of the integration tests (real node processes; see harness.py)."""
import contextlib

import pytest

from harness import RosGraph
from ship_mission.domain import DomainLease, LeaseError
from ship_mission.processes import LOOPBACK_PROFILE, install_env
from test_launcher import Launch


def pytest_collection_modifyitems(items):
    for item in items:
        if 'tests/integration/' in str(item.fspath).replace('\\', '/'):
            item.add_marker(pytest.mark.integration)


def lease_or_fail():
    """A DomainLease, or the test fails with the lease's one-line reason (no traceback)."""
    try:
        return DomainLease()
    except LeaseError as exc:
        pytest.fail(str(exc), pytrace=False)


@contextlib.contextmanager
def _fresh_graph(folder, monkeypatch):
    """A ROS graph on its own domain with Fast DDS on the loopback interface only, logs in
    ``folder``; every process it started is ended on exit."""
    lease = lease_or_fail()
    try:
        for var in ('ROS_LOCALHOST_ONLY', 'ROS_STATIC_PEERS', 'FASTDDS_DEFAULT_PROFILES_FILE'):
            monkeypatch.delenv(var, raising=False)
        monkeypatch.setenv('ROS_DOMAIN_ID', str(lease.domain_id))
        # Fast DDS on 127.0.0.1 only (doc/security.md) for the tests' nodes, the test process
        # and every launcher they start (install_env keeps a profile it finds set).
        monkeypatch.setenv('FASTRTPS_DEFAULT_PROFILES_FILE', str(LOOPBACK_PROFILE))
        monkeypatch.setenv('ROS_AUTOMATIC_DISCOVERY_RANGE', 'SYSTEM_DEFAULT')
        env = install_env(loopback_only=True)
        env['PYTHONUNBUFFERED'] = '1'
        env['RCUTILS_COLORIZED_OUTPUT'] = '0'
        graph = RosGraph(folder, lease.domain_id, env)
        try:
            yield graph
        finally:
            graph.close()
    finally:
        lease.close()


@pytest.fixture
def ros_graph(tmp_path, monkeypatch):
    """A fresh ROS graph for one test: own domain, localhost discovery, all ended at teardown."""
    with _fresh_graph(tmp_path, monkeypatch) as graph:
        yield graph


@pytest.fixture(scope='module')
def module_ros_graph(tmp_path_factory):
    """One fresh ROS graph for a module, for a run that several of its tests check (a
    module-scoped fixture of that module makes the run); ended after the module's last test."""
    with pytest.MonkeyPatch.context() as monkeypatch, \
            _fresh_graph(tmp_path_factory.mktemp('module_graph'), monkeypatch) as graph:
        yield graph


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
