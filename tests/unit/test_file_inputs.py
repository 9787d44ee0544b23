"""Bad route files, scenario files and launcher inputs: one line, the right exit code, no traceback.

1. files that are not UTF-8, not regular files (FIFO, directory, device) or too large are refused
   in one line naming the file (and the line of the first bad byte), without blocking;
2. generated routes are bounded (ship_planner.route_data MAX_ROUTE_LENGTH_M, MAX_ROUTE_SAMPLES):
   a circle of 1e9 degrees, a sine of 1e9 m or with a 1e-9 m step are refused at once, in one
   line with the line of the curve; curves within the bounds still load;
3. coordinates beyond MAX_COORDINATE_M (1e7 m) are refused in YAML routes and waypoint tables;
4. scenario names that would leave --runs, starts beyond the route's end and runs longer than
   vessel_node's step bound are refused (exit 2, before anything is created);
5. ``1e9`` (no dot) is a number in route and scenario files;
6. a node-parameter key no node declares is refused, naming the closest valid key; the valid
   keys are the packages' config/*.yaml lists;
7. a run folder that cannot be written (its parent a file, a read-only or a full file system)
   ends run_mission with one line naming the path and the OS error, and run.json is either
   whole or absent;
8. every YAML/JSON input goes through ship_sim.safe_load: an alias bomb is refused at once in
   bounded memory, nesting deeper than MAX_DEPTH, numbers longer than MAX_NUMBER_CHARS and keys
   given twice (both lines named) are refused in one line; FIFOs, devices and oversized files
   too; names that become ROS names are checked as ROS checks them;
9. a scenario's node sections (colav, guidance, autopilot) are checked by the nodes' own rules
   before anything starts (no run folder);
10. sweep files (episodes, names) and the command-line tools' numbers and output folders are
   refused in one line with exit code 2, leaving nothing behind.
"""
import os
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest
import yaml

from ship_mission.launcher import (RCLPY_PARAMETERS, MissionFailed, check_scenario, make_run_dir,
                              node_parameter_names,
                              write_run_json)
from ship_mission.scenario import MAX_STEPS, ScenarioError, load_scenario, load_scenarios
from ship_planner.route_loader import RouteError, load_route
from ship_planner.route_data import MAX_COORDINATE_M, MAX_ROUTE_LENGTH_M, MAX_ROUTE_SAMPLES
from ship_planner.yaml_route_reader import Loader, parse_route_yaml
from ship_sim.safe_load import (MAX_DEPTH, MAX_NODES, MAX_NUMBER_CHARS, InputError, TextFileError,
                                load_json, load_json_file, load_yaml, load_yaml_file, read_text_file)

ROOT = Path(__file__).resolve().parents[2]
ROUTE = ROOT / 'scenarios' / 'routes' / 'flagship_mariner.yaml'
HEAD = 'name: test\nsource: unit test\nframe: enu\n'


def route_error(text, filename='bad.yaml'):
    with pytest.raises(RouteError) as exc:
        parse_route_yaml(text, filename)
    msg = str(exc.value)
    assert '\n' not in msg and msg.startswith(filename), msg
    return exc.value


def scenario_file(tmp_path, extra_vessel='', name='t', top=''):
    text = (f'name: {name}\nsource: test\nduration_s: 100.0\n{top}vessels:\n  vessel_0:\n'
            f'    model: mariner\n    route: {ROUTE}\n')
    path = tmp_path / 'scenario.yaml'
    path.write_text(text + textwrap.indent(textwrap.dedent(extra_vessel), '    '))
    return path


def run_mission(*args, timeout=60):
    out = subprocess.run([sys.executable, str(ROOT / 'scripts' / 'run_mission.py'),
                          *map(str, args)], capture_output=True, text=True,
                         timeout=timeout, stdin=subprocess.DEVNULL)
    lines = [ln for ln in out.stderr.splitlines() if ln.strip()]
    assert 'Traceback' not in out.stderr + out.stdout, out.stderr
    return out.returncode, lines


# -- 1. unreadable files ---------------------------------------------------------------------------

@pytest.mark.parametrize('ext', ['.yaml', '.wpt'])
def test_non_utf8_route_file_is_refused_with_the_line_of_the_bad_byte(tmp_path, ext):
    path = tmp_path / f'latin1{ext}'
    path.write_bytes('name: x\n# caf\u00e9\n'.encode('latin-1'))
    with pytest.raises(RouteError) as exc:
        load_route(path)
    assert exc.value.file == str(path) and exc.value.line == 2
    assert 'UTF-8' in str(exc.value) and '\n' not in str(exc.value)


@pytest.mark.timeout(20)
@pytest.mark.parametrize('ext', ['.yaml', '.wpt'])
@pytest.mark.parametrize('kind', ['fifo', 'directory'])
def test_non_regular_route_files_are_refused_without_blocking(tmp_path, ext, kind):
    path = tmp_path / f'route{ext}'
    os.mkfifo(path) if kind == 'fifo' else path.mkdir()
    with pytest.raises(RouteError) as exc:
        load_route(path)      # a FIFO without a writer would block an ordinary open()
    assert exc.value.file == str(path)
    assert 'not a regular file' in str(exc.value) and kind.replace('fifo', 'FIFO') in str(exc.value)


