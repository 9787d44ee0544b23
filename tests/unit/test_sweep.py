"""Monte Carlo sweeps (scripts/sweep.py, scripts/montecarlo): issue 16 items 2-3.

- Sweep files: grid x samples expand to episodes in index order; random parameters are drawn
  per sample from SeedSequence(seed) children, inside their distribution, the same in every grid
  cell when paired; the seed changes them; bad files give one-line errors.
- Episodes: a row (batched loop) equals the single-vessel in-process loop
  (evaluate_controllers.run) for the same start to rounding, the tuned ILOS loop included,
  and in wind and waves (a named condition or explicit keys) with the episode's own seed;
  the metrics obey their definitions (RMS >= mean |e|, max >= RMS, reward at most one per
  sample); a Gauss-Markov current runs in the batch, each row equal to the single-vessel loop
  with the current of its own seed, and changes the episode.
- Confidence intervals: Student-t against scipy's interval; Wilson's lower bound for all
  successes is n / (n + z^2).
- Determinism: the CSV is identical byte for byte for 1 or 2 local workers and any chunk size,
  and a worker killed mid-sweep (test-only hook) leaves every row exactly once.
- Encounter sweeps (montecarlo.encounters): the speed factor keeps every Imazu target's meeting
  point and time; the miss offset gives the stated unmanoeuvred CPA (closed form,
  ship_guidance.cpa) at the same time, on the stated side; a file is one kind of sweep; a tiny
  encounter sweep's table is the same for any workers and chunks, its rows obey the metric
  definitions.
"""
import base64
import html
import json
import math
import re

import numpy as np
import pytest
from scipy import stats

import evaluate_controllers as ec
import sweep as sweep_cli
from montecarlo import episodes as mc_episodes
from montecarlo import encounters, results, spec
from montecarlo.driver import rerun_line, run_sweep
from imazu.cases import load_cases
from ship_guidance.cpa import velocity

BASE = {'model': 'mariner', 'duration_s': 20.0,
        'route': 'scenarios/routes/curved_path_{model}_000.yaml'}


def tiny(**over):
    doc = {'name': 'tiny', 'seed': 3, 'episodes': 3, 'base': dict(BASE),
           'vary': {'controller': ['los', 'ilos_lead'],
                    'current_speed_mps': [0.0, 0.9],
                    'current_direction_deg': {'uniform': [-180, 180]},
                    'start_cross_m': {'normal': [0.0, 30.0]},
                    'start_heading_deg': {'uniform': [-20, 20]}}}
    doc.update(over)
    return spec.parse(doc, 'tiny.yaml')


def test_grid_and_samples_expand_in_episode_order():
    sw = tiny()
    eps = spec.expand(sw)
    assert sw.n_cells == 4 and len(eps) == 12 == sw.n_episodes
    assert [e['episode'] for e in eps] == list(range(12))
    # Cell c, sample j -> episode c * 3 + j; grid axes in file order (controller slowest).
    assert [(e['controller'], e['current_speed_mps']) for e in eps[::3]] == [
        ('los', 0.0), ('los', 0.9), ('ilos_lead', 0.0), ('ilos_lead', 0.9)]
    assert all(e['duration_s'] == 20.0 and e['model'] == 'mariner' for e in eps)


def test_paired_draws_are_the_same_in_every_cell_and_inside_their_distribution():
    eps = spec.expand(tiny())
    keys = ('current_direction_deg', 'start_cross_m', 'start_heading_deg', 'seed')
    by_sample = {}
    for e in eps:
        by_sample.setdefault(e['sample'], set()).add(tuple(e[k] for k in keys))
    assert all(len(v) == 1 for v in by_sample.values())       # common random numbers
    assert len({next(iter(v)) for v in by_sample.values()}) == 3
    assert all(-180 <= e['current_direction_deg'] <= 180 for e in eps)
    assert all(-20 <= e['start_heading_deg'] <= 20 for e in eps)
    # Sample j's draws come from the j-th child of SeedSequence(seed), parameters sorted.
    rng = np.random.default_rng(np.random.SeedSequence(3).spawn(3)[1])
    direction = rng.uniform(-180, 180)
    cross = rng.normal(0.0, 30.0)
    assert (eps[1]['current_direction_deg'], eps[1]['start_cross_m']) == (direction, cross)


