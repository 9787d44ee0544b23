"""ship_sim.pacing without DDS: sequence pairing, the realtime schedule, the lockstep gates."""
import numpy as np
import pytest

from ship_sim.pacing import (LockstepPacer, RealtimePacer, SequencePairer, StepGate,
                             MAX_CUT_STEPS, paired_record)


class FakeClock:
    def __init__(self, t=100.0):
        self.t = t

    def __call__(self):
        return self.t


# -- SequencePairer ---------------------------------------------------------------------------
def test_pairer_pairs_the_nth_with_the_nth_whatever_the_arrival_order():
    p = SequencePairer()
    p.push_a('o0')
    p.push_a('o1')
    assert not p.ready and list(p.pairs()) == []
    p.push_b('c0')
    assert list(p.pairs()) == [('o0', 'c0')]
    p.push_b('c1')
    p.push_b('c2')
    p.push_a('o2')
    assert list(p.pairs()) == [('o1', 'c1'), ('o2', 'c2')]
    with pytest.raises(IndexError):
        p.pop()


def test_pairer_skip_drops_the_late_partner_and_keeps_alignment():
    p = SequencePairer()
    p.push_a(0)           # step 0 awaits its command
    p.skip()              # ... which timed out
    p.push_a(1)
    assert p.push_b('late 0') is False and p.n_dropped == 1
    assert p.push_b('c1') is True
    assert list(p.pairs()) == [(1, 'c1')]


def test_paired_record_takes_a_lockstep_record_cut_off_at_its_end():
    stamps = np.array([0.0, 0.1, 0.2, 0.30000000000000004])
    # the answering node got the last odom, the recorder did not: the extra message takes the
    # next step's stamp, the others pair exactly
    got = paired_record(stamps, 5, cut_at_end=True)
    assert np.array_equal(got[:4], stamps) and got[4] == stamps[3] + 0.1
    # the recorder got the last odom, not its answer: the answers pair with the first stamps
    assert np.array_equal(paired_record(stamps, 3, cut_at_end=True), stamps[:3])
    # with a step missing in the stream, or cut by more than MAX_CUT_STEPS, no pairing
    assert paired_record(np.array([0.0, 0.1, 0.3]), 4, cut_at_end=True) is None
    long = np.arange(20) * 0.1
    assert paired_record(long, 20 - MAX_CUT_STEPS - 1, cut_at_end=True) is None
    assert paired_record(long, 20 + MAX_CUT_STEPS + 1, cut_at_end=True) is None
    # not a lockstep record: a message may be missing anywhere, only equal counts pair
    assert paired_record(stamps, 3) is None and paired_record(stamps, 5) is None


def test_paired_record_when_the_counts_agree():
    stamps = np.array([0.0, 0.1, 0.2])
    got = paired_record(stamps, 3)
    assert np.array_equal(got, stamps) and got is not stamps


# -- RealtimePacer ----------------------------------------------------------------------------
def test_realtime_schedule_with_a_fake_clock():
    clock = FakeClock()
    pacer = RealtimePacer(period=1.0, speedup=4.0, clock=clock)   # a step every 0.25 s
    pacer.start(0)
    assert pacer.due(0) == (0, 0)
    clock.t += 0.3
    assert pacer.due(0) == (1, 0)
    pacer.published(1)
    assert pacer.lateness.mean == pytest.approx(0.05)
    clock.t += 0.7                                                 # 1.0 s after the start
    assert pacer.due(1) == (4, 0)
    # a new speedup re-anchors at the current step
    pacer.set_speedup(1.0, 4)
    clock.t += 2.5
    assert pacer.due(4) == (6, 0)


def test_realtime_resets_the_pace_beyond_max_catchup():
    clock = FakeClock()
    pacer = RealtimePacer(period=0.1, clock=clock, max_catchup=50)
    pacer.start(0)
    clock.t += 10.0                                   # 100 steps due
    due, behind = pacer.due(0)
    assert (due, behind) == (50, 100)
    assert pacer.due(50) == (50, 0)                   # re-anchored: nothing more due now
    clock.t += 0.15
    assert pacer.due(50)[0] == 51


# -- LockstepPacer ----------------------------------------------------------------------------
class Host:
    """Records what the pacer asks the node to do."""

    def __init__(self, graph=True):
        self.steps, self.warnings, self.errors, self.stops = [], [], [], []
        self.started = 0
        self.graph_ok = graph
        self.running = True

    def kwargs(self):
        return dict(start=self.start, step=self.step, stop=self.stops.append,
                    warn=self.warnings.append, error=self.errors.append,
                    graph=lambda: self.graph_ok, describe_graph=lambda: 'odom has 0 of 1')

    def start(self):
        self.started += 1
        return self.running

    def step(self, command):
        self.steps.append(command)
        return self.running


def make(host, clock, gates=(), timeout=5.0, max_timeouts=10, start_timeout=30.0,
         last_step=None):
    return LockstepPacer(**host.kwargs(), timeout=timeout, max_timeouts=max_timeouts,
                         start_timeout=start_timeout, gates=gates, clock=clock, grace=0.25,
                         last_step=last_step)


def test_lockstep_starts_after_the_grace_and_steps_once_per_command():
    clock, host = FakeClock(), Host()
    pacer = make(host, clock)
    pacer.on_command(0.1)               # before step 0 went out: it is step 0's
    pacer.watchdog()
    assert host.started == 0            # matched, grace not over
    clock.t += 0.3
    pacer.watchdog()
    assert host.started == 1 and host.steps == [0.1] and pacer.k == 1
    pacer.on_command(None)              # refused: hold the previous command
    pacer.on_command(0.3)
    assert host.steps == [0.1, 0.1, 0.3]