def test_a_device_and_an_oversized_file_are_refused(tmp_path):
    with pytest.raises(TextFileError, match='character device'):
        read_text_file('/dev/zero')       # would never end
    big = tmp_path / 'big.yaml'
    big.write_text('#' * 100)
    with pytest.raises(TextFileError, match='larger than 99 bytes'):
        read_text_file(big, max_bytes=99)
    assert read_text_file(big, max_bytes=100) == '#' * 100


# -- 2. bounded curves -----------------------------------------------------------------------------

@pytest.mark.timeout(20)
@pytest.mark.parametrize('curve, bound', [
    ('{type: circle, center: [0, 0], radius_m: 100, start_bearing_deg: 0, sweep_deg: 1.0e+9, '
     'direction: clockwise}', 'length'),
    ('{type: circle, center: [0, 0], radius_m: 1.0e-3, start_bearing_deg: 0, sweep_deg: 1.0e+9, '
     'direction: clockwise}', 'samples'),
    ('{type: sine, length_m: 1e9, amplitude_m: 100, wavelength_m: 1000}', 'length'),
    ('{type: sine, length_m: 1000, amplitude_m: 100, wavelength_m: 1000, step_m: 1e-9}', 'samples'),
    # short waves: the base line is short, the curve itself is 2e6 m long
    ('{type: sine, length_m: 1000, amplitude_m: 500, wavelength_m: 1, step_m: 10}', 'length'),
    ('{type: spline, points: [[0, 0], [5000, 1000], [9000, 0]], step_m: 1e-6}', 'samples'),
])
def test_generated_routes_beyond_the_bounds_are_refused_at_once(curve, bound):
    text = HEAD + 'curve: ' + curve + '\n'
    err = route_error(text)
    assert err.line == 4 and 'curve' in err.detail
    want = f'{MAX_ROUTE_LENGTH_M:.0e} m' if bound == 'length' else str(MAX_ROUTE_SAMPLES)
    assert want in err.detail, err.detail


def test_curves_within_the_bounds_still_load():
    ten_turns = parse_route_yaml(HEAD + 'curve: {type: circle, center: [0, 0], radius_m: 500, '
                                 'start_bearing_deg: 0, sweep_deg: 3600, direction: port}\n')
    assert ten_turns.route.length == pytest.approx(10 * 2 * 3.141592653589793 * 500)
    sine = parse_route_yaml(HEAD + 'curve: {type: sine, length_m: 20000, amplitude_m: 100, '
                            'wavelength_m: 2000, step_m: 5}\n')
    assert 4000 < len(sine.route.legs) <= MAX_ROUTE_SAMPLES


def test_a_route_longer_than_the_bound_is_refused_whatever_its_form():
    far = MAX_ROUTE_LENGTH_M * 1.5
    err = route_error(HEAD + f'waypoints: [[0, 0], [{far}, 0]]\n')
    assert f'{MAX_ROUTE_LENGTH_M:.0e} m' in err.detail and err.line == 4


# -- 3. coordinates ----------------------------------------------------------------------------------

@pytest.mark.parametrize('body, line', [
    ('waypoints: [[0, 0], [1e308, 0]]\n', 4),
    ('waypoints:\n  - [0, 0]\n  - {x_m: 0, y_m: -2.0e+7}\n', 6),
    ('start: [0, 0]\nlegs:\n  - {course_deg: 10, length_m: 1.0e+308}\n', 6),
    ('start: [1.0e+300, 0]\nlegs:\n  - {course_deg: 10, length_m: 100}\n', 4),
])
def test_non_physical_coordinates_are_refused_in_route_files(body, line):
    err = route_error(HEAD + body)
    assert err.line == line and f'{MAX_COORDINATE_M:.0e} m' in err.detail, err


def test_large_but_physical_coordinates_are_accepted():
    x = 0.99 * MAX_COORDINATE_M
    plan = parse_route_yaml(HEAD + f'waypoints: [[{x}, {x}], [{x}, {x - 1000}]]\n')
    assert plan.route.length == pytest.approx(1000.0)


@pytest.mark.parametrize('row, unit', [('1e308 0 0 1 0 0 0 0', None), ('10 0 0 1 0 0 0 0', 2e6)])
def test_non_physical_coordinates_are_refused_in_waypoint_tables(tmp_path, row, unit):
    path = tmp_path / 'far.wpt'
    path.write_text(f'#@ name: far\n#@ source: test\n{row}\n')
    with pytest.raises(RouteError) as exc:
        load_route(path, length_unit_m=unit)
    assert exc.value.row == 1 and exc.value.line == 3
    assert f'{MAX_COORDINATE_M:.0e} m' in str(exc.value)


# -- 5. numbers without a dot ------------------------------------------------------------------------

def test_exponent_numbers_without_a_dot_are_numbers_in_route_files():
    a = parse_route_yaml(HEAD + 'curve: {type: sine, length_m: 5e3, amplitude_m: 1E2, '
                         'wavelength_m: 2000, step_m: 1e1}\n')
    b = parse_route_yaml(HEAD + 'curve: {type: sine, length_m: 5000.0, amplitude_m: 100.0, '
                         'wavelength_m: 2000, step_m: 10.0}\n')
    assert a.route.length == b.route.length and len(a.route.legs) == len(b.route.legs)


