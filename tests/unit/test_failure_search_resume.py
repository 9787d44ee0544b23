"""scripts/failure_search.py --resume: a search stopped after a finished generation continues
from its partial file, runs only the generations it lacks, and ends with the results of an
uninterrupted search; a partial file of other arguments, or none, is refused in one line.

The search is the smallest real one (the Mariner with VO, two generations of two encounters,
the cross-entropy sampler alone): each simulation is a real in-process run.
"""
import json

import pytest

import failure_search
from colav_search import study

SEARCH = ['--ship', 'mariner', '--method', 'vo', '--budget', '4', '--generation', '2',
          '--seed', '3', '--samplers', 'cross_entropy']


def _samplers(folder):
    """The results without what depends on the machine (wall time)."""
    data = json.loads((folder / 'failure_search.json').read_text())
    return {name: {k: v for k, v in s.items() if k != 'wall_s_mean'}
            for name, s in data['samplers'].items()}


def _counting_runs(monkeypatch, stop_at=None):
    """Count the simulations run; with ``stop_at``, Ctrl-C as that one (1-based) starts."""
    real, calls = study._run, []

    def run(task):
        calls.append(task)
        if len(calls) == stop_at:
            raise KeyboardInterrupt
        return real(task)
    monkeypatch.setattr(study, '_run', run)
    return calls


@pytest.mark.timeout(180)
def test_a_stopped_search_resumes_where_it_stopped_and_ends_as_an_uninterrupted_one(
        tmp_path, monkeypatch, capsys):
    assert failure_search.main([*SEARCH, '--out', str(tmp_path / 'whole')]) == 0
    whole = _samplers(tmp_path / 'whole')
    assert not (tmp_path / 'whole' / failure_search.PARTIAL_NAME).exists()

    out = tmp_path / 'stopped'
    calls = _counting_runs(monkeypatch, stop_at=3)      # Ctrl-C in the second generation
    capsys.readouterr()
    assert failure_search.main([*SEARCH, '--out', str(out)]) == 130
    err = capsys.readouterr().err.strip().splitlines()
    partial = out / failure_search.PARTIAL_NAME
    assert len(err) == 1 and 'interrupted' in err[0] and '--resume' in err[0], err
    assert not (out / 'failure_search.json').exists()
    lines = partial.read_text().splitlines()
    assert len(lines) == 2 and json.loads(lines[1])['episode'] == 'cross_entropy:0'

    calls = _counting_runs(monkeypatch)
    assert failure_search.main([*SEARCH, '--out', str(out), '--resume']) == 0
    assert len(calls) == 2                             # the second generation only
    assert _samplers(out) == whole
    assert not partial.exists()


def test_resume_refuses_another_search_and_a_missing_partial_file_in_one_line(
        tmp_path, monkeypatch, capsys):
    out = tmp_path / 'stopped'
    _counting_runs(monkeypatch, stop_at=1)             # stopped before any generation ended
    assert failure_search.main([*SEARCH, '--out', str(out)]) == 130
    capsys.readouterr()
    other = [a if a != '3' else '4' for a in SEARCH]    # another seed
    assert failure_search.main([*other, '--out', str(out), '--resume']) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and 'another search' in err[0] and 'Traceback' not in err[0], err
    assert failure_search.main([*SEARCH, '--out', str(tmp_path / 'none'), '--resume']) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and 'nothing to resume' in err[0], err