def test_unpaired_draws_differ_between_cells_and_the_seed_matters():
    eps = spec.expand(tiny(paired=False))
    assert eps[0]['start_cross_m'] != eps[3]['start_cross_m']
    other = spec.expand(tiny(seed=4))
    assert eps[0]['start_cross_m'] != other[0]['start_cross_m']
    many = spec.expand(tiny(paired=False, episodes=400))
    cross = np.array([e['start_cross_m'] for e in many])
    # 1600 normal draws of sd 30: the sample sd within +-10 % (its sd is ~1.8 %).
    assert 27.0 < cross.std() < 33.0 and abs(cross.mean()) < 3.0


@pytest.mark.parametrize('doc, message', [
    ({'bogus': 1}, 'unknown key'),
    ({'vary': {'condition': ['calm', 'storm']}}, "condition 'storm' unknown"),
    ({'base': {'condition': 'wind10'}, 'vary': {'wave_height_m': [1.0]}}, 'not both'),
    ({'vary': {'wave_period_s': [8.0, 50.0]}}, 'outside [0, 40]'),
    ({'vary': {'wind_speed_mps': {'uniform': [-1, 5]}}}, 'outside [0, 60]'),
    ({'vary': {'rudder_gain': [1]}}, "unknown parameter 'rudder_gain'"),
    ({'vary': {'controller': ['los', 'mpc']}}, "controller 'mpc' unknown"),
    ({'base': {'model': 'titanic'}}, "model 'titanic' unknown"),
    ({'vary': {'current_speed_mps': [0.5, 12.0]}}, 'outside [0, 10]'),
    ({'vary': {'start_cross_m': {'uniform': [10, -10]}}}, 'low <= high'),
    ({'vary': {'start_cross_m': {'beta': [1, 2]}}}, 'a random parameter is one of'),
    ({'vary': {'start_cross_m': 5}}, 'give a list'),
    ({'episodes': 0}, 'episodes must be an integer in [1, '),
    ({'vary': {'controller': []}}, 'at least one value'),
    ({'base': {'encounter': 1}, 'vary': {'controller': ['los']}},
     "'controller' is not a parameter of an encounter sweep"),
    ({'vary': {'encounter': [1, 2], 'current_speed_mps': [0.5]}},
     "'current_speed_mps' is not a parameter of an encounter sweep"),
    ({'vary': {'colav_method': ['sbmpc']}}, "'colav_method' belongs to an encounter sweep"),
    ({'vary': {'encounter': [1, 23]}}, 'encounter 23 unknown'),
    ({'vary': {'encounter': {'uniform': [1, 4]}}}, 'needs two numbers and a numeric'),
    ({'base': {'encounter': 1, 'colav_method': 'mpc'}}, "colav_method 'mpc' unknown"),
    ({'base': {'encounter': 1, 'model': 'nomoto1'}}, "'nomoto1' cannot be an encounter"),
    ({'base': {'encounter': 1}, 'vary': {'encounter_speed_factor': [0.05]}}, 'outside [0.1, 3]'),
])
def test_bad_sweep_files_are_refused_in_one_line(doc, message):
    with pytest.raises(spec.SweepError, match=None) as err:
        spec.parse(doc, 'bad.yaml')
    text = str(err.value)
    assert message in text and '\n' not in text and text.startswith('bad.yaml')


def test_cli_reports_a_bad_file_and_exits_2(tmp_path, capsys):
    bad = tmp_path / 'bad.yaml'
    bad.write_text('vary: {controller: [los\n')
    assert sweep_cli.main([str(bad)]) == 2
    err = capsys.readouterr().err.strip()
    assert err.startswith('error: ') and 'not valid YAML' in err and '\n' not in err
    assert sweep_cli.main([str(tmp_path / 'missing.yaml')]) == 2


