"""Start and stop node processes from the colcon install tree, the way `ros2 run` would.

`ros2 run P E` finds package P through the ament index under AMENT_PREFIX_PATH and runs
`<prefix>/lib/P/E`. We compute the environment that sourcing `install/setup.bash` would give
(AMENT_PREFIX_PATH, PYTHONPATH) instead of sourcing bash, so the launcher and the tests need no
shell and no ros2 CLI. Every process gets its own session (process group) so it can be stopped
with all its children; `ProcessGroup.stop()` escalates SIGINT -> SIGTERM -> SIGKILL and is safe to
call twice, from `finally:` blocks and signal handlers alike. Every process also gets SIGTERM
when the process that started it dies, even by SIGKILL (Linux's parent-death signal), so a
killed launcher leaves no orphans, and the recorder, which finalises its bag on SIGTERM, a
readable bag.
"""
import ctypes
import math
import os
import re
import signal
import subprocess
import time
from pathlib import Path


def _install_tree(here=Path(__file__).resolve()):
    """The colcon install tree this package runs with: the one it is installed in
    (<install>/ship_mission/lib/python3.X/site-packages/ship_mission/, found by colcon's marker
    file), else the checkout's ros_ws/install (the package imported from its source folder,
    ros_ws/src/ship_mission/ship_mission/)."""
    for parent in here.parents:
        if (parent / '.colcon_install_layout').is_file():
            return parent
    return here.parents[3] / 'install'


INSTALL = _install_tree()
#: The checkout the install tree was built in (runs/ and scripts/ live there).
REPO = INSTALL.parents[1]


def _package_prefixes(install=INSTALL):
    """{package: prefix} of an isolated colcon install, in dependency order (deps first)."""
    pkgs = {}
    for marker in sorted(install.glob('*/share/colcon-core/packages/*')):
        prefix = marker.parents[3]
        if marker.name == prefix.name:
            deps = [d for d in marker.read_text().strip().split(':') if d]
            pkgs[marker.name] = (prefix, deps)
    order, seen = [], set()

    def visit(name):
        if name in seen or name not in pkgs:
            return
        seen.add(name)
        for dep in pkgs[name][1]:
            visit(dep)
        order.append(name)

    for name in sorted(pkgs):
        visit(name)
    return {name: pkgs[name][0] for name in order}


def _apply_dsv(env, prefix, dsv):
    """Apply one colcon .dsv file (the subset colcon's python packages write) to env."""
    for line in dsv.read_text().splitlines():
        parts = line.strip().split(';')
        if len(parts) < 2:
            continue
        kind, rest = parts[0], parts[1:]
        if kind == 'source':
            path = prefix / rest[0]
            if path.suffix == '.dsv' and path.exists():
                _apply_dsv(env, prefix, path)
        elif kind in ('prepend-non-duplicate', 'prepend-non-duplicate-if-exists'):
            var, values = rest[0], rest[1:] or ['']
            for sub in reversed(values):
                value = str(prefix / sub) if sub else str(prefix)
                if kind.endswith('if-exists') and not Path(value).exists():
                    continue
                old = [v for v in env.get(var, '').split(os.pathsep) if v and v != value]
                env[var] = os.pathsep.join([value] + old)
        elif kind == 'set':
            env[rest[0]] = rest[1] if len(rest) > 1 else ''
        elif kind == 'set-if-unset':
            env.setdefault(rest[0], rest[1] if len(rest) > 1 else '')


# Fast DDS confined to 127.0.0.1 (doc/security.md): UDPv4 with an interface whitelist, plus
# shared memory, builtin transports off. Fast DDS 2.14 (the Jazzy wheels) reads the file named by
# FASTRTPS_DEFAULT_PROFILES_FILE; FASTDDS_DEFAULT_PROFILES_FILE is only read from Fast DDS 3.
LOOPBACK_PROFILE = Path(__file__).resolve().with_name('fastdds_loopback.xml')


