"""Compiled RK4 of the MSS ship models for a batch, built from each model's own equations.

``batch_rk4(model)`` returns a numba kernel ``step(x, u, h, drift, ix, iy, out)`` that does,
for every vessel i, what the numpy batch path does (``rk4_step(model.rhs, x, u, h)``, then the
current's ``drift`` (N, 2) (m per step) added to the north and east columns ``ix``, ``iy``):
the four derivative evaluations, the same RK4 combination in the same order as
``ship_sim.integrators.rk4_step``, written to ``out`` (N, n_states), which it returns.

There is no second copy of any model: the derivative is the model's own
``_derivatives(ops, *state, *inputs)`` source (mariner.py, tanker.py, container.py), compiled
with ``ops`` the float backend (math_backends.FLOAT_OPS, its helpers compiled) and with the
instance's parameters it reads (``self.U0``, ``self.rudder_max``, ...) and the module's
coefficients frozen as compile-time constants, which numba does with globals. So a kernel is
built per model class and parameter values, kept in the process and cached on disk.

Disk cache: numba caches a function beside its source file and checks only that file's time
stamp, not the globals it froze. The generated source is therefore written to a file whose
name is the hash of everything the machine code depends on: the generated text, the frozen
parameter values, the sources of the models package (the model modules, math_backends, this
module) and numba's version. Any change gives another file, so a stale kernel is never loaded; a new
process (a sweep worker, a test) loads the compiled kernel instead of compiling it again. The
folder is ``$SHIPNAV_KERNEL_CACHE`` if set, else ``$XDG_CACHE_HOME/shipnav/kernels`` (default
``~/.cache``); if it cannot be written the kernel is compiled in memory, as without the cache.
External loads (wind) are not compiled: that path stays on numpy.
"""
import ast
import functools
import hashlib
import inspect
import math
import os
import sys
import tempfile
import textwrap
import types
from pathlib import Path

from ship_sim import kernels

from . import math_backends

_CACHE = {}


def _ops_module():
    """math_backends.FLOAT_OPS as a module of compiled functions (numba resolves a global
    module's attributes at compile time; it cannot take a Python object)."""
    ops = types.ModuleType('compiled_float_ops')
    for name, fn in vars(math_backends.FLOAT_OPS).items():
        ops.__dict__[name] = fn if getattr(fn, '__module__', None) == 'math' else \
            kernels.njit(fn)
    return ops


def _without_ops(fn, skip_self=False):
    """``fn``'s source as a function without its leading (self and) ``ops`` parameters, whose
    calls of global helpers as ``helper(ops, ...)`` drop that argument too (the helpers are
    rewritten the same way, ``_helpers``). Returns (ast.FunctionDef, names of the ``self``
    attributes it reads, names of the helpers it calls with ops)."""
    node = ast.parse(textwrap.dedent(inspect.getsource(fn))).body[0]
    node.decorator_list = []
    lead = ['self', 'ops'] if skip_self else ['ops']
    if [a.arg for a in node.args.args[:len(lead)]] != lead:
        raise ValueError(f'{fn.__qualname__} must start with ({", ".join(lead)}, ...)')
    node.args.args = node.args.args[len(lead):]
    helpers = set()
    for call in ast.walk(node):
        if (isinstance(call, ast.Call) and isinstance(call.func, ast.Name) and call.args
                and isinstance(call.args[0], ast.Name) and call.args[0].id == 'ops'):
            helpers.add(call.func.id)
            call.args = call.args[1:]
    used = sorted({n.attr for n in ast.walk(node) if isinstance(n, ast.Attribute)
                   and isinstance(n.value, ast.Name) and n.value.id == 'self'})
    return node, used, sorted(helpers)


@functools.lru_cache(maxsize=None)
def _derivative_source(cls):
    """The class's ``_derivatives`` (named ``derivative``) and the helpers it calls with
    ``ops`` (e.g. mss_ship.rudder_servo), as functions of floats only: ``self`` and ``ops``
    become globals. Returns (source, names of ``self`` attributes)."""
    node, used, helpers = _without_ops(cls._derivatives, skip_self=True)
    node.name = 'derivative'
    module = sys.modules[cls.__module__].__dict__
    body = []
    for name in helpers:
        helper, _, more = _without_ops(module[name])
        if more:
            raise ValueError(f'{name}: helpers called with ops may not call others')
        body.append(helper)
    body.append(node)
    return ast.unparse(ast.Module(body=body, type_ignores=[])), used, helpers


