"""Start and stop node processes from the colcon install tree, the way `ros2 run` would.

`ros2 run P E` finds package P through the ament index under AMENT_PREFIX_PATH and runs
`<prefix>/lib/P/E`. We compute the environment that sourcing `install/setup.bash` would give
(AMENT_PREFIX_PATH, PYTHONPATH) instead of sourcing bash, so the launcher and the tests need no
shell and no ros2 CLI. Every process gets its own session (process group) so it can be stopped
with all its children; `ProcessGroup.stop()` escalates SIGINT -> SIGTERM -> SIGKILL and is safe to
call twice, from `finally:` blocks and signal handlers alike.
"""
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

REPO = Path(__file__).resolve().parents[2]
INSTALL = REPO / 'ros_ws' / 'install'
PY_SITE = f'lib/python{sys.version_info.major}.{sys.version_info.minor}/site-packages'


def install_env(base_env=None, install=INSTALL, domain_id=None, localhost_only=True):
    """Environment in which the installed packages and ROS 2 work, like `source setup.bash`."""
    env = dict(os.environ if base_env is None else base_env)
    if not (install / 'setup.bash').exists():
        raise FileNotFoundError(f'{install} has no colcon install tree; run `make build` first')
    prefixes = sorted(p for p in install.iterdir() if (p / 'share' / 'ament_index').is_dir())
    ament = [str(p) for p in prefixes]
    pypath = [str(p / PY_SITE) for p in prefixes]
    for key, extra in (('AMENT_PREFIX_PATH', ament), ('PYTHONPATH', pypath)):
        old = [x for x in env.get(key, '').split(os.pathsep) if x and x not in extra]
        env[key] = os.pathsep.join(extra + old)
    if domain_id is not None:
        env['ROS_DOMAIN_ID'] = str(domain_id)
    if localhost_only:
        env['ROS_AUTOMATIC_DISCOVERY_RANGE'] = 'LOCALHOST'
    env['PYTHONUNBUFFERED'] = '1'
    return env


def executable(package, name, install=INSTALL):
    """Path of an installed node executable (what `ros2 run package name` runs)."""
    path = install / package / 'lib' / package / name
    if not path.exists():
        raise FileNotFoundError(f'{path} not found: is {package} built (make build)?')
    return path


def ros_args(namespace=None, params=None, node_name=None, log_level=None):
    """`--ros-args` for a namespace, a node name and parameters (values as YAML literals)."""
    args = ['--ros-args']
    if namespace:
        args += ['-r', f'__ns:={namespace}']
    if node_name:
        args += ['-r', f'__node:={node_name}']
    for key, value in (params or {}).items():
        args += ['-p', f'{key}:={_param_literal(value)}']
    if log_level:
        args += ['--log-level', log_level]
    return args


def _param_literal(value):
    if isinstance(value, bool):
        return 'true' if value else 'false'
    if isinstance(value, float):
        return repr(value)  # keeps a decimal point so ROS types it as a double
    if isinstance(value, (list, tuple)):
        return '[' + ','.join(_param_literal(v) for v in value) + ']'
    return str(value)


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
                                      stdin=subprocess.DEVNULL, start_new_session=True)

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
