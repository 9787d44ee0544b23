"""ship_sim.allocator: the batched plant's step does not page-fault once the entry points have
tuned the allocator, and settings the user gave are left alone.

Each case runs in a fresh interpreter: the allocator's state is per process and glibc adapts
its thresholds to what the process freed before, so only a fresh process shows what an entry
point starts with."""
import json
import platform
import subprocess
import sys

import pytest

pytestmark = pytest.mark.skipif(platform.system() != 'Linux' or platform.libc_ver()[0] != 'glibc',
                                reason='the allocator tuning is glibc-only')

N, STEPS = 10_000, 20
#: One RK4 step of N Mariners, minor page faults counted over STEPS steps after one warm-up.
PROBE = f"""
import json, resource, sys
import numpy as np
from ship_sim.allocator import tune_allocator
from ship_sim.integrators import rk4_step
from ship_sim.models import make_model
tuned = tune_allocator() if sys.argv[1] == 'tune' else None
m = make_model('mariner')
x = np.tile(m.initial_state(), ({N}, 1))
x[:, m.IPSI] = np.linspace(-3.0, 3.0, {N})
u = m.inputs(np.linspace(-0.3, 0.3, {N}))
x = rk4_step(m.rhs, x, u, 0.1)
f0 = resource.getrusage(resource.RUSAGE_SELF).ru_minflt
for _ in range({STEPS}):
    x = rk4_step(m.rhs, x, u, 0.1)
faults = resource.getrusage(resource.RUSAGE_SELF).ru_minflt - f0
print(json.dumps({{'tuned': tuned, 'faults_per_step': faults / {STEPS}}}))
"""


def probe(mode, env=None):
    out = subprocess.run([sys.executable, '-c', PROBE, mode], capture_output=True, text=True,
                         timeout=120, env=env)
    assert out.returncode == 0, out.stderr
    return json.loads(out.stdout)


def test_a_tuned_process_steps_the_batch_without_page_faults():
    """Untuned, every step maps fresh pages for its (N, 7) temporaries: at least the pages of
    one such array per step (the check that the probe exercises what the tuning is for).
    Tuned, less than one fault per step on average: the step reuses the heap."""
    pages_of_one_state = N * 7 * 8 / 4096
    default = probe('default')
    assert default['faults_per_step'] > pages_of_one_state
    tuned = probe('tune')
    assert tuned['tuned'] is True
    assert tuned['faults_per_step'] < 1.0


def test_thresholds_the_user_set_are_left_alone():
    import os
    env = dict(os.environ, MALLOC_TRIM_THRESHOLD_='131072')
    assert probe('tune', env)['tuned'] is False