def test_a_row_is_the_single_vessel_loop_and_obeys_the_metric_definitions():
    ep = mc_episodes.with_route_keys(spec.expand(tiny(episodes=1)))[3]   # ilos_lead, 0.9 m/s
    row = mc_episodes.run_chunk([ep])[0]
    route = mc_episodes._route(ep['route_key'])
    start = {'route': 0, 'along': 0.0, 'cross': ep['start_cross_m'],
             'heading': math.radians(ep['start_heading_deg']), 'current_speed': 0.9,
             'current_direction': math.radians(ep['current_direction_deg'])}
    direct = ec.run('mariner', route, 'ilos_lead', [start], 0.9, 20.0)
    # The batched loop equals the single-vessel loop to rounding (test_batch_closed_loop).
    assert row['reward'] == pytest.approx(direct['gaussian'][0], rel=1e-12)
    assert row['max_abs_e_m'] == pytest.approx(direct['max_abs_e'][0], rel=1e-12)
    assert row['rms_e_m'] == pytest.approx(direct['rms_e'][0], rel=1e-12)
    assert row['mean_abs_e_m'] <= row['rms_e_m'] <= row['max_abs_e_m']
    assert 0.0 <= row['reward'] <= 20.0 / ec.SIM_DT and row['completed'] == 1


def test_a_varying_current_runs_in_the_batch_and_follows_its_seed():
    """Gauss-Markov currents in speed, direction, both or neither (grid), in one sweep: the
    table is the same byte for byte for any chunking (each pattern a batch of its own), a
    row equals the single-vessel loop of that episode alone with its current drawn from
    default_rng(its seed) (ship_sim.current), and the variation changes the row."""
    from ship_sim.current import OceanCurrent
    sw = spec.parse({'seed': 2, 'episodes': 2,
                     'base': dict(BASE, duration_s=10.0, controller='ilos',
                                  current_speed_mps=0.6, current_time_constant_s=5.0),
                     'vary': {'current_speed_std_mps': [0.0, 0.3],
                              'current_direction_std_deg': [0.0, 30.0],
                              'current_direction_deg': {'uniform': [-180, 180]},
                              'start_cross_m': {'uniform': [-50, 50]}}}, 'c.yaml')
    rows, _ = run_sweep(sw, 'local', workers=1, chunk_size=100, progress=False)
    for chunk in (1,):
        other, _ = run_sweep(sw, 'local', workers=1, chunk_size=chunk, progress=False)
        assert results.table_text(other, sw.columns()) == results.table_text(rows, sw.columns())
    eps = mc_episodes.with_route_keys(spec.expand(sw))
    route = mc_episodes._route(eps[0]['route_key'])
    const = {}
    for ep, row in zip(eps, rows):
        s_std, d_std = ep['current_speed_std_mps'], math.radians(ep['current_direction_std_deg'])
        if s_std == d_std == 0.0:
            const[ep['start_cross_m']] = row
            continue
        field = OceanCurrent.from_std(0.6, math.radians(ep['current_direction_deg']), s_std,
                                      d_std, ep['current_time_constant_s'], seed=ep['seed'],
                                      shape=(1,))
        direct = ec.run('mariner', route, 'ilos', [mc_episodes._start(ep, 0)], 0.6, 10.0,
                        current_field=field)
        assert row['reward'] == pytest.approx(direct['gaussian'][0], rel=1e-12)
        assert row['max_abs_e_m'] == pytest.approx(direct['max_abs_e'][0], rel=1e-12)
    assert len(const) == 2                      # paired: every cell meets the same starts
    for ep, row in zip(eps, rows):
        if ep['current_speed_std_mps'] > 0.0:
            assert row['rms_e_m'] != const[ep['start_cross_m']]['rms_e_m']


