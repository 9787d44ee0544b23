"""Keep the C library's allocator from mapping and unmapping numpy's temporaries on every step.

glibc's malloc serves a block of at least ``M_MMAP_THRESHOLD`` (128 KiB at start) with a fresh
``mmap`` and returns it with ``munmap`` when freed, and gives memory at the top of its heap
back to the kernel once more than ``M_TRIM_THRESHOLD`` (128 KiB) is free there. A batched
step builds arrays above that size many times (a (10 000, 7) state is 560 KB; SB-MPC's
scenario x target x step arrays, a block of the batch's wave response), so every step maps
them, the kernel zero-fills each 4 KiB page on its first touch (a minor page fault), and the
step unmaps them again. glibc raises its threshold by itself when it frees a mapped block, to
that block's size (and the trim threshold to twice it), but a step whose freed temporaries
add up to more than that still gives its heap back and faults it in again, and how much
depends on the largest block the process freed before (a benchmark row run after another).

``tune_allocator()``, called once at process start by the entry points (the nodes' common
main ship_sim.ros.run.run_node, scripts/bench.py, scripts/sweep.py and its workers,
scripts/evaluate_controllers.py, scripts/imazu_benchmark.py, scripts/train_ddpg.py), sets
both thresholds for the whole process: blocks below ``MMAP_THRESHOLD`` come from the heap and
are reused from step to step, and up to ``TRIM_THRESHOLD`` of freed heap is kept rather than
given back. Setting them also turns glibc's own adjustment off, so a figure no longer depends
on what ran before. The price is memory: a process keeps up to ``TRIM_THRESHOLD`` of freed
heap it would otherwise return. This was chosen over preallocated work buffers (``out=``
arguments) in every batched module: it covers every path, present and future, with the same
effect on the faults and the time (doc/results/performance.md), and leaves the arithmetic untouched.

Not glibc (macOS, musl), or thresholds the user set (``MALLOC_MMAP_THRESHOLD_``,
``MALLOC_TRIM_THRESHOLD_``, or ``glibc.malloc`` tunables in ``GLIBC_TUNABLES``): nothing is
changed.
"""
import ctypes
import os
import platform

#: glibc's malloc.h parameter numbers for mallopt.
M_TRIM_THRESHOLD = -1
M_MMAP_THRESHOLD = -3
#: 32 MiB: glibc's upper bound of its dynamic mmap threshold on 64-bit systems
#: (DEFAULT_MMAP_THRESHOLD_MAX), so only blocks it would never serve from the heap are mapped.
MMAP_THRESHOLD = 32 * 1024 * 1024
#: Twice the mmap threshold, the ratio glibc's own adjustment keeps.
TRIM_THRESHOLD = 2 * MMAP_THRESHOLD
_USER_SETTINGS = ('MALLOC_MMAP_THRESHOLD_', 'MALLOC_TRIM_THRESHOLD_')

_applied = None


def tune_allocator():
    """Set glibc's mmap and trim thresholds once for this process (module doc); True if they
    are set (now or by an earlier call), False where nothing is changed."""
    global _applied
    if _applied is None:
        _applied = _set_thresholds()
    return _applied


def _set_thresholds():
    if platform.system() != 'Linux' or platform.libc_ver()[0] != 'glibc':
        return False
    if any(k in os.environ for k in _USER_SETTINGS) or \
            'glibc.malloc' in os.environ.get('GLIBC_TUNABLES', ''):
        return False
    try:
        mallopt = ctypes.CDLL(None).mallopt
    except (OSError, AttributeError):
        return False
    mallopt.argtypes, mallopt.restype = (ctypes.c_int, ctypes.c_int), ctypes.c_int
    # mallopt returns 1 on success, 0 on error.
    return bool(mallopt(M_MMAP_THRESHOLD, MMAP_THRESHOLD)
                and mallopt(M_TRIM_THRESHOLD, TRIM_THRESHOLD))
