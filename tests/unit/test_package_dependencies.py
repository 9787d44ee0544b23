"""Imports run one way, package.xml says so, and no module imports itself round a cycle.

The order of the five packages (a package may import only those listed for it):

    ship_sim  <-  ship_guidance  <-  {ship_autopilot, ship_planner}  <-  ship_mission

ship_autopilot and ship_planner do not import each other; ship_mission (launcher, recorder,
analysis) may import the four and none of them imports it; scripts/ may import any package; no
package imports scripts/. Every package.xml declares (exec_depend or depend) exactly the ship_*
packages its modules import, and every other module they import that is not in the standard
library: a ROS package under its own name, a Python library under its rosdep key (ROSDEP_KEYS).
Imports are read from the source (ast), at module level and inside functions alike: a lazy
import is still a dependency.
"""
import ast
import configparser
import sys
import xml.etree.ElementTree as ET
from pathlib import Path

import networkx as nx
import pytest

REPO = Path(__file__).resolve().parents[2]
SRC = REPO / 'ros_ws' / 'src'
SCRIPTS = REPO / 'scripts'
#: Package -> the packages it may import (besides itself).
ALLOWED = {
    'ship_sim': set(),
    'ship_guidance': {'ship_sim'},
    'ship_autopilot': {'ship_sim', 'ship_guidance'},
    'ship_planner': {'ship_sim', 'ship_guidance'},
    'ship_mission': {'ship_sim', 'ship_guidance', 'ship_autopilot', 'ship_planner'},
}
PACKAGES = sorted(ALLOWED)
#: Top-level module of a Python library -> its rosdep key in package.xml (rosdistro's
#: rosdep/python.yaml; '-pip' keys install from PyPI). Any other non-stdlib import is taken for
#: a ROS package, whose key is its own name.
ROSDEP_KEYS = {
    'numpy': 'python3-numpy',
    'scipy': 'python3-scipy',
    'yaml': 'python3-yaml',
    'skimage': 'python3-skimage',
    'networkx': 'python3-networkx',
    'PIL': 'python3-pil',
    'fiona': 'python3-fiona',
    'shapely': 'python3-shapely',
    'gymnasium': 'python3-gymnasium-pip',
    'numba': 'python3-numba',
    'pyais': 'python3-pyais-pip',
    'roaring_landmask': 'python3-roaring-landmask-pip',
    'matplotlib': 'python3-matplotlib',
    'lz4': 'python3-lz4',
    'websockets': 'python3-websockets',
    'rosbags': 'python3-rosbags-pip',
    'mcap': 'python3-mcap-pip',
    'mcap_ros2': 'python3-mcap-ros2-support-pip',
    'foxglove': 'python3-foxglove-sdk-pip',
    'playwright': 'python3-playwright-pip',
}


def module_files(root):
    """{dotted module name: file} of every .py under root (a folder on sys.path)."""
    out = {}
    for path in sorted(root.rglob('*.py')):
        if '__pycache__' in path.parts:
            continue
        parts = list(path.relative_to(root).with_suffix('').parts)
        if parts[-1] == '__init__':
            parts.pop()
        out['.'.join(parts)] = path
    return out


def imports(path, module):
    """[(imported dotted name, line)] of one file, relative imports resolved; for
    ``from A import b`` both A and A.b are given (b may be a submodule or a name in A)."""
    tree = ast.parse(path.read_text(), filename=str(path))
    package = module if path.name == '__init__.py' else module.rpartition('.')[0]
    found = []
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            found += [(alias.name, node.lineno) for alias in node.names]
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                base = package.split('.')[:len(package.split('.')) - node.level + 1]
                base = '.'.join(base + ([node.module] if node.module else []))
            else:
                base = node.module
            found.append((base, node.lineno))
            found += [(f'{base}.{alias.name}', node.lineno) for alias in node.names]
    return found


def package_modules(pkg):
    return module_files(SRC / pkg)


def run_depends(pkg):
    """Every key package.xml declares as a run dependency (exec_depend or depend)."""
    root = ET.parse(SRC / pkg / 'package.xml').getroot()
    return {e.text.strip() for tag in ('exec_depend', 'depend') for e in root.iter(tag) if e.text}


def declared(pkg):
    """ship_* packages package.xml declares as run dependencies."""
    return {key for key in run_depends(pkg) if key.startswith('ship_')}


def test_the_packages_are_the_five_of_the_order():
    found = sorted(p.name for p in SRC.iterdir() if (p / 'package.xml').exists())
    assert found == PACKAGES, ('ros_ws/src holds packages %s; add a new one to ALLOWED in this '
                               'test with the packages it may import' % found)