def is_loopback_profile(path):
    """True if ``path`` names LOOPBACK_PROFILE or a copy of it: a launcher from the install tree
    has its own copy of the file a test or a source-tree launcher set."""
    try:
        return bool(path) and Path(path).read_bytes() == LOOPBACK_PROFILE.read_bytes()
    except OSError:
        return False


def install_env(base_env=None, install=INSTALL, domain_id=None, localhost_only=True,
                loopback_only=False):
    """The environment ``source install/setup.bash`` gives (colcon's .dsv files applied), plus
    an optional ROS_DOMAIN_ID and localhost-only discovery.

    ``loopback_only`` (also on when the base environment already names LOOPBACK_PROFILE, as the
    integration tests do) selects that profile and ROS_AUTOMATIC_DISCOVERY_RANGE=SYSTEM_DEFAULT:
    the profile's own discovery is unicast to 127.0.0.1, and the LOCALHOST range would make
    rmw_fastrtps add a locator on every address again."""
    env = dict(os.environ if base_env is None else base_env)
    if not (install / 'setup.bash').exists():
        raise FileNotFoundError(f'no colcon install tree at {install}: run `make build`')
    old = [v for v in env.get('COLCON_PREFIX_PATH', '').split(os.pathsep)
           if v and v != str(install)]
    env['COLCON_PREFIX_PATH'] = os.pathsep.join([str(install)] + old)
    for name, prefix in _package_prefixes(install).items():
        dsv = prefix / 'share' / name / 'package.dsv'
        if dsv.exists():
            _apply_dsv(env, prefix, dsv)
    if domain_id is not None:
        env['ROS_DOMAIN_ID'] = str(domain_id)
    if localhost_only:
        env['ROS_AUTOMATIC_DISCOVERY_RANGE'] = 'LOCALHOST'
    if loopback_only or is_loopback_profile(env.get('FASTRTPS_DEFAULT_PROFILES_FILE')):
        env['FASTRTPS_DEFAULT_PROFILES_FILE'] = str(LOOPBACK_PROFILE)
        env['ROS_AUTOMATIC_DISCOVERY_RANGE'] = 'SYSTEM_DEFAULT'
    env['PYTHONUNBUFFERED'] = '1'
    return env


def executable(package, name, install=INSTALL):
    """Path of ``ros2 run package name``: <prefix>/lib/<package>/<name>, checked."""
    path = install / package / 'lib' / package / name
    if not (path.is_file() and os.access(path, os.X_OK)):
        raise FileNotFoundError(f'{package}/{name} is not installed at {path}: run `make build`')
    return path


def format_param(value):
    """A Python value as the YAML text `-p name:=value` expects."""
    if isinstance(value, bool):
        return 'true' if value else 'false'
    if isinstance(value, int):
        return str(value)
    if isinstance(value, float):
        if math.isnan(value):
            return '.nan'
        if math.isinf(value):
            return '.inf' if value > 0 else '-.inf'
        # a '.' in the mantissa, so that YAML 1.1 readers too take 1e-05 as a float (1.0e-05)
        mantissa, e, exponent = repr(value).partition('e')
        return mantissa + ('' if '.' in mantissa else '.0') + e + exponent
    if isinstance(value, (list, tuple)):
        return '[' + ', '.join(format_param(v) for v in value) + ']'
    text = str(value)
    # Quote strings YAML would read as something else (numbers, booleans, empty, null).
    if (text == '' or re.fullmatch(r'[-+]?(\d+\.?\d*([eE][-+]?\d+)?|\.\d+|\.nan|\.inf)', text)
            or text.lower() in ('true', 'false', 'yes', 'no', 'on', 'off', 'null', '~')):
        return "'" + text.replace("'", "''") + "'"
    return text


