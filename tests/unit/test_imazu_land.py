"""Land in the Imazu runner (run_scenario(..., land=chart)) and the coast of the land study
(imazu.land, scripts/imazu_land.py), on the first minutes of case 2: one target crossing from
starboard, so the own ship gives way to starboard, towards a coast on that side."""
import tempfile

import numpy as np
import pytest

from imazu import land as coast
from imazu.cases import load_cases
from imazu.runner import case_scenario, land_mask, run_scenario, write_scenario

from ship_guidance.colav_params import ColavParams
from ship_planner.chart import Chart

CASE = 2
#: Sim time of the runs: past the give-way turn (colav acts once the meeting, 20 min ahead,
#: enters its horizon; then some minutes on the new course).
DURATION_S = 1200.0 - ColavParams().horizon_s + 240.0


def _run(chart):
    sc, route = case_scenario(CASE, load_cases()[CASE], 'mariner', 'sbmpc', DURATION_S)
    with tempfile.TemporaryDirectory() as tmp:
        return run_scenario(write_scenario(sc, route, tmp), land=chart)


@pytest.fixture(scope='module')
def without_land():
    return _run(None)


def _same(a, b):
    return (np.array_equal(a.t, b.t) and np.array_equal(a.own, b.own)
            and np.array_equal(a.heading, b.heading) and a.decisions == b.decisions
            and all(np.array_equal(a.targets[n], b.targets[n]) for n in a.targets))


def test_land_mask_puts_the_charts_land_cells_where_the_chart_has_them():
    water = np.ones((5, 7), dtype=bool)
    water[2, 4] = False                       # centre at north 100 + 2 * 10, east -50 + 4 * 10
    chart = Chart(water, 10.0, north0=100.0, east0=-50.0)
    mask = land_mask(chart, 0.0)
    centre = np.array([120.0, -10.0])
    assert mask.hits(centre)
    # anywhere in the cell, and not in the cells beside it
    assert mask.hits(centre + [4.9, -4.9]) and mask.hits(centre + [-4.9, 4.9])
    for step in ([10.0, 0.0], [-10.0, 0.0], [0.0, 10.0], [0.0, -10.0]):
        assert not mask.hits(centre + step)
    # widened by the clearance as colav_node widens the /map grid
    assert land_mask(chart, 10.0).hits(centre + [10.0, 0.0])


#: Each of these tests runs minutes of closed loop (one or two runs): seconds of CPU, but on
#: the shared 2-core machine under load, longer than the default timeout.
@pytest.mark.timeout(1200)
def test_land_out_of_reach_leaves_the_run_bit_for_bit_as_without_land(without_land):
    assert any(d[1] == 'avoid' and d[2] > 0.0 for d in without_land.decisions)  # gives way
    # a coast farther to starboard than any scenario's prediction reaches (from the farthest
    # the ship got, a horizon at its top speed, and a margin): the grounding cost is zero for
    # every scenario, so every decision and the whole run are today's
    reach = (float(without_land.own[:, 1].max())
             + ColavParams().horizon_s * float(without_land.own[:, 3].max()) + 1000.0)
    far = coast.coast_chart(offset_m=reach, extent_m=(-3000.0, 27000.0, -8000.0, reach + 2000.0),
                            resolution_m=50.0)
    assert _same(_run(far), without_land)


@pytest.mark.timeout(1200)
def test_the_grounding_cost_keeps_the_own_ship_off_a_coast_it_crosses_without_it(without_land):
    # the coast halfway out to the farthest the give-way took the ship without land: without
    # land in its cost the ship runs onto it, by construction
    farthest = float(without_land.own[:, 1].max())
    assert farthest > 2.0 * ColavParams().grounding_clearance_m   # a turn that reaches it
    chart = coast.coast_chart(offset_m=0.5 * farthest)
    assert coast.land_outcome(chart, without_land.t, without_land.own)['grounded']
    with_land = _run(chart)
    outcome = coast.land_outcome(chart, with_land.t, with_land.own)
    assert not outcome['grounded'] and outcome['time_on_land_s'] == 0.0
    assert float(with_land.own[:, 1].max()) < 0.5 * farthest
    # and it still gave way (it acted on the target), only not across the coast
    assert any(d[1] == 'avoid' for d in with_land.decisions)


def test_land_outcome_reads_distance_and_time_on_land():
    chart = coast.coast_chart(offset_m=1000.0, resolution_m=20.0)
    t = np.arange(5.0)
    track = np.array([[0.0, 0.0], [0.0, 505.0], [0.0, 1100.0], [0.0, 1200.0], [0.0, 0.0]])
    out = coast.land_outcome(chart, t, track)
    assert out['grounded'] and out['time_on_land_s'] == 2.0
    assert out['min_land_distance_m'] == 0.0
    away = coast.land_outcome(chart, t[:2], track[:2])
    # cell centres: the nearest land cell centre is the first one east of 1000 m, the ship's
    # cell centre within half a cell of it
    assert not away['grounded']
    assert abs(away['min_land_distance_m'] - (1000.0 - 505.0)) <= chart.resolution_m