def test_wind_and_waves_rows_follow_their_seed_whatever_the_chunking():
    """A named condition and explicit wind and sea keys: each row equals the single-vessel
    loop of that episode alone with its seed (its own gusts and waves), the table is the same
    byte for byte for any chunking, and the weather changes the rows."""
    sw = spec.parse({'seed': 5, 'episodes': 2, 'base': dict(BASE, duration_s=10.0,
                                                           controller='ilos'),
                     'vary': {'condition': ['calm', 'wind20'],
                              'start_cross_m': {'uniform': [-50, 50]}}}, 'w.yaml')
    rows, _ = run_sweep(sw, 'local', workers=1, chunk_size=100, progress=False)
    one, _ = run_sweep(sw, 'local', workers=1, chunk_size=1, progress=False)
    assert results.table_text(one, sw.columns()) == results.table_text(rows, sw.columns())
    ep = mc_episodes.with_route_keys(spec.expand(sw))[3]          # wind20, sample 1
    start = mc_episodes._start(ep, 0)
    direct = ec.run('mariner', mc_episodes._route(ep['route_key']), 'ilos', [start], 0.0, 10.0,
                    condition='wind20', seeds=[ep['seed']])
    assert rows[3]['reward'] == pytest.approx(direct['gaussian'][0], rel=1e-12)
    assert rows[3]['rudder_rate_deg_s'] == pytest.approx(direct['rudder_rate_deg_s'][0],
                                                         rel=1e-12)
    assert rows[3]['reward'] != rows[1]['reward']                 # calm, the same start
    explicit = spec.parse({'seed': 5, 'episodes': 1, 'base': dict(
        BASE, duration_s=10.0, controller='ilos', wind_speed_mps=15.0, wind_direction_deg=90.0,
        wave_height_m=3.0, wave_period_s=9.0, wave_direction_deg=270.0)}, 'x.yaml')
    row = run_sweep(explicit, 'local', workers=1, chunk_size=1, progress=False)[0][0]
    from ship_mission.conditions import Condition
    direct = ec.run('mariner', mc_episodes._route(ep['route_key']), 'ilos',
                    [mc_episodes._start(spec.expand(explicit)[0], 0)], 0.0, 10.0,
                    condition=Condition.custom(15.0, 90.0, 3.0, 9.0, 270.0),
                    seeds=[spec.expand(explicit)[0]['seed']])
    assert row['reward'] == pytest.approx(direct['gaussian'][0], rel=1e-12)


def test_t_and_wilson_intervals():
    x = np.array([3.0, 5.0, 4.0, 9.0, 1.0])
    mean, lo, hi = results.t_interval(x)
    ref = stats.t.interval(0.95, 4, loc=x.mean(), scale=stats.sem(x))
    assert mean == pytest.approx(4.4) and (lo, hi) == pytest.approx(ref)
    z = stats.norm.ppf(0.975)
    p, lo, hi = results.wilson_interval(40, 40)
    assert p == 1.0 and hi == 1.0 and lo == pytest.approx(40 / (40 + z * z))
    p, lo, hi = results.wilson_interval(0, 10)
    assert p == 0.0 and lo == 0.0 and 0.0 < hi < 0.35


@pytest.fixture(scope='module')
def reference_table():
    sw = tiny(episodes=2)
    rows, run = run_sweep(sw, 'local', workers=1, chunk_size=100, progress=False)
    return sw, results.table_text(rows, sw.columns())


def test_table_is_sorted_and_complete(reference_table):
    sw, text = reference_table
    lines = text.splitlines()
    assert len(lines) == 1 + 8
    assert [int(line.split(',')[0]) for line in lines[1:]] == list(range(8))


