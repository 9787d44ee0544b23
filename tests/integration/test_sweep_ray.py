"""Sweeps on Ray (scripts/montecarlo/backends.run_ray): issue 16 item 3.

A private local Ray instance of 2 CPUs is started by the test and shut down after it, even on
failure (no ROS graph: no domain needed). It must give the same table, byte for byte, as the
local backend with one process; and a Ray worker process killed while running a chunk (the
test-only SHIPNAV_SWEEP_FAIL_ONCE hook, os._exit in the worker) makes Ray rerun that task
(max_retries) with every row still once, and the run counts that one rerun chunk. A tiny
encounter sweep (montecarlo.encounters: Imazu runs with colav, 30 s each) and a tiny wind and
waves sweep (a random wind direction: batches of one episode, each with its own gusts, sea and
Gauss-Markov current from its seed) give the same table on Ray as locally too. Skipped, with
the reason, only if Ray cannot start.
"""
import pytest

from montecarlo import encounters
from montecarlo import episodes as mc_episodes
from montecarlo import results, spec
from montecarlo.backends import start_local_ray
from montecarlo.driver import run_sweep

pytestmark = [pytest.mark.integration, pytest.mark.timeout(300)]


def tiny():
    return spec.parse({'name': 'ray', 'seed': 5, 'episodes': 3,
                       'base': {'model': 'mariner', 'duration_s': 20.0},
                       'vary': {'controller': ['los', 'ilos'],
                                'start_cross_m': {'uniform': [-80, 80]},
                                'current_direction_deg': {'uniform': [-180, 180]},
                                'current_speed_mps': {'uniform': [0.0, 0.9]}}}, 'ray.yaml')


@pytest.fixture
def ray_local(tmp_path, monkeypatch):
    ray = pytest.importorskip('ray')
    marker = tmp_path / 'failed_once'
    # Workers inherit the driver's environment when the instance starts.
    monkeypatch.setenv(mc_episodes.FAIL_ONCE_ENV, str(marker))
    # and run at niceness 0, not Ray's 15, which beside the suite's other tests starved them
    monkeypatch.setenv('RAY_worker_niceness', '0')
    try:
        start_local_ray(2)
    except Exception as exc:  # noqa: BLE001 (any start failure is a reason to skip)
        pytest.skip(f'ray cannot start here: {type(exc).__name__}: {exc}')
    try:
        yield marker
    finally:
        ray.shutdown()


def test_ray_table_equals_local_and_a_killed_worker_is_retried(ray_local, monkeypatch):
    sw = tiny()
    rows, run = run_sweep(sw, 'ray', workers=2, chunk_size=1, progress=False)
    assert ray_local.exists()                    # one worker process did die mid-sweep
    assert sorted(r['episode'] for r in rows) == list(range(6))
    assert run['rerun_chunks'] == 1                 # its chunk, counted where it ran
    monkeypatch.delenv(mc_episodes.FAIL_ONCE_ENV)
    local, _ = run_sweep(sw, 'local', workers=1, chunk_size=6, progress=False)
    assert results.table_text(rows, sw.columns()) == results.table_text(local, sw.columns())
    enc = spec.parse({'name': 'ray_enc', 'seed': 4, 'episodes': 2,
                      'base': {'model': 'mariner', 'duration_s': 30.0, 'encounter': 2},
                      'vary': {'encounter_speed_factor': {'uniform': [0.7, 1.3]},
                               'encounter_miss_m': {'normal': [0.0, 300.0]}}}, 'enc.yaml')
    on_ray, _ = run_sweep(enc, 'ray', workers=2, chunk_size=1, progress=False)
    local, _ = run_sweep(enc, 'local', workers=1, chunk_size=2, progress=False)
    assert (results.table_text(on_ray, enc.columns(), encounters.METRICS)
            == results.table_text(local, enc.columns(), encounters.METRICS))
    weather = spec.parse({'name': 'ray_wind', 'seed': 6, 'episodes': 3,
                          'base': {'model': 'mariner', 'controller': 'ilos', 'duration_s': 10.0,
                                   'wind_speed_mps': 15.0, 'wave_height_m': 3.0,
                                   'wave_direction_deg': 200.0, 'current_speed_mps': 0.5,
                                   'current_direction_std_deg': 20.0,
                                   'current_time_constant_s': 10.0},
                          'vary': {'wind_direction_deg': {'uniform': [0, 360]},
                                   'start_cross_m': {'uniform': [-50, 50]}}}, 'wind.yaml')
    on_ray, _ = run_sweep(weather, 'ray', workers=2, chunk_size=1, progress=False)
    local, _ = run_sweep(weather, 'local', workers=1, chunk_size=3, progress=False)
    assert (results.table_text(on_ray, weather.columns())
            == results.table_text(local, weather.columns()))