def test_the_loader_changes_nothing_but_exponent_numbers():
    data = yaml.load('a: 1e9\nb: -2E-3\nc: "1e9"\nd: e9\ne: 1.5\nf: 12\ng: 1_000\nh: .inf\n',
                     Loader=Loader)
    assert data['a'] == 1e9 and data['b'] == -2e-3
    assert data == {**yaml.safe_load('c: "1e9"\nd: e9\ne: 1.5\nf: 12\ng: 1_000\nh: .inf\n'),
                    'a': 1e9, 'b': -2e-3}


def test_exponent_numbers_without_a_dot_are_numbers_in_scenario_files(tmp_path):
    path = scenario_file(tmp_path, 'guidance: {lookahead_m: 3e2}\nspeed_mps: 7e0\n',
                         top='dt_s: 1e-1\n')
    sc = load_scenario(path)
    assert sc.dt_s == 0.1 and sc.vessels[0].speed == 7.0
    assert sc.vessels[0].guidance_params == {'lookahead_m': 300.0}


# -- 4. scenario checks ------------------------------------------------------------------------------

@pytest.mark.parametrize('name', ['../../escape', 'a/b', '..', '"a\\\\b"', '""', '"  "', '.'])
def test_scenario_names_that_would_leave_the_runs_folder_are_refused(tmp_path, name):
    path = scenario_file(tmp_path, name=name)
    with pytest.raises(ScenarioError) as exc:
        load_scenario(path)
    assert str(exc.value).startswith(f'{path}: name:') and '\n' not in str(exc.value)


def test_run_mission_refuses_an_escaping_name_before_creating_anything(tmp_path):
    runs = tmp_path / 'a' / 'b' / 'runs'
    path = scenario_file(tmp_path, name='../../escape')
    rc, lines = run_mission(path, '--runs', runs)
    assert rc == 2 and len(lines) == 1 and 'name' in lines[0] and str(path) in lines[0]
    assert list(tmp_path.rglob('escape*')) == [] and not runs.exists()


@pytest.mark.parametrize('along', [1.0e9, -1.0, 'end'])
def test_a_start_beyond_the_route_is_refused(tmp_path, along):
    length = load_route(ROUTE).route.length
    along = length if along == 'end' else along
    sc = load_scenario(scenario_file(tmp_path, f'start: {{along_m: {along!r}}}\n'))
    with pytest.raises(ScenarioError) as exc:
        check_scenario(sc)
    msg = str(exc.value)
    assert 'vessels.vessel_0.start.along_m' in msg and f'{length:.1f}' in msg, msg


@pytest.mark.parametrize('start', ['{x_m: 1.0e+308, y_m: 0.0}', '{along_m: 0.0, cross_m: -2.0e+7}'])
def test_a_non_physical_start_position_is_refused(tmp_path, start):
    path = scenario_file(tmp_path, f'start: {start}\n')
    with pytest.raises(ScenarioError) as exc:
        load_scenario(path)
    assert 'vessels.vessel_0.start.' in str(exc.value) and str(MAX_COORDINATE_M) in str(exc.value)


def test_a_start_on_the_route_is_accepted(tmp_path):
    check_scenario(load_scenario(scenario_file(tmp_path, 'start: {along_m: 100.0}\n')))


def test_a_run_beyond_the_vessel_nodes_step_bound_is_refused(tmp_path):
    too_long = MAX_STEPS * 0.1 * 10
    sc = load_scenario(scenario_file(tmp_path, top='dt_s: 0.1\n'))
    sc.duration_s = too_long
    with pytest.raises(ScenarioError, match='duration_s'):
        check_scenario(sc)
    sc.duration_s = MAX_STEPS * 0.1 * 0.5
    check_scenario(sc)


@pytest.mark.parametrize('where', ['file', 'option'])
def test_run_mission_exits_2_for_a_run_beyond_the_step_bound(tmp_path, where):
    path = scenario_file(tmp_path, top='dt_s: 0.1\n')
    if where == 'file':
        path.write_text(path.read_text().replace('duration_s: 100.0', 'duration_s: 1e12'))
        extra = []
    else:
        extra = ['--duration', repr(MAX_STEPS * 0.1 * 10)]
    rc, lines = run_mission(path, '--runs', tmp_path / 'runs', *extra)
    assert rc == 2 and len(lines) == 1 and 'duration_s' in lines[0], lines
    assert not (tmp_path / 'runs').exists()


# -- 6. node parameter keys --------------------------------------------------------------------------

