"""The MSS ship ports against the original MATLAB functions run under Octave.

Reference: tests/data/mss_golden/golden_<model>.json (cybergalactic/MSS commit
736a3d1, CRAFT/SHIP/models/{mariner,tanker,container}.m, GNU Octave 7.3.0): (x, ui) -> xdot, U.
Our rhs takes the same state and input vectors as the MSS function (mariner's optional U0 is a
constructor parameter, the tanker's depth h stays the third input).
"""
import json
from pathlib import Path

import numpy as np
import pytest

from ship_sim.models import make_model

# provenance: tests/data/README.md
GOLDEN = Path(__file__).resolve().parents[1] / 'data' / 'mss_golden'
MODELS = ('mariner', 'tanker', 'container')
# Relative tolerance from the brief; absolute floor only for values that are exactly 0 in MSS.
RTOL, ATOL = 1e-9, 1e-15


def _load(name):
    return json.loads((GOLDEN / f'golden_{name}.json').read_text())


def _model(name, case):
    return make_model(name, U0=case['U0']) if name == 'mariner' else make_model(name)


CASES = [(name, case) for name in MODELS for case in _load(name)['cases']]
IDS = [f"{name}-{case['id']}-{case['kind']}" for name, case in CASES]


def test_every_documented_case_is_present():
    for name in MODELS:
        doc = _load(name)
        assert doc['source_commit'] == '736a3d128ccd5ecb3736eba231bbf046de7bdafa'
        # The file holds the even ids of n_cases generated cases.
        assert len(doc['cases']) == doc['n_cases'] // 2


@pytest.mark.parametrize('name, case', CASES, ids=IDS)
def test_rhs_matches_mss(name, case):
    model = _model(name, case)
    xdot = model.rhs(np.array(case['x']), np.array(case['ui']))
    np.testing.assert_allclose(xdot, case['xdot'], rtol=RTOL, atol=ATOL)


@pytest.mark.parametrize('name, case', CASES, ids=IDS)
def test_float_path_matches_mss(name, case):
    model = _model(name, case)
    xdot = model.rhs_scalar(case['x'], case['ui'])
    assert all(type(v) is float for v in xdot)
    np.testing.assert_allclose(xdot, case['xdot'], rtol=RTOL, atol=ATOL)


@pytest.mark.parametrize('name, case', CASES, ids=IDS)
def test_speed_matches_mss_output_U(name, case):
    model = _model(name, case)
    assert model.speed(np.array(case['x'])) == pytest.approx(case['U'], rel=1e-14)


@pytest.mark.parametrize('name', MODELS)
def test_batched_rhs_equals_rows(name):
    # Mariner cases with a non-default U0 need another model instance: batch the default ones.
    cases = [c for c in _load(name)['cases'] if c.get('U0', 7.7175) == 7.7175]
    model = _model(name, cases[0])
    X = np.array([c['x'] for c in cases])
    U = np.array([c['ui'] for c in cases])
    batch = model.rhs(X, U)
    assert batch.shape == X.shape
    rows = np.array([model.rhs(x, u) for x, u in zip(X, U)])
    np.testing.assert_array_equal(batch, rows)
    np.testing.assert_allclose(batch, [c['xdot'] for c in cases], rtol=RTOL, atol=ATOL)
    # Extra leading axes and one input shared by all rows broadcast.
    X3 = X.reshape(2, -1, X.shape[-1]) if len(X) % 2 == 0 else X[None]
    shared = model.rhs(X3, U[0])
    np.testing.assert_array_equal(
        shared, model.rhs(X3, np.broadcast_to(U[0], X3.shape[:-1] + U[0].shape)))
    np.testing.assert_array_equal(shared.reshape(X.shape)[1], model.rhs(X[1], U[0]))
