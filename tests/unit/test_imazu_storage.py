"""A benchmark's runs written for --rescore come back equal, without pickle."""
import numpy as np

from imazu.runner import RunResult
from imazu.storage import load_runs, save_runs


def test_runs_round_trip_exactly(tmp_path):
    rng = np.random.default_rng(0)
    own = RunResult(np.arange(5.0), rng.normal(size=(5, 4)), {'ts1': rng.normal(size=(5, 4))},
                    [(1.0, 'avoid', 0.26, 1.0), (2.0, 'nominal', 0.0, 1.0)], rng.normal(size=5),
                    0.125, 'clear')
    ref = RunResult(np.arange(5.0), rng.normal(size=(5, 4)))
    results = {('tanker', 'sbmpc', 12): own, ('tanker', None, None): ref}
    save_runs(tmp_path, results, {'walls': [1.5], 'cases': [12]})
    back = load_runs(tmp_path)
    assert back['walls'] == [1.5] and back['cases'] == [12]
    assert set(back['results']) == set(results)
    for key, r in results.items():
        b = back['results'][key]
        assert np.array_equal(b.t, r.t) and np.array_equal(b.own, r.own)
        assert (b.heading is None) == (r.heading is None)
        assert b.heading is None or np.array_equal(b.heading, r.heading)
        assert b.targets.keys() == r.targets.keys()
        assert all(np.array_equal(b.targets[n], r.targets[n]) for n in r.targets)
        assert b.decisions == r.decisions and b.end == r.end
        assert b.decision_wall_s == r.decision_wall_s
    assert not list(tmp_path.glob('*.pkl'))