@pytest.mark.parametrize('block, key, package, node, near', [
    ('guidance', 'lookahed_m', 'ship_guidance', 'guidance_node', 'lookahead_m'),
    ('vessel', 'curent_speed', 'ship_sim', 'vessel_node', 'current_speed'),
    ('autopilot', 'omega', 'ship_autopilot', 'autopilot_node', 'omega_n'),
])
def test_an_undeclared_node_parameter_is_refused_with_the_closest_one(tmp_path, block, key,
                                                                       package, node, near):
    assert near in node_parameter_names(package, node)
    path = scenario_file(tmp_path, f'{block}: {{{key}: 1.0}}\n')
    sc = load_scenario(path)
    with pytest.raises(ScenarioError) as exc:
        check_scenario(sc)
    msg = str(exc.value)
    assert f'vessels.vessel_0.{block}.{key}' in msg and node in msg and f'"{near}"' in msg, msg
    rc, lines = run_mission(path, '--runs', tmp_path / 'runs')
    assert rc == 2 and lines == [f'run_mission: {msg}']


@pytest.mark.parametrize('package, node', [('ship_sim', 'vessel_node'),
                                           ('ship_guidance', 'guidance_node'),
                                           ('ship_guidance', 'follower_node'),
                                           ('ship_autopilot', 'autopilot_node'),
                                           ('ship_planner', 'route_node')])
def test_the_valid_keys_are_the_packages_config_lists(package, node):
    cfg = ROOT / 'ros_ws' / 'src' / package / 'config' / (node.removesuffix('_node') + '.yaml')
    listed = set(yaml.safe_load(cfg.read_text())['/**']['ros__parameters'])
    names = node_parameter_names(package, node)
    assert listed | set(RCLPY_PARAMETERS) <= names
    from ship_sim.param_schema import node_schema
    renamed = set(node_schema(package, node).renamed())   # deprecated names, still taken
    for extra in names - listed - set(RCLPY_PARAMETERS) - renamed:   # lists without a default
        assert f'{extra}: [' in cfg.read_text()


#: every shipped scenario: a plain file's one, each of a matrix file's (ship_mission.matrix)
SCENARIOS = [s for f in sorted((ROOT / 'scenarios').glob('*.yaml')) for s in load_scenarios(f)]


@pytest.mark.parametrize('scenario', SCENARIOS, ids=[s.name for s in SCENARIOS])
def test_every_shipped_scenario_passes_the_launchers_check(scenario):
    check_scenario(scenario)


def test_every_key_of_the_config_lists_passes_the_check(tmp_path):
    path = scenario_file(tmp_path, 'guidance: {law: ilos, lookahead_m: 800.0, use_sim_time: true}\n'
                                   'autopilot: {controller: pd}\nvessel: {depth: 30.0}\n')
    check_scenario(load_scenario(path))


# -- 1 (scenarios) -----------------------------------------------------------------------------------

@pytest.mark.timeout(60)
@pytest.mark.parametrize('kind', ['latin1', 'fifo', 'directory'])
def test_run_mission_refuses_unreadable_scenario_files_in_one_line(tmp_path, kind):
    path = tmp_path / 'scenario.yaml'
    if kind == 'latin1':
        path.write_bytes(b'name: t\nsource: caf\xe9\n')
    elif kind == 'fifo':
        os.mkfifo(path)
    else:
        path.mkdir()
    rc, lines = run_mission(path, '--runs', tmp_path / 'runs')
    assert rc == 2 and len(lines) == 1 and str(path) in lines[0], lines
    if kind == 'latin1':
        assert f'{path}:2:' in lines[0] and 'UTF-8' in lines[0]


def test_run_mission_refuses_a_scenario_whose_route_is_not_utf8(tmp_path):
    route = tmp_path / 'route.yaml'
    route.write_bytes(ROUTE.read_bytes() + b'# \xff\n')
    path = scenario_file(tmp_path)
    path.write_text(path.read_text().replace(str(ROUTE), str(route)))
    rc, lines = run_mission(path, '--runs', tmp_path / 'runs')
    assert rc == 2 and len(lines) == 1 and 'vessels.vessel_0.route' in lines[0]
    assert str(route) in lines[0] and 'UTF-8' in lines[0]


# -- 7. disk faults ----------------------------------------------------------------------------------

class _Scenario:
    name = 'disk'


@pytest.fixture
def tmpfs(tmp_path):
    """mount(options) -> a fresh tmpfs mount point (root only; skipped elsewhere)."""
    mounted = []

    def mount(options):
        point = tmp_path / f'mnt{len(mounted)}'
        point.mkdir()
        r = subprocess.run(['mount', '-t', 'tmpfs', '-o', options, 'tmpfs', str(point)],
                           capture_output=True, text=True)
        if r.returncode != 0:
            pytest.skip(f'cannot mount a tmpfs here: {r.stderr.strip()}')
        mounted.append(point)
        return point

    yield mount
    for point in reversed(mounted):
        subprocess.run(['umount', '-l', str(point)], capture_output=True)


def test_a_run_folder_under_a_file_is_one_line_naming_the_path(tmp_path):
    blocker = tmp_path / 'not_a_dir'
    blocker.write_text('')
    with pytest.raises(MissionFailed) as exc:
        make_run_dir(_Scenario(), blocker / 'runs')
    assert str(blocker) in str(exc.value) and os.strerror(20) in str(exc.value)
    rc, lines = run_mission(scenario_file(tmp_path), '--runs', blocker / 'runs')
    assert rc == 1 and len(lines) == 1 and str(blocker) in lines[0], lines
    assert os.strerror(20) in lines[0]


