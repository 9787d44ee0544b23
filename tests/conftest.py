"""Fixtures and set-up shared by every test.

The test process imports ship_* and scripts/ modules from the folders pytest.ini's
``pythonpath`` names. The processes tests start (scripts, launchers, recorders) get the same
folders through PYTHONPATH, set here once; graphs started from the colcon install put the
install tree ahead of them (ship_mission.processes.install_env), as sourcing
install/setup.bash would.
"""
import os


def pytest_configure(config):
    folders = [str(path) for path in config.getini('pythonpath')]
    old = [p for p in os.environ.get('PYTHONPATH', '').split(os.pathsep) if p and p not in folders]
    os.environ['PYTHONPATH'] = os.pathsep.join(folders + old)