def _rk4_source(n_states, n_inputs):
    """The batch loop around ``derivative``: rk4_step's arithmetic, unrolled per component."""
    xs = [f'x{j}' for j in range(n_states)]
    us = [f'u{j}' for j in range(n_inputs)]
    inputs = ', '.join(us)
    lines = ['def step(x, u, h, drift, ix, iy, out):',
             '    hh = 0.5 * h',
             '    h6 = h / 6',
             '    for i in range(x.shape[0]):']
    lines += [f'        {a} = x[i, {j}]' for j, a in enumerate(xs)]
    lines += [f'        {a} = u[i, {j}]' for j, a in enumerate(us)]
    prev = None
    for k, scale in ((1, None), (2, 'hh'), (3, 'hh'), (4, 'h')):
        ks = [f'k{k}_{j}' for j in range(n_states)]
        args = xs if prev is None else [f'{a} + {scale} * {b}' for a, b in zip(xs, prev)]
        lines.append(f'        {", ".join(ks)} = derivative({", ".join(args)}, {inputs})')
        prev = ks
    for j, a in enumerate(xs):
        lines.append(f'        out[i, {j}] = {a} + h6 * (k1_{j} + 2 * k2_{j} + 2 * k3_{j} '
                     f'+ k4_{j})')
    lines += ['        out[i, ix] += drift[i, 0]',
              '        out[i, iy] += drift[i, 1]',
              '    return out']
    return '\n'.join(lines) + '\n'


#: Environment variable naming the folder of the generated kernels' disk cache.
CACHE_ENV = 'SHIPNAV_KERNEL_CACHE'


def cache_folder():
    """Where generated kernel sources and numba's cache of them go (module docstring)."""
    if os.environ.get(CACHE_ENV):
        return Path(os.environ[CACHE_ENV])
    base = os.environ.get('XDG_CACHE_HOME') or Path.home() / '.cache'
    return Path(base) / 'shipnav' / 'kernels'


def _cached_file(name, text):
    """``text`` written once to the cache folder as ``<name>_<hash>.py`` (atomically: a process
    never reads a half-written file); None if the folder cannot be written."""
    digest = hashlib.sha256(text.encode()).hexdigest()[:20]
    folder = cache_folder()
    path = folder / f'{name}_{digest}.py'
    if path.is_file():
        return path
    try:
        folder.mkdir(parents=True, exist_ok=True)
        fd, tmp = tempfile.mkstemp(dir=folder, suffix='.tmp')
        with os.fdopen(fd, 'w') as f:
            f.write(text)
        os.chmod(tmp, 0o644)      # mkstemp's 0600 would hide it from other users' numba
        os.replace(tmp, path)
    except OSError:
        return None
    return path


@functools.lru_cache(maxsize=None)
def _dependency_stamp():
    """What the generated code's meaning depends on besides its own text: the sources of the
    models package (the model modules, their coefficients and helpers, math_backends, this
    module) and numba's version."""
    import numba
    parts = [p.read_text() for p in sorted(Path(__file__).parent.glob('*.py'))]
    return hashlib.sha256('\0'.join(parts + [numba.__version__]).encode()).hexdigest()


def batch_rk4(model):
    """The compiled batch RK4 of an MSS ship model instance (module docstring)."""
    cls = type(model)
    source, attrs, helpers = _derivative_source(cls)
    frozen = tuple((a, getattr(model, a)) for a in attrs)
    for a, v in frozen:
        if not (isinstance(v, (int, float)) and math.isfinite(v)):
            raise ValueError(f'{cls.__name__}.{a} = {v!r}: only finite numbers can be frozen')
    key = (cls, frozen)
    if key not in _CACHE:
        self_ns = types.ModuleType(f'{cls.__name__}_parameters')
        self_ns.__dict__.update(frozen)
        namespace = dict(sys.modules[cls.__module__].__dict__, self=self_ns, ops=_ops_module())
        text = (f'# Generated by {__name__} for {cls.__module__}.{cls.__name__}; not edited.\n'
                f'# parameters: {dict(frozen)!r}\n'
                f'# dependencies: {_dependency_stamp()}\n'
                + source + '\n\n' + _rk4_source(model.n_states, model.n_inputs))
        path = _cached_file(f'{cls.__name__.lower()}_rk4', text)
        exec(compile(text, str(path) if path else f'<compiled {cls.__name__} rk4>', 'exec'),
             namespace)
        for name in helpers:
            namespace[name] = kernels.njit(namespace[name])
        namespace['derivative'] = kernels.njit(inline='always')(namespace['derivative'])
        _CACHE[key] = kernels.njit(cache=path is not None)(namespace['step'])
    return _CACHE[key]
