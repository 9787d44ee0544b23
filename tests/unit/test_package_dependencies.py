"""Imports run one way, package.xml says so, and no module imports itself round a cycle.

The order of the four packages (a package may import only those listed for it):

    ship_sim  <-  ship_guidance  <-  {ship_autopilot, ship_planner}

ship_autopilot and ship_planner do not import each other; scripts/ may import any package; no
package imports scripts/. Every package.xml declares (exec_depend or depend) exactly the ship_*
packages its modules import. Imports are read from the source (ast), at module level and inside
functions alike: a lazy import is still a dependency.
"""
import ast
import configparser
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
}
PACKAGES = sorted(ALLOWED)


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


def declared(pkg):
    """ship_* packages package.xml declares as run dependencies."""
    root = ET.parse(SRC / pkg / 'package.xml').getroot()
    return {e.text.strip() for tag in ('exec_depend', 'depend') for e in root.iter(tag)
            if e.text and e.text.strip().startswith('ship_')}


def test_the_packages_are_the_four_of_the_order():
    found = sorted(p.name for p in SRC.iterdir() if (p / 'package.xml').exists())
    assert found == PACKAGES, ('ros_ws/src holds packages %s; add a new one to ALLOWED in this '
                               'test with the packages it may import' % found)


def test_pytest_puts_every_package_and_scripts_on_the_path():
    # The venv's shipnav.pth (Makefile) lists ros_ws/src/* and scripts/ by itself; pytest.ini
    # names them by hand, so a new package must be added there too.
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
                                    'ship_planner})')
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


def import_graph():
    """Directed graph module -> imported module over the four packages and scripts/ (edges
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
