"""Fixtures and set-up shared by every test.

The test process imports ship_* and scripts/ modules from the folders pytest.ini's
``pythonpath`` names. The processes tests start (scripts, launchers, recorders) get the same
folders through PYTHONPATH, set here once; graphs started from the colcon install put the
install tree ahead of them (ship_mission.processes.install_env), as sourcing
install/setup.bash would.
"""
import os

import pytest


def pytest_configure(config):
    folders = [str(path) for path in config.getini('pythonpath')]
    old = [p for p in os.environ.get('PYTHONPATH', '').split(os.pathsep) if p and p not in folders]
    os.environ['PYTHONPATH'] = os.pathsep.join(folders + old)


#: Where the tests that start node graphs live (tests/integration/conftest.py marks them
#: `integration`), as pytest-xdist names a test: relative to the rootdir.
GRAPH_TESTS = 'tests/integration/'
#: The files there that start no graph (a Ray cluster or a local Ray instance; executables
#: that refuse a bad parameter and exit): the scheduler lets them run beside the graphs, on the
#: other worker. Checked at collection: none of their tests may take a graph fixture.
WITHOUT_GRAPHS = frozenset(GRAPH_TESTS + name for name in (
    'test_install_tree.py', 'test_sweep_ray.py', 'test_sweep_ray_cluster.py'))
#: The fixtures that start a ROS graph (``launch`` and the others build on them).
GRAPH_FIXTURES = frozenset({'ros_graph', 'module_ros_graph'})
#: The files there whose tests start one node process at a time on their own domain, driven by
#: the test node (a lockstep simulator the test itself steps among them), and never a graph of
#: nodes that wait for each other: no two lockstep graphs can start together through them (what
#: keeps the graph files on one worker), so the scheduler lets them run on either worker.
#: Checked at collection: none of their tests may take ``launch``.
SINGLE_NODES = frozenset(GRAPH_TESTS + name for name in (
    'test_ais_node.py', 'test_ais_node_hostile.py', 'test_colav_node_hostile.py',
    'test_colav_uncertainty.py', 'test_file_input_processes.py', 'test_held_by_name.py',
    'test_live_bridge_latched.py', 'test_node_input_processes.py',
    'test_param_schema_processes.py', 'test_planner_node.py', 'test_speed_factor_node.py',
    'test_tracker_node.py', 'test_vessel_node.py', 'test_vessel_node_wind.py',
    'test_waves_node.py'))
LAUNCH_FIXTURE = 'launch'


def pytest_collection_modifyitems(items):
    for item in items:
        path = item.nodeid.split('::', 1)[0]
        if path in WITHOUT_GRAPHS and GRAPH_FIXTURES & set(item.fixturenames):
            raise pytest.UsageError(
                f'{item.nodeid} starts a ROS graph: take {path} out of WITHOUT_GRAPHS '
                '(tests/conftest.py), so that it runs on the graphs\' worker')
        if path in SINGLE_NODES and LAUNCH_FIXTURE in item.fixturenames:
            raise pytest.UsageError(
                f'{item.nodeid} launches a graph: take {path} out of SINGLE_NODES '
                '(tests/conftest.py), so that it runs on the graphs\' worker')


@pytest.hookimpl(tryfirst=True, optionalhook=True)
def pytest_xdist_make_scheduler(config, log):
    """`make test TEST_JOBS=2` (``--dist loadgroup``): every integration file that starts a
    graph on one worker, so no two graph tests run at a time (two lockstep graphs starting
    together under the doubled load can miss a first command, doc/known_limits.md) while the
    other worker runs the rest (WITHOUT_GRAPHS and SINGLE_NODES among them: the graphs' worker
    is the suite's longest); every other file whole on a worker, so a module-scoped fixture is made once, as
    with ``--dist loadfile``. The graph files go out first: they take longest, and another
    worker's queue is then only the short files (longest job first).

    xdist 3.8's own loadgroup puts a group into the node id (``item._nodeid``), which pytest 9
    no longer reads (node ids are structured), so it groups nothing: the groups are made here,
    from the file path, on xdist's scope scheduler."""
    if config.getvalue('dist') != 'loadgroup':
        return None
    from xdist.scheduler import LoadScopeScheduling

    class GraphsOnOneWorker(LoadScopeScheduling):
        def _split_scope(self, nodeid):
            path = nodeid.split('::', 1)[0]
            graphs = path.startswith(GRAPH_TESTS) and path not in WITHOUT_GRAPHS | SINGLE_NODES
            return GRAPH_TESTS if graphs else path

        def _assign_work_unit(self, node):
            if GRAPH_TESTS in self.workqueue:
                self.workqueue.move_to_end(GRAPH_TESTS, last=False)
            super()._assign_work_unit(node)

    return GraphsOnOneWorker(config, log)
