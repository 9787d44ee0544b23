"""A failure of the failure search replayed through the node graph (real processes, the
launcher, lockstep): the bag's own-target minimum distance equals the in-process run's to 1 m
(issue 30 item 2).

The failure is built with the search's own geometry (colav_search.encounter), short enough
for the suite: the mariner with SB-MPC and one target on a reciprocal course at 1.6 times its
speed, on a collision course (CPA offset 0) meeting at 120 s, so it starts under 2 km ahead
closing at 16 m/s; the mariner cannot turn far enough in time and the target comes inside its
domain (a near miss). The scenario is written as the search writes a failure
(episode.write_failure's header), its duration cut to 10 s past the closest approach.
"""
import numpy as np
import pytest

from colav_search import encounter, episode, replay
from harness import run_to_duration

SHIP, METHOD, MEETING_S = 'mariner', 'sbmpc', 120.0


def _short_failure():
    x = np.full(encounter.DIM, 0.5)
    low, high = encounter.MEETING[1:3]
    x[0] = (MEETING_S - low) / (high - low)          # below the search's box: a short run
    x[encounter.slot_dims(0)] = [1.0, 1.0, 0.5]      # reciprocal course, speed ratio 1.6, CPA 0
    return 1, x


@pytest.mark.timeout(300)
def test_a_found_failure_replayed_on_the_graph_has_the_in_process_min_distance(launch, tmp_path):
    n, x = _short_failure()
    row = episode.run(n, x, SHIP, METHOD)
    assert row['failure'], row
    assert row['t_min_s'] < MEETING_S + 30.0, 'the closest approach is near the meeting'
    row = dict(row, end_s=round(row['t_min_s'] + 10.0, 1))
    path = episode.write_failure(n, x, SHIP, METHOD, row, tmp_path / 'failure', 'short_failure')

    run = run_to_duration(launch, path, wall_timeout_s=200.0)
    replayed = replay.run_min_distance(run)
    assert replayed == pytest.approx(replay.in_process_min_distance(path),
                                     abs=replay.TOLERANCE_M)
