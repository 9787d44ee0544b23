"""The one place that chooses how the batched paths run: numpy arrays or numba-compiled loops.

Backends (``BACKENDS``):

- ``'numpy'``: the reference. Every batched path (the MSS plants' RK4, the batch guidance, the
  batch autopilot) is written on numpy arrays; it is always there.
- ``'numba'``: compiled per-vessel loops of the same arithmetic in the same order (no fastmath),
  so an episode equals the numpy one to rounding. Needs numba (requirements/kernels.txt); the
  demo's runtime does not install it.

Selection: the environment variable ``SHIPNAV_KERNELS`` = ``auto`` (default: numba when it can
be imported, else numpy), ``numpy`` or ``numba`` (an error when numba is missing), read once at
import; ``use(name)`` changes it for the process and ``using(name)`` for a ``with`` block (the
tests run both). The batched code asks ``compiled()`` each time it builds or runs a kernel, so
a switch takes effect at the next call.
"""
import contextlib
import os

ENV = 'SHIPNAV_KERNELS'
BACKENDS = ('numpy', 'numba')
CHOICES = ('auto',) + BACKENDS

_backend = None


def numba_available():
    """True when numba can be imported (it is then imported)."""
    try:
        import numba  # noqa: F401
    except ImportError:
        return False
    return True


def _resolve(name):
    name = (name or 'auto').strip().lower()
    if name not in CHOICES:
        raise ValueError(f'{ENV} / kernel backend = {name!r}; allowed: {", ".join(CHOICES)}')
    if name == 'auto':
        return 'numba' if numba_available() else 'numpy'
    if name == 'numba' and not numba_available():
        raise ValueError('kernel backend numba requested but numba is not installed '
                         '(pip install -r requirements/kernels.txt), or use numpy')
    return name


def backend():
    """The backend in force: 'numpy' or 'numba'."""
    global _backend
    if _backend is None:
        _backend = _resolve(os.environ.get(ENV))
    return _backend


def use(name):
    """Switch the backend ('auto', 'numpy' or 'numba') for this process; returns the one in
    force before."""
    global _backend
    before = backend()
    _backend = _resolve(name)
    return before


@contextlib.contextmanager
def using(name):
    """``with using('numpy'):`` runs a block on one backend, then restores the previous."""
    before = use(name)
    try:
        yield backend()
    finally:
        use(before)


def compiled():
    """True when the batched paths should run their compiled kernels."""
    return backend() == 'numba'


def njit(*args, **options):
    """numba.njit with the project's options: no fastmath (IEEE arithmetic in source order,
    so results equal numpy's), numpy's error model (x / 0 gives inf or NaN as in the array
    code, not ZeroDivisionError). Used as ``@njit`` or ``@njit(cache=True)``; the kernels'
    modules import numba only through this, lazily, on the first compiled call."""
    import numba
    options = {'fastmath': False, 'error_model': 'numpy', **options}
    if args and callable(args[0]):
        return numba.njit(**options)(args[0])
    return numba.njit(*args, **options)


def compile_globals(namespace, names, **options):
    """Replace the plain functions ``names`` of a module's ``namespace`` (its globals()) by
    their compiled versions, in place (once: names already compiled are left), so compiled
    code calling them by name calls the compiled ones; with ``cache=True`` they are cached on
    disk beside the module. Call it from a ``lazy`` factory: the module stays importable
    without numba."""
    for name in names:
        if not hasattr(namespace[name], 'py_func'):   # not compiled by an earlier factory
            namespace[name] = njit(**options)(namespace[name])


def lazy(factory):
    """A function that builds its kernel (``factory()``, importing numba) on first call.

    Lets a module define compiled kernels at import time without importing numba until a
    compiled path actually runs."""
    box = []

    def call(*args):
        if not box:
            box.append(factory())
        return box[0](*args)
    call.__name__ = getattr(factory, '__name__', 'kernel')
    call.__doc__ = factory.__doc__
    return call