# Two workers with chunks of one episode: test_a_killed_worker_is_replaced_and_every_row_comes_once
# (the same table after a worker died, the other chunks run as here).
@pytest.mark.parametrize('workers, chunk', [(2, 3), (1, 2)])
def test_table_is_identical_for_any_workers_and_chunks(reference_table, workers, chunk):
    sw, text = reference_table
    rows, run = run_sweep(sw, 'local', workers=workers, chunk_size=chunk, progress=False)
    assert run['workers'] == workers
    assert run['rerun_chunks'] == 0 and run['rerun_episodes'] == ''   # no worker was lost
    assert results.table_text(rows, sw.columns()) == text


def parse_ranges(text):
    """The episode indices of results.episode_ranges' '3-5, 9' form."""
    out = []
    for part in filter(None, text.split(', ')):
        lo, _, hi = part.partition('-')
        out.extend(range(int(lo), int(hi or lo) + 1))
    return out


def test_a_killed_worker_is_replaced_and_every_row_comes_once(reference_table, tmp_path,
                                                              monkeypatch):
    sw, text = reference_table
    marker = tmp_path / 'failed_once'
    monkeypatch.setenv(mc_episodes.FAIL_ONCE_ENV, str(marker))
    rows, run = run_sweep(sw, 'local', workers=2, chunk_size=1, progress=False)
    assert marker.exists()                      # a worker did die
    assert sorted(r['episode'] for r in rows) == list(range(8))
    assert results.table_text(rows, sw.columns()) == text
    # The dead worker's chunk ran again; so did every chunk the broken pool had started and not
    # yet returned (how many the surviving worker took before the break was seen depends on the
    # load, so no tighter bound holds). Chunks of one episode: chunks and episodes correspond.
    killed = [int(e) for e in marker.read_text().split('\n')[1].split()]
    assert len(killed) == 1
    rerun = parse_ranges(run['rerun_episodes'])
    assert killed[0] in rerun and len(rerun) == run['rerun_chunks'] <= 8
    line = rerun_line(run)
    assert f"{run['rerun_chunks']} of 8 chunks ran again" in line and '\n' not in line
    assert rerun_line(dict(run, rerun_chunks=0)) is None              # nothing to say
    assert 'unknown' in rerun_line(dict(run, rerun_chunks=None))     # counts not readable


def test_cli_writes_table_summary_and_plots(tmp_path):
    path = tmp_path / 'cli.yaml'
    path.write_text('name: cli\nseed: 1\nepisodes: 2\nbase: {model: mariner, duration_s: 10, '
                    'route: "scenarios/routes/curved_path_{model}_000.yaml"}\n'
                    'vary: {controller: [los, ilos], start_cross_m: {uniform: [-50, 50]}}\n')
    assert sweep_cli.main([str(path), '--out', str(tmp_path / 'o'), '--workers', '1']) == 0
    out = tmp_path / 'o'
    rows = results.read_table(out / 'results.csv')
    assert len(rows) == 4 and {r['controller'] for r in rows} == {'los', 'ilos'}
    md = (out / 'summary.md').read_text()
    assert md.count('\n| los') == 1 and md.count('\n| ilos') == 1
    assert (out / 'cdf_max_cross_track.png').stat().st_size > 0
    assert (out / 'max_abs_e_m_vs_start_cross_m.png').stat().st_size > 0
    # index.html shows every plot of the folder inline (the bytes of the PNG) and the summary
    page = (out / 'index.html').read_text()
    srcs = re.findall(r'<img src="data:image/png;base64,([^"]+)" alt="([^"]+)"', page)
    assert {alt: base64.b64decode(data) for data, alt in srcs} == \
        {p.name: p.read_bytes() for p in out.glob('*.png')}
    for line in md.splitlines():
        if line.startswith(('| los', '| ilos')):
            first = [c.strip() for c in line.strip('|').split('|')]
            cells = re.search(r'<tr><td>' + first[0] + r'</td>(.*?)</tr>', page).group(1)
            assert [html.unescape(c) for c in re.findall(r'<td[^>]*>(.*?)</td>', cells)] == first[1:]
    # summary.json is a results file: its provenance, and a page renders summary.md's table
    from results_pages.studies import render
    data = json.loads((out / 'summary.json').read_text())
    assert data['provenance']['command'].endswith(f"--out {tmp_path / 'o'} --workers 1")
    table = md.split('\n\n', 1)[1]
    assert table in render('sweeps', 'summary', data).replace('<wbr>', '') and data['run']['episodes'] == 4