def test_lockstep_start_timeout_warns_and_starts():
    clock, host = FakeClock(), Host(graph=False)
    pacer = make(host, clock, start_timeout=2.0)
    pacer.watchdog()
    clock.t += 2.1
    pacer.watchdog()
    assert host.started == 1
    assert host.warnings == ['lockstep: after 2 s odom has 0 of 1; starting anyway (step 0 may '
                             'be lost)']


def started(pacer, clock):
    pacer.watchdog()
    clock.t += 0.3
    pacer.watchdog()
    assert pacer.started


def test_timeout_holds_the_command_and_drops_the_late_one():
    clock, host = FakeClock(), Host()
    pacer = make(host, clock)
    started(pacer, clock)
    pacer.on_command(0.2)
    clock.t += 5.1
    pacer.watchdog()                    # no command for step 1: hold 0.2
    assert host.steps == [0.2, 0.2] and pacer.n_timeouts == 1
    assert 'no rudder_cmd for step 1 within 5 s; holding 0.2000 rad' in host.warnings[0]
    pacer.on_command(0.9)               # step 1's, late: dropped
    assert pacer.n_stale == 1 and host.steps == [0.2, 0.2]
    pacer.on_command(0.4)               # step 2's
    assert host.steps == [0.2, 0.2, 0.4]


def test_consecutive_timeout_limit_stops_the_run():
    clock, host = FakeClock(), Host()
    pacer = make(host, clock, max_timeouts=3)
    started(pacer, clock)
    for _ in range(3):
        clock.t += 5.1
        pacer.watchdog()
    assert len(host.warnings) == 2 and host.stops == [1] and len(host.errors) == 1
    assert 'no rudder_cmd for 3 consecutive steps' in host.errors[0]
    clock.t += 5.1
    pacer.watchdog()                    # stopped: nothing more
    assert host.stops == [1] and len(host.steps) == 2


def test_a_command_resets_the_consecutive_count():
    clock, host = FakeClock(), Host()
    pacer = make(host, clock, max_timeouts=2)
    started(pacer, clock)
    clock.t += 5.1
    pacer.watchdog()
    pacer.on_command(0.0)               # step 0's, late: dropped, no reset
    pacer.on_command(0.0)               # step 1's: resets the count
    clock.t += 5.1
    pacer.watchdog()
    assert host.stops == [] and pacer.n_timeouts == 2


def test_gate_holds_at_the_window_and_releases_on_acks():
    clock, host = FakeClock(), Host()
    gate = StepGate('the recorder', window=2, needed_at_start=True)
    pacer = make(host, clock, gates=[gate])
    pacer.watchdog()
    clock.t += 1.0
    pacer.watchdog()
    assert host.started == 0            # the recorder has not been heard from
    gate.acknowledge(0)
    pacer.on_gate()
    started(pacer, clock)
    for _ in range(4):
        pacer.on_command(0.0)
    assert pacer.k == 2 and gate.waits == 2   # steps 1, 2 went out; step 3 > 0 + 2 waits
    # (a wait is counted each time the closed gate is asked, here on each of two commands)
    gate.acknowledge(1)
    pacer.on_gate()
    assert pacer.k == 3 and gate.waits == 3   # released one step, then closed again
    gate.acknowledge(5)
    pacer.on_gate()
    assert pacer.k == 4 and host.warnings == []


def test_a_gate_closed_for_a_timeout_is_given_up_with_one_warning():
    clock, host = FakeClock(), Host()
    gate = StepGate('follower /vessel_1/odom', window=1, heard=0)
    pacer = make(host, clock, gates=[gate])
    started(pacer, clock)
    pacer.on_command(0.0)
    pacer.on_command(0.0)               # step 2 would be beyond 0 + 1: held
    assert pacer.k == 1
    clock.t += 5.1
    pacer.watchdog()
    assert gate.given_up and pacer.k == 2
    assert host.warnings == ['lockstep: follower /vessel_1/odom took 0 steps and no more within '
                             '5 s; going on without waiting for it (it may miss messages)']
    pacer.on_command(0.0)
    assert pacer.k == 3 and len(host.warnings) == 1


def test_the_last_step_ends_the_run_once_answered_and_recorded():
    """A run of steps 0..3 ends after step 3's command has come and the recorder holds all four
    steps (window 0 at the end), not when step 3 goes out: the record then has every answer."""
    clock, host = FakeClock(), Host()
    gate = StepGate('the recorder', window=2, needed_at_start=True)
    gate.acknowledge(0)
    pacer = make(host, clock, gates=[gate], last_step=3)
    started(pacer, clock)
    for k in range(3):
        gate.acknowledge(k + 1)
        pacer.on_command(0.1)
    assert pacer.k == 3 and host.stops == []
    pacer.on_command(0.2)               # step 3's answer; the recorder has taken steps 0..2
    assert host.stops == [] and len(host.steps) == 3
    gate.acknowledge(4)
    pacer.on_gate()
    assert host.stops == [0] and len(host.steps) == 3 and host.warnings == []
    pacer.on_command(0.3)               # nothing after the end
    assert host.stops == [0] and len(host.steps) == 3


def test_the_last_step_without_its_answer_ends_after_the_timeout_with_a_warning():
    clock, host = FakeClock(), Host()
    pacer = make(host, clock, last_step=1)
    started(pacer, clock)
    pacer.on_command(0.0)
    assert pacer.k == 1 and host.stops == []
    clock.t += 4.9
    pacer.watchdog()
    assert host.stops == []
    clock.t += 0.2
    pacer.watchdog()
    assert host.stops == [0] and len(host.steps) == 1 and pacer.n_timeouts == 0
    assert host.warnings == ['lockstep: the last step 1 ends the run without its rudder_cmd '
                             'after 5 s']