def ros_args(namespace=None, params=None, node_name=None, log_level=None):
    """`--ros-args` for a namespace, a node name and parameters (values as YAML literals)."""
    args = ['--ros-args']
    if namespace:
        args += ['-r', f'__ns:={namespace}']
    if node_name:
        args += ['-r', f'__node:={node_name}']
    for key, value in (params or {}).items():
        args += ['-p', f'{key}:={format_param(value)}']
    if log_level:
        args += ['--log-level', log_level]
    return args


PR_SET_PDEATHSIG = 1


def die_with_parent():
    """In a child before exec: SIGTERM when its parent dies (PR_SET_PDEATHSIG; Linux).

    The signal follows the thread that forked, so start processes from the main thread."""
    libc = ctypes.CDLL('libc.so.6', use_errno=True)
    libc.prctl(PR_SET_PDEATHSIG, signal.SIGTERM)
    if os.getppid() == 1:   # the parent died before prctl took effect
        os.kill(os.getpid(), signal.SIGTERM)


class NodeProcess:
    """One node process with its output in a log file."""

    def __init__(self, label, argv, env, log_dir):
        self.label = label
        self.argv = [str(a) for a in argv]
        log_dir = Path(log_dir)
        log_dir.mkdir(parents=True, exist_ok=True)
        self.log_path = log_dir / f"{label.strip('/').replace('/', '.')}.log"
        self._log = open(self.log_path, 'wb')
        self.popen = subprocess.Popen(self.argv, env=env, stdout=self._log, stderr=subprocess.STDOUT,
                                      stdin=subprocess.DEVNULL, start_new_session=True,
                                      preexec_fn=die_with_parent)

    @property
    def returncode(self):
        return self.popen.poll()

    def signal(self, sig):
        if self.popen.poll() is None:
            try:
                os.killpg(self.popen.pid, sig)
            except ProcessLookupError:
                pass

    def wait(self, timeout):
        try:
            return self.popen.wait(timeout)
        except subprocess.TimeoutExpired:
            return None

    def output(self):
        self._log.flush()
        return self.log_path.read_text(errors='replace')

    def close(self):
        self._log.close()


class ProcessGroup:
    """The processes of one run; stops all of them, always, in reverse start order."""

    def __init__(self, env, log_dir):
        self.env = env
        self.log_dir = Path(log_dir)
        self.procs = []

    def start(self, label, package, exe, args=()):
        proc = NodeProcess(label, [executable(package, exe), *args], self.env, self.log_dir)
        self.procs.append(proc)
        return proc

    def start_argv(self, label, argv):
        proc = NodeProcess(label, argv, self.env, self.log_dir)
        self.procs.append(proc)
        return proc

    def failed(self):
        """Processes that have exited (during a run, any exit of a node is a failure)."""
        return [p for p in self.procs if p.returncode is not None]

    def stop(self, grace=5.0, first=None, settle=0.0):
        """SIGINT, then SIGTERM, then SIGKILL; returns {label: exit code}.

        ``first``: a predicate on processes to stop before the others (e.g. the simulators, so
        nothing new is published), then wait ``settle`` seconds (e.g. for a recorder to drain
        its queue) before stopping the rest.
        """
        if first is not None:
            self._signal_all([p for p in self.procs if first(p)], grace)
            if settle > 0.0:
                time.sleep(settle)
        self._signal_all(self.procs, grace)
        codes = {}
        for p in self.procs:
            codes[p.label] = p.returncode
            p.close()
        return codes

    @staticmethod
    def _signal_all(procs, grace):
        for sig, wait in ((signal.SIGINT, grace), (signal.SIGTERM, 2.0), (signal.SIGKILL, 2.0)):
            alive = [p for p in reversed(procs) if p.returncode is None]
            if not alive:
                break
            for p in alive:
                p.signal(sig)
            deadline = time.monotonic() + wait
            for p in alive:
                p.wait(max(0.0, deadline - time.monotonic()))

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.stop()
        return False