def test_where_runs_some_cells_with_the_whole_sweeps_rows(reference_table):
    sw, text = reference_table
    rows, _ = run_sweep(sw, 'local', workers=1, chunk_size=4, progress=False,
                        where={'controller': 'ilos_lead', 'current_speed_mps': 0.9})
    assert [r['episode'] for r in rows] == [6, 7]
    part = results.table_text(rows, sw.columns()).splitlines()
    assert part[1:] == text.splitlines()[7:9]
    with pytest.raises(spec.SweepError, match='not a grid axis value'):
        run_sweep(sw, 'local', workers=1, progress=False, where={'controller': 'policy'})


def _position_at(target, t):
    v = velocity(math.radians(target['course_deg']), target['speed_mps'])
    return np.array([target['north_m'], target['east_m']]) + v * t


@pytest.mark.parametrize('factor', [0.7, 1.3, 2.5])
def test_speed_factor_keeps_every_targets_meeting_point_and_time(factor):
    for number, case in load_cases().items():
        new = encounters.perturbed_case(case, speed_factor=factor)
        for old, t in zip(case['targets'], new['targets']):
            tcpa, dcpa = encounters.target_cpa(case['own'], old)
            assert t['speed_mps'] == pytest.approx(factor * old['speed_mps'], rel=1e-15)
            assert t['course_deg'] == old['course_deg']
            # At the old TCPA the target is where it was (the own ship did not change) ...
            assert _position_at(t, tcpa) == pytest.approx(_position_at(old, tcpa), abs=1e-6)
            # ... so the closest approach stays there (DCPA ~0: the cases meet): the relative
            # position r0 at the old TCPA is kept, |r0| = DCPA; a new relative velocity v'
            # moves the closest time by r0.v' / |v'|^2 and can only shorten the miss.
            tcpa_new, dcpa_new = encounters.target_cpa(case['own'], t)
            v_rel = (velocity(math.radians(t['course_deg']), t['speed_mps'])
                     - velocity(0.0, case['own']['speed_mps']))
            assert dcpa_new <= dcpa + 1e-9
            assert abs(tcpa_new - tcpa) <= dcpa / np.hypot(*v_rel) + 1e-6
    assert encounters.perturbed_case(load_cases()[5]) == load_cases()[5]   # f = 1, d = 0


@pytest.mark.parametrize('miss', [-450.0, 300.0, 1500.0])
@pytest.mark.parametrize('factor', [1.0, 0.8])
def test_miss_offset_gives_the_stated_unmanoeuvred_cpa_at_the_same_time(miss, factor):
    for number, case in load_cases().items():
        scaled = encounters.perturbed_case(case, speed_factor=factor)
        new = encounters.perturbed_case(case, speed_factor=factor, miss_m=miss)
        for old, t in zip(scaled['targets'], new['targets']):
            tcpa0, dcpa0 = encounters.target_cpa(case['own'], old)
            tcpa, dcpa = encounters.target_cpa(case['own'], t)
            # The shift is perpendicular to the relative velocity: the signed miss grows by d,
            # |DCPA - |d|| <= DCPA0 (<= 0.07 m in the Imazu set), equal where DCPA0 = 0.
            assert abs(dcpa - abs(miss)) <= dcpa0 + 1e-6
            assert tcpa == pytest.approx(tcpa0, abs=1e-6)
    # Side: head-on (case 1) and overtaking (case 3), d > 0 puts the target to starboard (east)
    # of the own ship at the CPA; the crossing target from port (case 4) ahead (north) of it.
    for number, axis in ((1, 1), (3, 1), (4, 0)):
        case = load_cases()[number]
        t = encounters.perturbed_case(case, factor, miss)['targets'][0]
        tcpa, _ = encounters.target_cpa(case['own'], t)
        own = np.array([velocity(0.0, case['own']['speed_mps'])[0] * tcpa, 0.0])
        assert np.sign((_position_at(t, tcpa) - own)[axis]) == np.sign(miss)


