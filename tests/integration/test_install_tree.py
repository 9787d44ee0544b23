"""The colcon install tree is what `ros2 run` and the ament index expect, for every package.

`ros2 run P E` finds P through <prefix>/share/ament_index/resource_index/packages/P under
AMENT_PREFIX_PATH and runs <prefix>/lib/P/E; package.xml must be a valid format-3 manifest.
"""
import ast
import os
import subprocess
from pathlib import Path

import pytest
from catkin_pkg.package import parse_package

from conftest import lease_or_fail

REPO = Path(__file__).resolve().parents[2]
SRC = REPO / 'ros_ws' / 'src'
INSTALL = REPO / 'ros_ws' / 'install'
PACKAGES = sorted(p.name for p in SRC.iterdir() if (p / 'package.xml').exists())


def console_scripts(pkg):
    """Executable names declared in setup.py's console_scripts (read, not executed)."""
    tree = ast.parse((SRC / pkg / 'setup.py').read_text())
    for node in ast.walk(tree):
        if isinstance(node, ast.Dict):
            for k, v in zip(node.keys, node.values):
                if isinstance(k, ast.Constant) and k.value == 'console_scripts':
                    return [ast.literal_eval(e).split('=')[0].strip() for e in v.elts]
    return []


def test_all_four_packages_exist():
    assert {'ship_sim', 'ship_guidance', 'ship_autopilot', 'ship_planner'} <= set(PACKAGES)


@pytest.mark.parametrize('pkg', PACKAGES)
def test_package_xml_is_valid_format_3(pkg):
    manifest = parse_package(str(SRC / pkg / 'package.xml'))
    manifest.validate()  # raises on an invalid manifest (e.g. a malformed maintainer e-mail)
    assert manifest.package_format == 3
    assert manifest.get_build_type() == 'ament_python'
    assert manifest.name == pkg


@pytest.mark.parametrize('pkg', PACKAGES)
def test_install_tree_has_index_marker_manifest_and_executables(pkg):
    prefix = INSTALL / pkg
    assert (prefix / 'share' / 'ament_index' / 'resource_index' / 'packages' / pkg).exists()
    assert (prefix / 'share' / pkg / 'package.xml').exists()
    exes = console_scripts(pkg)
    assert exes, f'{pkg} declares no console_scripts'
    for exe in exes:
        path = prefix / 'lib' / pkg / exe
        assert path.exists() and os.access(path, os.X_OK), f'{path} missing (ros2 run {pkg} {exe})'



def installed_data(pkg):
    """setup.py's data_files as (install dir, source pattern or file) and its package_data patterns
    (relative to the package folder, e.g. 'data/*.npz' of 'ship_sim.environment' as
    'environment/data/*.npz'), read from the AST with only ``package_name`` and ``glob``
    known (the file is not executed)."""
    tree = ast.parse((SRC / pkg / 'setup.py').read_text())
    env = {'package_name': pkg, 'glob': lambda pattern: ('glob', pattern), '__builtins__': {}}
    data_files, package_data = [], []
    for node in ast.walk(tree):
        if isinstance(node, ast.keyword) and node.arg == 'data_files':
            for dest, files in eval(ast.unparse(node.value), env):   # only package_name and glob, no builtins
                data_files += [(dest, files)] if isinstance(files, tuple) else \
                              [(dest, f) for f in files]
        if isinstance(node, ast.keyword) and node.arg == 'package_data':
            for name, pats in eval(ast.unparse(node.value), env).items():
                sub = Path(*name.split('.')[1:])   # setuptools: patterns relative to that package
                package_data += [str(sub / p) for p in pats]
    return data_files, package_data


@pytest.mark.parametrize('pkg', PACKAGES)
def test_setup_py_installs_only_folders_that_exist_and_all_of_them(pkg):
    """No data_files or package_data pattern for a folder that does not exist, every matched
    file is in the install tree, and every config/ and doc/ file of the package is installed."""
    data_files, package_data = installed_data(pkg)
    listed = set()
    for dest, entry in data_files:
        sources = sorted((SRC / pkg).glob(entry[1])) if isinstance(entry, tuple) else [SRC / pkg / entry]
        assert sources, f'{pkg}/setup.py installs {entry[1]!r} into {dest}: nothing matches'
        for src in sources:
            assert src.is_file(), src
            assert (INSTALL / pkg / dest / src.name).exists(), f'{src} is not installed in {dest}'
            listed.add(src)
    for folder in ('config', 'doc'):
        files = {f for f in (SRC / pkg / folder).rglob('*') if f.is_file()} \
            if (SRC / pkg / folder).is_dir() else set()
        assert files <= listed, f'{pkg}/setup.py does not install {sorted(files - listed)}'
    site = sorted((INSTALL / pkg / 'lib').glob(f'python3*/site-packages/{pkg}'))
    assert site, f'{pkg} has no Python package in the install tree'
    for pattern in package_data:
        sources = sorted((SRC / pkg / pkg).glob(pattern))
        assert sources, f'{pkg}/setup.py package_data {pattern!r}: nothing matches'
        for src in sources:
            assert (site[0] / src.relative_to(SRC / pkg / pkg)).exists(), f'{src} is not installed'


