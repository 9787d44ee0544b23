"""ship_mission's modules use each other through public names only.

A name with a leading underscore is its module's own business: another module that imports it
(``from ship_mission.bag import _x``) or reaches for it (``bag._x``, ``ship_mission.bag._x``)
breaks when the owner changes it. Read from the source (ast), lazy imports inside functions
included; dunder names (``__file__``, ``__doc__``) are not private.
"""
import ast
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]
PACKAGE = 'ship_mission'
SOURCE = REPO / 'ros_ws' / 'src' / PACKAGE / PACKAGE


def is_private(name):
    return name.startswith('_') and not (name.startswith('__') and name.endswith('__'))


def private_uses(source, module):
    """[(line, text)] of the places where ``source`` (the text of ship_mission module ``module``,
    e.g. 'ship_mission.report') imports or accesses a private name of another ship_mission
    module. Module-level names bound to a ship_mission module (``from ship_mission import bag``,
    ``import ship_mission.bag as b``, ``import ship_mission.bag``) are followed by name, in
    every scope."""
    tree = ast.parse(source)
    package = module.rpartition('.')[0]
    found = []
    # name in this file -> the ship_mission module it stands for
    modules = {}
    for node in ast.walk(tree):
        if isinstance(node, ast.ImportFrom):
            base = node.module or ''
            if node.level:
                parent = package.split('.')[:len(package.split('.')) - node.level + 1]
                base = '.'.join(parent + ([node.module] if node.module else []))
            if base != PACKAGE and not base.startswith(PACKAGE + '.'):
                continue
            for alias in node.names:
                if base == PACKAGE:
                    modules[alias.asname or alias.name] = f'{PACKAGE}.{alias.name}'
                if is_private(alias.name) and base != module:
                    found.append((node.lineno, f'from {base} import {alias.name}'))
        elif isinstance(node, ast.Import):
            for alias in node.names:
                if alias.name.startswith(PACKAGE + '.'):
                    if alias.asname:
                        modules[alias.asname] = alias.name
                    else:
                        modules[PACKAGE] = PACKAGE
    for node in ast.walk(tree):
        if not isinstance(node, ast.Attribute) or not is_private(node.attr):
            continue
        # ship_mission.bag._x: the dotted chain down to a name
        chain, value = [], node.value
        while isinstance(value, ast.Attribute):
            chain.insert(0, value.attr)
            value = value.value
        if not isinstance(value, ast.Name) or value.id not in modules:
            continue
        owner = '.'.join([modules[value.id]] + chain)
        if owner != module and owner != PACKAGE:
            found.append((node.lineno, f'{value.id}.{".".join(chain + [node.attr])}'))
    return sorted(found)


def mission_modules():
    return sorted(p for p in SOURCE.glob('*.py'))


def test_the_checker_finds_each_kind_of_reach_in():
    source = '\n'.join([
        'from ship_mission.recorder import _clock_ns, DEFAULT_EXCLUDE',
        'from ship_mission import bag as bagmod, plots',
        'import ship_mission.metrics',
        'import ship_mission.metrics as m',
        'from .launcher import _wait',
        'def f():',
        '    from ship_mission.scenario import _inner',
        '    return bagmod._open(1), plots._save(2), ship_mission.metrics._f(3), m._f(4)',
        'x = plots.save_figure, bagmod.__file__, _local()',
    ])
    found = sorted(text for _line, text in private_uses(source, 'ship_mission.report'))
    assert found == sorted(['from ship_mission.recorder import _clock_ns',
                            'from ship_mission.launcher import _wait',
                            'from ship_mission.scenario import _inner',
                            'bagmod._open', 'plots._save', 'ship_mission.metrics._f', 'm._f'])
    # a module's own private names are its own
    assert private_uses('from ship_mission.report import _own\nimport ship_mission.report as r\n'
                        'r._own()', 'ship_mission.report') == []


@pytest.mark.parametrize('path', mission_modules(), ids=lambda p: p.stem)
def test_no_module_uses_a_private_name_of_another(path):
    module = f'{PACKAGE}.{path.stem}' if path.stem != '__init__' else PACKAGE
    found = private_uses(path.read_text(), module)
    where = path.relative_to(REPO)
    assert not found, '\n'.join(f'{where}:{line} uses {text}: make the name public (no leading '
                                f'underscore) where it is defined, or keep it inside its module'
                                for line, text in found)


def test_scripts_and_tests_use_no_private_name_of_the_package():
    files = [p for folder in ('scripts', 'tests') for p in (REPO / folder).rglob('*.py')
             if '__pycache__' not in p.parts]
    assert len(files) > 50   # the folders were found
    problems = [f'{p.relative_to(REPO)}:{line} uses {text}'
                for p in files for line, text in private_uses(p.read_text(), '__main__')]
    assert not problems, '\n'.join(problems)