ENC = {'name': 'enc', 'seed': 2, 'episodes': 2, 'base': {'model': 'mariner', 'duration_s': 30.0},
       'vary': {'encounter': [3], 'colav_method': ['sbmpc', 'vo'],
                'encounter_speed_factor': {'uniform': [0.7, 1.3]},
                'encounter_miss_m': {'normal': [0.0, 300.0]}}}


@pytest.fixture(scope='module')
def encounter_table():
    sw = spec.parse(ENC, 'enc.yaml')
    rows, _ = run_sweep(sw, 'local', workers=1, chunk_size=100, progress=False)
    return sw, rows, results.table_text(rows, sw.columns(), encounters.METRICS)


def test_an_encounter_sweep_is_its_own_kind_with_the_benchmarks_defaults():
    sw = spec.parse({'base': {'encounter': 2}}, 'e.yaml')
    assert sw.kind == 'encounter' and tiny().kind == 'route'
    assert set(sw.columns()) == set(spec.ENCOUNTER_KEYS)
    from imazu.runner import LIMIT_S
    assert sw.base['duration_s'] == LIMIT_S and sw.base['colav_method'] == 'sbmpc'
    assert not set(tiny().columns()) & set(spec.ENCOUNTER_KEYS[2:])


def test_encounter_rows_obey_the_metric_definitions(encounter_table):
    sw, rows, text = encounter_table
    assert [r['episode'] for r in rows] == [0, 1, 2, 3]
    # Paired draws: both methods meet the same two perturbed geometries.
    assert [r['encounter_miss_m'] for r in rows[:2]] == [r['encounter_miss_m'] for r in rows[2:]]
    for r in rows:
        assert r['unmanoeuvred_cpa_m'] == pytest.approx(abs(r['encounter_miss_m']), abs=1e-6)
        assert r['collision'] <= r['near_miss'] <= r['below_r_min']
        assert r['below_r_min'] == int(r['min_distance_m'] < 926.0)
        assert 0.0 <= r['rule_score'] <= 1.0 and r['path_deviation_m'] >= 0.0
        # The geometry met: the range at t = 0 bounds the minimum from above; in 30 s the own
        # ship covers 30 U (~185 m) whatever it does, so the minimum is at least the
        # unmanoeuvred range at 30 s (closing) less that.
        case = load_cases()[3]
        t = encounters.perturbed_case(case, r['encounter_speed_factor'],
                                      r['encounter_miss_m'])['targets'][0]
        own = velocity(0.0, case['own']['speed_mps'])
        r0, r30 = (np.hypot(*(_position_at(t, s) - own * s)) for s in (0.0, 30.0))
        assert r30 - 30.0 * case['own']['speed_mps'] <= r['min_distance_m'] <= r0 + 1e-6


@pytest.mark.parametrize('workers, chunk', [(2, 1)])
def test_encounter_table_is_identical_for_any_workers_and_chunks(encounter_table, workers,
                                                                   chunk):
    sw, _, text = encounter_table
    rows, run = run_sweep(sw, 'local', workers=workers, chunk_size=chunk, progress=False)
    assert run['chunks'] == 4
    assert results.table_text(rows, sw.columns(), encounters.METRICS) == text