def test_pytest_puts_every_package_and_scripts_on_the_path():
    # pytest.ini names the source folders by hand (doc/guide/install.md), so a new package must
    # be added there too.
    ini = configparser.ConfigParser()
    ini.read(REPO / 'pytest.ini')
    listed = set(ini['pytest']['pythonpath'].split())
    want = {f'ros_ws/src/{pkg}' for pkg in PACKAGES} | {'scripts'}
    assert listed == want, f'pytest.ini pythonpath {sorted(listed)} should be {sorted(want)}'


def scripts_top_level_names():
    return {name.split('.')[0] for name in module_files(SCRIPTS)}


@pytest.mark.parametrize('pkg', PACKAGES)
def test_package_imports_are_declared_and_go_one_way(pkg):
    script_names = scripts_top_level_names()
    used, problems = set(), []
    for module, path in package_modules(pkg).items():
        where = path.relative_to(REPO)
        seen = {}   # one report per import statement and package (the first name it gives)
        for name, line in imports(path, module):
            seen.setdefault((line, name.split('.')[0]), name)
        for (line, top), name in seen.items():
            if top == pkg:
                continue
            if top.startswith('ship_'):
                used.add(top)
                if top not in ALLOWED[pkg]:
                    problems.append(f'{where}:{line} imports {name}: {pkg} may import only '
                                    f'{sorted(ALLOWED[pkg]) or "no other ship_* package"} '
                                    '(order ship_sim <- ship_guidance <- {ship_autopilot, '
                                    'ship_planner} <- ship_mission)')
                elif top not in declared(pkg):
                    problems.append(f'{where}:{line} imports {name}, but '
                                    f'ros_ws/src/{pkg}/package.xml has no '
                                    f'<exec_depend>{top}</exec_depend>')
            elif top in script_names and not (SRC / pkg / top).exists():
                problems.append(f'{where}:{line} imports {name} from scripts/: packages must '
                                'not depend on the tools that use them')
    for extra in sorted(declared(pkg) - used):
        problems.append(f'ros_ws/src/{pkg}/package.xml declares <exec_depend>{extra}'
                        f'</exec_depend> but no module of {pkg} imports {extra}')
    for dep in sorted(declared(pkg) - ALLOWED[pkg] - {pkg}):
        problems.append(f'ros_ws/src/{pkg}/package.xml declares {dep}, against the order')
    assert not problems, '\n'.join(problems)


@pytest.mark.parametrize('pkg', PACKAGES)
def test_package_third_party_imports_are_declared(pkg):
    # setup.py runs at build time (setuptools is colcon's), not when the package runs.
    modules = {m: p for m, p in package_modules(pkg).items() if m != 'setup'}
    own = {m.split('.')[0] for m in modules}
    deps, missing = run_depends(pkg), {}
    for module, path in modules.items():
        for name, line in imports(path, module):
            top = name.split('.')[0]
            if top in own or top.startswith('ship_') or top in sys.stdlib_module_names:
                continue
            key = ROSDEP_KEYS.get(top, top)
            if key not in deps:
                hint = '' if top in ROSDEP_KEYS else (f' (taken for a ROS package; if {top} is a Python '
                                                      'library, add its rosdep key to ROSDEP_KEYS here)')
                missing.setdefault(key, f'{path.relative_to(REPO)}:{line} imports {top}, but '
                                        f'ros_ws/src/{pkg}/package.xml has no <exec_depend>{key}'
                                        f'</exec_depend>{hint}')
    assert not missing, '\n'.join(sorted(missing.values()))


def import_graph():
    """Directed graph module -> imported module over the five packages and scripts/ (edges
    carry the file and line of the import)."""
    files = {}
    for pkg in PACKAGES:
        files.update(package_modules(pkg))
    scripts = module_files(SCRIPTS)
    clash = sorted(set(files) & set(scripts))
    assert not clash, f'scripts/ modules shadow package modules: {clash}'
    files.update(scripts)
    graph = nx.DiGraph()
    graph.add_nodes_from(files)
    for module, path in files.items():
        for name, line in imports(path, module):
            # The longest importable prefix: ``from A import b`` names A.b if it is a module.
            while name and name not in files:
                name = name.rpartition('.')[0]
            if name and name != module:
                graph.add_edge(module, name, where=f'{path.relative_to(REPO)}:{line}')
    return graph


def test_no_import_cycle_in_the_repository():
    graph = import_graph()
    assert graph.number_of_nodes() > 50 and graph.number_of_edges() > 100   # the parse worked
    cycles = []
    for component in nx.strongly_connected_components(graph):
        if len(component) > 1:
            cycle = nx.find_cycle(graph.subgraph(component))
            text = (' -> '.join([a for a, _ in cycle] + [cycle[0][0]]) + '  ('
                    + ', '.join(graph.edges[a, b]['where'] for a, b in cycle) + ')')
            if len(component) > len(cycle):
                text += f'; all of {sorted(component)} import each other round cycles'
            cycles.append(text)
    assert not cycles, 'import cycles:\n' + '\n'.join(sorted(cycles))