def test_a_read_only_runs_folder_is_one_line_naming_the_path(tmp_path, tmpfs):
    ro = tmpfs('ro,size=1m')
    rc, lines = run_mission(scenario_file(tmp_path), '--runs', ro)
    assert rc == 1 and len(lines) == 1 and str(ro) in lines[0], lines
    assert os.strerror(30) in lines[0]     # EROFS


def test_run_json_on_a_full_disk_is_whole_or_absent(tmpfs):
    disk = tmpfs('size=2m')
    run = make_run_dir(_Scenario(), disk / 'runs')
    write_run_json(run, {'outcome': 'first'})
    with open(disk / 'filler', 'wb', buffering=0) as f:       # fill the file system
        try:
            while True:
                f.write(b'\0' * 65536)
        except OSError:
            pass
    with pytest.raises(MissionFailed) as exc:
        write_run_json(run, {'outcome': 'second', 'pad': 'x' * 200_000})
    msg = str(exc.value)
    assert str(run / 'run.json') in msg and os.strerror(28) in msg and '\n' not in msg
    assert yaml.safe_load((run / 'run.json').read_text()) == {'outcome': 'first'}
    assert sorted(p.name for p in run.iterdir()) == ['params', 'run.json']


# -- 8. the bounded loader (ship_sim.safe_load): every YAML/JSON input ------------------------------

def _bomb(levels=9, width=9):
    """A YAML 'billion laughs': ``levels`` anchors of ``width`` aliases of the one before; it
    stands for width**levels values in a file of a few hundred bytes."""
    lines = ['l0: &l0 [' + ', '.join(['lol'] * width) + ']']
    lines += [f'l{i}: &l{i} [' + ', '.join([f'*l{i - 1}'] * width) + ']'
              for i in range(1, levels)]
    return '\n'.join(lines) + '\n'


def _one_line(exc):
    msg = str(exc)
    assert '\n' not in msg and 'Traceback' not in msg, msg
    return msg


@pytest.mark.timeout(20)
def test_an_alias_bomb_is_refused_fast_in_bounded_memory():
    import time
    import tracemalloc
    text = _bomb()
    assert 9 ** 9 > 100 * MAX_NODES and len(text) < 1000
    tracemalloc.start()
    t0 = time.perf_counter()
    with pytest.raises(InputError) as exc:
        load_yaml(text, 'bomb.yaml')
    wall = time.perf_counter() - t0
    peak = tracemalloc.get_traced_memory()[1]
    tracemalloc.stop()
    msg = _one_line(exc.value)
    assert msg.startswith('bomb.yaml:') and str(MAX_NODES) in msg and 'alias' in msg
    # Refused before expanding: the parser saw at most MAX_NODES values' worth of aliases and
    # built only the file's own few dozen nodes (each under 1 kB).
    assert peak < 10_000_000, peak
    assert wall < 5.0, wall


def test_anchors_aliases_and_merge_keys_within_the_bounds_still_load():
    data = load_yaml('base: &b {x: 1.0, y: 2.0}\na: *b\nc: {<<: *b, y: 3.0}\nl: [*b, *b]\n')
    assert data['a'] == {'x': 1.0, 'y': 2.0} and data['c'] == {'x': 1.0, 'y': 3.0}
    assert data['l'] == [data['a']] * 2
    small = load_yaml(_bomb(levels=3, width=9))      # 9**3 values: well within the bound
    assert len(small['l2']) == 9 and small['l2'][0] == small['l1']


@pytest.mark.parametrize('text', ['a: &a [1, *a]\n', 'a: &a {b: *a}\n'])
def test_a_recursive_alias_is_refused(text):
    with pytest.raises(InputError, match='inside its own anchor') as exc:
        load_yaml(text, 'r.yaml')
    assert exc.value.line == 1