#: One invalid parameter per executable: the node must refuse it with one line and exit 2.
BAD_PARAMETER = {
    'vessel_node': ('model', 'no_such_model'),
    'guidance_node': ('law', 'no_such_law'),
    'autopilot_node': ('controller', 'no_such_controller'),
    'route_node': ('route_file', '/no/such/route.yaml'),
    'follower_node': ('lookahead_m', '-1.0'),
    'planner_node': ('clearance_m', '.nan'),
    'ais_node': ('file', '/no/such/file.nmea'),
    'colav_node': ('method', 'no_such_method'),
    'traffic_node': ('targets', 'no_json'),
    'nav_display_node': ('display_rate_hz', '-1.0'),
    'aivdm_out_node': ('vessels', 'no_json'),
    'tracker_node': ('process_noise', '-1.0'),
}
#: Executables that are not nodes: their arguments, and a bad one of them (refused the same way).
BAD_ARGUMENTS = {
    'run_mission': ('duration', ['scenarios/flagship_mariner.yaml', '--duration', '-1']),
    'component_container': ('spec', ['/no/such/spec.json']),
}


@pytest.fixture(scope='module')
def setup_bash_env():
    """The environment `source install/setup.bash` gives (what a ROS 2 user runs nodes with)."""
    out = subprocess.run(['bash', '-c', f'source {INSTALL}/setup.bash && env -0'],
                         capture_output=True, text=True, check=True)
    return dict(kv.split('=', 1) for kv in out.stdout.split('\0') if '=' in kv)


@pytest.mark.parametrize('pkg', PACKAGES)
def test_executables_run_and_refuse_a_bad_parameter_in_one_line(pkg, setup_bash_env):
    lease = lease_or_fail()   # the domain scheme every test shares
    env = dict(setup_bash_env, ROS_DOMAIN_ID=str(lease.domain_id),
               ROS_AUTOMATIC_DISCOVERY_RANGE='LOCALHOST')
    try:
        _refuse_bad_parameters(pkg, env)
    finally:
        lease.close()


def _refuse_bad_parameters(pkg, env):
    for exe in console_scripts(pkg):
        assert exe in BAD_PARAMETER or exe in BAD_ARGUMENTS, \
            f'add a bad parameter for {exe} to BAD_PARAMETER (or BAD_ARGUMENTS)'
        if exe in BAD_ARGUMENTS:
            name, args = BAD_ARGUMENTS[exe]
        else:
            name, value = BAD_PARAMETER[exe]
            args = ['--ros-args', '-p', f'{name}:={value}']
        proc = subprocess.run([str(INSTALL / pkg / 'lib' / pkg / exe), *args], capture_output=True,
                              text=True, env=env, timeout=60, cwd=REPO)
        assert proc.returncode == 2, proc.stderr[-2000:]
        lines = proc.stderr.strip().splitlines()
        assert len(lines) == 1 and name in lines[0] and exe in lines[0], proc.stderr


def test_run_mission_is_installed_where_ros2_run_finds_it():
    """`ros2 run ship_mission run_mission` runs <prefix>/lib/ship_mission/run_mission: in a shell
    that sourced install/setup.bash and nothing else (no PYTHONPATH of the tests' source
    folders) it imports ship_mission and answers --help with the launcher's options."""
    exe = INSTALL / 'ship_mission' / 'lib' / 'ship_mission' / 'run_mission'
    env = {k: v for k, v in os.environ.items() if k != 'PYTHONPATH'}
    proc = subprocess.run(['bash', '-c', f'source {INSTALL}/setup.bash && exec {exe} --help'],
                          capture_output=True, text=True, env=env, timeout=60, cwd='/')
    assert proc.returncode == 0, proc.stderr[-2000:]
    assert proc.stdout.startswith('usage: run_mission') and '--domain-id' in proc.stdout