def test_encounter_summary_gives_wilson_intervals_for_collisions(encounter_table):
    sw, rows, _ = encounter_table
    kind = results.KINDS['encounter']
    summary = results.summarise(rows, list(sw.grid), kind)
    entry = summary[(3, 'sbmpc')]
    z = stats.norm.ppf(0.975)
    assert entry['collision']['mean'] == 0.0 and entry['collision']['n'] == 2
    assert entry['collision']['high'] == pytest.approx(z * z / (2 + z * z))
    assert entry['min_distance_m']['n'] == 2
    md = results.summary_markdown(summary, list(sw.grid), kind)
    assert md.count('\n| 3 | sbmpc') == 1 and 'min_distance_m' in md


CLI_SWEEP = ('name: cli\nseed: 1\nepisodes: 3\nbase: {model: mariner, duration_s: 10, '
             'route: "scenarios/routes/curved_path_{model}_000.yaml"}\n'
             'vary: {controller: [los, ilos], start_cross_m: {uniform: [-50, 50]}}\n')


def test_a_backend_that_dies_keeps_its_rows_and_resume_completes_the_table(tmp_path, capsys,
                                                                           monkeypatch):
    from montecarlo import backends
    path = tmp_path / 'cli.yaml'
    path.write_text(CLI_SWEEP)
    opts = ['--workers', '1', '--chunk', '1', '--no-plots']
    assert sweep_cli.main([str(path), '--out', str(tmp_path / 'whole'), *opts]) == 0
    whole = (tmp_path / 'whole' / 'results.csv').read_text()
    assert not (tmp_path / 'whole' / results.PARTIAL_NAME).exists()

    real, ran = backends.run_local, []

    def dies_after_two_chunks(chunks, on_rows, **kw):   # like a raylet killed mid-sweep
        ran.append([e['episode'] for c in chunks for e in c])
        if len(ran) == 1:
            real(chunks[:2], on_rows, **kw)
            raise RuntimeError('raylet died\nsecond line of a Ray traceback')
        return real(chunks, on_rows, **kw)
    monkeypatch.setattr(backends, 'run_local', dies_after_two_chunks)
    out = tmp_path / 'broken'
    capsys.readouterr()
    assert sweep_cli.main([str(path), '--out', str(out), *opts]) == 1
    err = [ln for ln in capsys.readouterr().err.splitlines() if ln.startswith('error')]
    assert len(err) == 1 and 'RuntimeError: raylet died;' in err[0]   # one line, no traceback
    err = err[0]
    assert '4 of 6 episodes without a row: 2-5' in err and '--resume' in err
    assert not (out / 'results.csv').exists()
    kept = out / results.PARTIAL_NAME
    assert sorted(json.loads(line)['episode'] for line in kept.read_text().splitlines()[1:]) \
        == [0, 1]

    # Other options than the broken run's: its rows are not mixed in.
    assert sweep_cli.main([str(path), '--out', str(out), *opts, '--resume',
                           '--duration', '11']) == 2
    assert 'another sweep' in capsys.readouterr().err
    assert sweep_cli.main([str(path), '--out', str(out), *opts, '--resume']) == 0
    assert ran[-1] == [2, 3, 4, 5]                       # only the missing episodes ran
    assert (out / 'results.csv').read_text() == whole    # byte for byte
    assert not kept.exists()
    assert sweep_cli.main([str(path), '--out', str(out), *opts, '--resume']) == 2  # nothing left
    assert 'nothing to resume' in capsys.readouterr().err


def test_a_partial_file_cut_mid_line_resumes_from_its_whole_rows(tmp_path):
    sw = tiny(episodes=1)
    eps = spec.expand(sw, None)
    partial = tmp_path / results.PARTIAL_NAME
    rows, _ = run_sweep(sw, 'local', workers=1, chunk_size=1, progress=False, partial=partial)
    text = partial.read_text()
    partial.write_text(text[:text.rindex('\n', 0, -1) + 20])   # the last row cut by a crash
    again, run = run_sweep(sw, 'local', workers=1, chunk_size=1, progress=False,
                           partial=partial, resume=True)
    assert run['resumed_rows'] == len(eps) - 1
    assert results.table_text(again, sw.columns()) == results.table_text(rows, sw.columns())