@pytest.mark.parametrize('kind', ['yaml', 'json'])
def test_nesting_beyond_the_bound_is_refused_and_within_it_loads(kind):
    def nested(n):
        return '[' * n + '1' + ']' * n
    load = load_yaml if kind == 'yaml' else load_json
    assert load(nested(MAX_DEPTH - 1)) is not None
    with pytest.raises(InputError) as exc:
        load(nested(10_000))        # without the bound: a RecursionError
    assert f'deeper than {MAX_DEPTH} levels' in _one_line(exc.value)
    if kind == 'yaml':              # an alias that takes a shallow tree deeper counts too
        half = nested(MAX_DEPTH // 2 + 1)
        with pytest.raises(InputError, match='aliases expanded'):
            load_yaml(f'a: &a {half}\nb: [{"[" * (MAX_DEPTH // 2)}*a{"]" * (MAX_DEPTH // 2)}]\n')


@pytest.mark.parametrize('kind', ['yaml', 'json'])
@pytest.mark.parametrize('number', ['9' * 5000, '1.' + '5' * 5000, '-' + '7' * 200 + 'e3'])
def test_a_number_beyond_the_length_bound_is_refused(kind, number):
    text = f'a: {number}\n' if kind == 'yaml' else f'{{"a": {number}}}'
    load = load_yaml if kind == 'yaml' else load_json
    with pytest.raises(InputError) as exc:
        load(text, 'n')
    assert f'a number of {len(number)} characters' in _one_line(exc.value)
    assert load(text.replace(number, '1' * MAX_NUMBER_CHARS))['a'] == int('1' * MAX_NUMBER_CHARS)


def test_a_key_given_twice_is_refused_naming_the_key_and_both_lines():
    with pytest.raises(InputError) as exc:
        load_yaml('a: 1\nb:\n  c: 2\n  d: 3\n  c: 4\n', 'd.yaml')
    assert exc.value.line == 5 and 'key "c"' in str(exc.value) and 'lines 3 and 5' in str(exc.value)
    with pytest.raises(InputError, match='key "a" is given twice, on lines 1 and 1'):
        load_yaml('{a: 1, a: 2}')
    with pytest.raises(InputError, match='key "a" is given twice'):
        load_json('{"a": 1, "a": 2}')


@pytest.mark.parametrize('body, key, first, second', [
    ('duration_s: 50.0\n', 'duration_s', 3, 4),
    ('  vessel_0:\n    model: mariner\n    route: {route}\n', 'vessel_0', 5, 8),
])
def test_run_mission_refuses_a_scenario_with_a_key_given_twice(tmp_path, body, key, first, second):
    path = scenario_file(tmp_path)
    text = path.read_text()
    if key == 'duration_s':
        text = text.replace('duration_s: 100.0\n', 'duration_s: 100.0\n' + body)
    else:
        text += body.format(route=ROUTE)
    path.write_text(text)
    with pytest.raises(ScenarioError) as exc:
        load_scenario(path)
    msg = _one_line(exc.value)
    assert msg.startswith(f'{path}:{second}:') and f'key "{key}"' in msg
    assert f'lines {first} and {second}' in msg
    rc, lines = run_mission(path, '--runs', tmp_path / 'runs')
    assert rc == 2 and lines == [f'run_mission: {msg}'] and not (tmp_path / 'runs').exists()


@pytest.mark.timeout(60)
def test_run_mission_refuses_an_alias_bomb_scenario_at_once(tmp_path):
    import time
    path = tmp_path / 'bomb.yaml'
    path.write_text(_bomb() + 'name: t\nsource: x\n')
    # run_mission in a child that reports its own peak memory (kB) last, whatever its exit
    # (VmHWM, not ru_maxrss: Linux keeps ru_maxrss across exec, so a child of a large pytest
    # process would report the parent's peak; VmHWM belongs to the new address space.)
    report = ('import runpy, sys\nsys.argv = sys.argv[1:]\ntry:\n'
              '    runpy.run_path(sys.argv[0], run_name="__main__")\nfinally:\n'
              '    hwm = [ln for ln in open("/proc/self/status") if ln.startswith("VmHWM")]\n'
              '    print(hwm[0].split()[1], file=sys.stderr)\n')
    t0 = time.perf_counter()
    out = subprocess.run([sys.executable, '-c', report, str(ROOT / 'scripts' / 'run_mission.py'),
                          str(path), '--runs', str(tmp_path / 'runs')], capture_output=True,
                         text=True, timeout=50, stdin=subprocess.DEVNULL)
    wall = time.perf_counter() - t0
    *lines, peak_kb = [ln for ln in out.stderr.splitlines() if ln.strip()]
    assert out.returncode == 2 and len(lines) == 1, out.stderr
    assert str(MAX_NODES) in lines[0] and str(path) in lines[0] and 'Traceback' not in out.stderr
    # The expansion (9**9 values) would take tens of GB; the child's peak is the interpreter's
    # and its imports (well under 1 GB), and it answers in seconds, not never.
    assert int(peak_kb) < 1_000_000 and wall < 30.0, (peak_kb, wall)
    assert not (tmp_path / 'runs').exists()


@pytest.mark.timeout(20)
@pytest.mark.parametrize('loader', ['yaml', 'json'])
def test_file_loaders_refuse_fifos_devices_and_oversized_files(tmp_path, loader):
    load = load_yaml_file if loader == 'yaml' else load_json_file
    fifo = tmp_path / 'fifo'
    os.mkfifo(fifo)
    for path, what in ((fifo, 'FIFO'), ('/dev/zero', 'character device'), (tmp_path, 'directory')):
        with pytest.raises(InputError) as exc:
            load(path)
        msg = _one_line(exc.value)
        assert msg.startswith(f'{path}: cannot read: it is ') and what in msg
    big = tmp_path / 'big'
    big.write_text('[' + '0, ' * 50 + '0]')
    with pytest.raises(InputError, match='larger than 100 bytes'):
        load(big, max_bytes=100)
    assert load(big, max_bytes=1000) == [0] * 51


def test_traffic_targets_parameter_is_bounded():
    from ship_sim.light_traffic import parse_targets
    for text, needle in (('[' * 5000 + ']' * 5000, f'deeper than {MAX_DEPTH}'),
                         ('[{"name": "a", "x_m": ' + '9' * 5000 + '}]', 'a number of 5000'),
                         ('[{"name": "a", "name": "b"}]', 'key "name" is given twice')):
        with pytest.raises(ValueError) as exc:
            parse_targets(text)
        assert needle in _one_line(exc.value) and str(exc.value).startswith('light targets:')


@pytest.mark.parametrize('name', ['ta\u00efget', '\u03a9mega', '2nd'])
def test_a_light_target_name_that_is_no_ros_name_is_refused_naming_it(tmp_path, name):
    if not name[0].isdigit():
        assert name.isidentifier()      # what the former check let through
    path = scenario_file(tmp_path)
    path.write_text(path.read_text() + f'traffic:\n  {name}:\n    light: {{course_deg: 0.0, '
                    'speed_mps: 5.0}\n')
    with pytest.raises(ScenarioError) as exc:
        load_scenario(path)
    msg = _one_line(exc.value)
    assert f'traffic.{name}' in msg and f"'{name}' is not a ROS name" in msg


# -- 9. node sections checked by the nodes' rules before anything starts -----------------------------

@pytest.mark.parametrize('block, needle', [
    ('colav: {method: magic}', "colav.method: parameter 'method' = 'magic' is not allowed: one of"),
    ('colav: {d_safe_m: -5.0}', 'colav.d_safe_m:'),
    ('colav: {d_safe_m: 900}', 'colav.d_safe_m:'),               # an int for a float parameter
    ('colav: {d_safe_m: 100.0}', 'colav: colav parameters: need 0 < collision_m'),
    ('colav: {speed_factors: [0.5]}', 'speed_factors 1'),
    ('guidance: {law: magic}', "guidance.law: parameter 'law' = 'magic'"),
    ('guidance: {lookahead_m: fast}', 'guidance.lookahead_m:'),
    ('autopilot: {vessel_model: boat}', 'autopilot.vessel_model:'),
])
def test_node_sections_are_checked_before_launch_without_a_run_folder(tmp_path, block, needle):
    path = scenario_file(tmp_path, block + '\n')
    with pytest.raises(ScenarioError) as exc:
        check_scenario(load_scenario(path))
    assert needle in _one_line(exc.value) and 'vessels.vessel_0.' in str(exc.value)
    if 'magic' in block and 'colav' in block:
        rc, lines = run_mission(path, '--runs', tmp_path / 'runs')
        assert rc == 2 and len(lines) == 1 and needle in lines[0], lines
        assert not (tmp_path / 'runs').exists()


def test_valid_node_sections_pass_the_check(tmp_path):
    path = scenario_file(tmp_path, 'colav: {method: vo, d_safe_m: 900.0}\n'
                                   'guidance: {law: ilos, lookahead_m: 800.0}\n'
                                   'autopilot: {vessel_model: mariner}\n')
    check_scenario(load_scenario(path))


# -- 10. sweep files and command-line tools ------------------------------------------------------------

def _sweep_file(tmp_path, top):
    path = tmp_path / 'sweep.yaml'
    path.write_text(top + 'base: {model: mariner, duration_s: 10}\n')
    return path


def _cli(script, *args, timeout=60):
    out = subprocess.run([sys.executable, str(ROOT / 'scripts' / script), *map(str, args)],
                         capture_output=True, text=True, timeout=timeout,
                         stdin=subprocess.DEVNULL)
    assert 'Traceback' not in out.stderr + out.stdout, out.stderr
    return out.returncode, [ln for ln in out.stderr.splitlines() if ln.strip()]


@pytest.mark.timeout(60)
@pytest.mark.parametrize('top, needle', [
    ('episodes: 1000000000000\n', 'episodes must be an integer in [1, '),
    ('episodes: 1000\nvary: {start_cross_m: [' + ', '.join(['0.0'] * 300) + ']}\n', 'at most'),
    ('name: ".."\n', "name must be a plain file name"),
    ('name: "."\n', "name must be a plain file name"),
    ('name: "a/b"\n', "name must be a plain file name"),
    ('name: "-rf"\n', 'must not start with a dot or a dash'),
    ('name: ".hidden"\n', 'must not start with a dot or a dash'),
    ('name: "a\\tb"\n', 'control characters'),
    ('seed: 1\nseed: 2\n', 'key "seed" is given twice, on lines 1 and 2'),
    ('vary: {start_cross_m: ' + '[' * 100 + ']' * 100 + '}\n', f'deeper than {MAX_DEPTH}'),
])
def test_sweep_refuses_bad_files_in_one_line_before_creating_anything(tmp_path, top, needle):
    from montecarlo.spec import MAX_EPISODES
    path = _sweep_file(tmp_path, top)
    out = tmp_path / 'out'
    rc, lines = _cli('sweep.py', path, '--out', out, '--no-plots')
    assert rc == 2 and len(lines) == 1 and needle in lines[0], lines
    assert not out.exists()
    if 'at most' in needle:
        assert str(MAX_EPISODES) in lines[0]


@pytest.mark.timeout(60)
@pytest.mark.parametrize('args, needle', [
    (['--episodes', '1000000000000'], '--episodes'),
    (['--duration', 'nan'], '--duration'),
    (['--workers', '0'], '--workers'),
    (['--out', '{file}'], 'exists and is not a folder'),
])
def test_sweep_refuses_bad_arguments_in_one_line(tmp_path, args, needle):
    path = _sweep_file(tmp_path, 'episodes: 1\n')
    out = tmp_path / 'out'
    args = [a.replace('{file}', str(path)) for a in args]
    if '--out' not in args:
        args += ['--out', str(out)]
    rc, lines = _cli('sweep.py', path, *args, '--no-plots')
    assert rc == 2 and len(lines) == 1 and needle in lines[0], lines
    assert sorted(p.name for p in tmp_path.iterdir()) == ['sweep.yaml']


@pytest.mark.timeout(60)
@pytest.mark.parametrize('args, needle', [
    (['--duration', 'nan'], '--duration'),
    (['--duration', '-5'], '--duration'),
    (['--duration', '0'], '--duration'),
    (['--duration', 'inf'], '--duration'),
    (['--jobs', '100000'], '--jobs'),
    (['--jobs', '0'], '--jobs'),
    (['--out', '{file}'], 'exists and is not a folder'),
    (['--out', '{file}/sub'], 'exists and is not a folder'),
])
def test_imazu_benchmark_refuses_bad_arguments_leaving_nothing(tmp_path, args, needle):
    blocker = tmp_path / 'a_file'
    blocker.write_text('')
    out = tmp_path / 'results'
    args = [a.replace('{file}', str(blocker)) for a in args]
    if '--out' not in args:
        args += ['--out', str(out)]
    rc, lines = _cli('imazu_benchmark.py', '--quick', '--no-plots', *args)
    assert rc == 2 and len(lines) == 1 and needle in lines[0], lines
    assert not out.exists() and sorted(p.name for p in tmp_path.iterdir()) == ['a_file']


@pytest.mark.timeout(60)
@pytest.mark.parametrize('script, args, needle', [
    ('run_mission.py', ['{scenario}', '--duration', 'nan'], '--duration'),
    ('run_mission.py', ['{scenario}', '--wall-timeout', '-1'], '--wall-timeout'),
    ('run_mission.py', ['{scenario}', '--domain-id', '999'], '--domain-id'),
    ('run_mission.py', ['{scenario}', '--live-port', '70000'], '--live-port'),
    ('make_ais_replay.py', ['{out}', '--mmsi', '1', '--origin', '63', '10', '--light', '{}',
                            '--period', '0', '--duration', '60'], '--period'),
    ('make_ais_replay.py', ['{out}', '--mmsi', '1', '--origin', '63', '10', '--light', '{}',
                            '--duration', '1e12'], '--duration'),
    ('make_ais_replay.py', ['{out}', '--mmsi', '1', '--origin', 'nan', '10', '--light', '{}',
                            '--duration', '60'], '--origin'),
    ('make_ais_replay.py', ['{out}', '--mmsi', '1', '--origin', '63', '10', '--light',
                            '[' * 1000 + ']' * 1000, '--duration', '60'], 'deeper than'),
    ('encounter_report.py', ['{out}'], 'no such file'),
])
def test_cli_number_and_input_refusals_are_one_line(tmp_path, script, args, needle):
    out = tmp_path / 'out.nmea'
    args = [a.replace('{scenario}', str(scenario_file(tmp_path))).replace('{out}', str(out))
            for a in args]
    rc, lines = _cli(script, *args)
    assert rc == 2 and len(lines) == 1 and needle in lines[0], lines
    assert not out.exists() and not (tmp_path / 'runs').exists()


@pytest.mark.timeout(20)
def test_chart_files_that_are_not_regular_or_too_large_are_refused_before_reading(tmp_path):
    from PIL import Image

    from ship_planner.chart import ChartError, image_chart
    fifo = tmp_path / 'chart.png'
    os.mkfifo(fifo)
    with pytest.raises(ChartError, match='FIFO') as exc:
        image_chart(fifo, 10.0)           # PIL would wait for a writer
    _one_line(exc.value)
    big = tmp_path / 'big.png'
    Image.new('1', (4000, 3000), 1).save(big)     # a few kB on disk, 12 million cells
    with pytest.raises(ChartError, match='4000 = 12,000,000 cells'):
        image_chart(big, 10.0, max_cells=1_000_000)
    assert image_chart(big, 10.0, max_cells=12_000_000).water.all()


@pytest.mark.timeout(120)
@pytest.mark.parametrize('script, args', [
    ('evaluate_controllers.py', ['--duration', 'nan']),
    ('evaluate_controllers.py', ['--jobs', '100000']),
    ('wave_filter_comparison.py', ['--duration', '-1']),
    ('replay_bag.py', ['{out}', '--settle', 'inf']),
    ('run_seed_scenarios.py', ['--wall-timeout', 'nan']),
    ('wind_study.py', ['--speeds', '1e9']),
])
def test_other_tools_refuse_bad_numbers_in_one_line(tmp_path, script, args):
    out = tmp_path / 'out'
    option = next(a for a in args if a.startswith('--'))
    rc, lines = _cli(script, *[a.replace('{out}', str(out)) for a in args])
    assert rc == 2 and len(lines) == 1 and f'argument {option}:' in lines[0], lines
    assert list(tmp_path.iterdir()) == []
