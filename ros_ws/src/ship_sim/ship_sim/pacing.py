"""When the simulator's next step goes out: the realtime pacer and the lockstep gates (pure).

vessel_node owns the parameters, topics and the simulator; this module decides when it steps,
so the rules can be tested without DDS, with a fake clock (any callable returning seconds).

- ``RealtimePacer``: steps due by the wall clock at ``speedup`` (period / speedup apart). Steps
  that fell behind are caught up at once, at most ``max_catchup`` per tick; beyond that the
  pace is reset (the caller warns). Lateness and interval of every published step are kept.
- ``LockstepPacer``: publish step k, then step k+1 only once the command for step k has come
  (paired by sequence, ``SequencePairer``) and every ``StepGate`` (the recorder's
  acknowledgements, the followers' odom) is within its window. Step 0 waits for the graph (the
  caller's ``graph`` check and every gate that is needed at start) plus ``grace`` seconds, or
  ``start_timeout`` (warning). A command missing for ``timeout`` seconds: a warning, the
  previous command is held for that step, and its late message is dropped when it comes, so
  the pairing stays aligned; ``max_timeouts`` in a row end the run (error, stop(1)). A gate
  closed for ``timeout`` seconds is given up (warning once per gate), not waited for again.
  With ``last_step``, the run ends (stop(0)) once that step's command has come and every gate
  has taken every step (window 0), so the record holds the answer to the last step too; a
  command or gate missing for ``timeout`` seconds there ends it anyway, with a warning.
- ``SequencePairer``: lockstep pairing by sequence (doc/design.md "Lockstep needs a deterministic
  pairing of messages"): every producer publishes exactly one message per step, so the n-th
  message of one stream belongs with the n-th of another. The simulator pairs its steps with
  rudder_cmd, the autopilot odom with heading_cmd; ``paired_record`` is the same rule applied
  to a whole recorded topic (ship_mission.bag).
"""
import collections
import math
import time

import numpy as np

# Extra wall time after the lockstep graph has matched, before step 0 goes out: the match is
# seen from the simulator's side only; the controller's rudder_cmd writer must also have
# matched its reader, or the first command is lost (a volatile reader gets nothing sent before
# matching).
START_GRACE_S = 0.25
# Realtime: most steps run in one timer tick when catching up; beyond it the pace is reset.
MAX_CATCHUP = 50


class SequencePairer:
    """Pair two streams by sequence: the n-th item pushed to A with the n-th pushed to B.

    ``skip()`` lets the oldest unpaired index go by without its pair (a lockstep timeout): what
    is held of it is dropped, and its partner, when it comes, is dropped too (``n_dropped``),
    so every later pair stays aligned.
    """

    __slots__ = ('_a', '_b', 'n_a', 'n_b', 'n_dropped', '_floor')

    def __init__(self):
        self._a, self._b = collections.deque(), collections.deque()
        self.n_a = self.n_b = 0    # items pushed so far (the index of the next one)
        self.n_dropped = 0         # items that came after their index had been skipped
        self._floor = 0            # lowest index that can still be paired

    def push_a(self, item):
        """Add the next item of stream A; False if its index was skipped (item dropped)."""
        index, self.n_a = self.n_a, self.n_a + 1
        return self._hold(self._a, index, item)

    def push_b(self, item):
        """Add the next item of stream B; False if its index was skipped (item dropped)."""
        index, self.n_b = self.n_b, self.n_b + 1
        return self._hold(self._b, index, item)

    def _hold(self, queue, index, item):
        if index < self._floor:
            self.n_dropped += 1
            return False
        queue.append(item)
        return True

    @property
    def ready(self):
        """A pair is complete (both streams hold the item of the lowest open index)."""
        return bool(self._a) and bool(self._b)

    def pop(self):
        """The next complete pair (a, b); IndexError if there is none."""
        if not self.ready:
            raise IndexError('no complete pair')
        self._floor += 1
        return self._a.popleft(), self._b.popleft()

    def pairs(self):
        """Pop every complete pair, in order."""
        while self._a and self._b:
            yield self.pop()

    def skip(self):
        """Let the lowest open index go by unpaired."""
        for queue in (self._a, self._b):
            if queue:
                queue.popleft()
        self._floor += 1


#: Most steps a record may be cut off at its end and still be paired (paired_record): the
#: simulator stopped with its last steps in flight (lockstep keeps at most
#: lockstep_record_window, 4, of them unacknowledged).
MAX_CUT_STEPS = 4


def paired_record(stamps, count, cut_at_end=False):
    """The pairing rule applied to a whole record: a topic with ``count`` messages recorded next
    to a stream with ``stamps`` was paired with it message by message, so message n takes
    stamps[n] (a copy), when the counts agree.

    With ``cut_at_end`` (a lockstep record, which loses nothing in its middle: the simulator
    waits for the recorder) a record cut off at its end is paired too, when the stream's stamps
    are evenly spaced and the counts differ by at most MAX_CUT_STEPS: the simulator was stopped with
    its last steps in flight, so the recorder got an answer to an odom it did not get (the
    extra messages take the next steps' stamps) or an odom whose answer it did not get (the
    messages pair with the first stamps). None otherwise (a message lost, a partial record):
    then the pairing cannot be recovered."""
    stamps = np.asarray(stamps)
    if count == len(stamps):
        return stamps.copy()
    if not cut_at_end or len(stamps) < 2 or abs(count - len(stamps)) > MAX_CUT_STEPS:
        return None
    step = np.diff(stamps)
    if not (step[0] > 0 and np.all(np.abs(step - step[0]) <= 1e-6 * step[0])):
        return None
    if count < len(stamps):
        return stamps[:count].copy()
    return np.concatenate([stamps, stamps[-1] + step[0] * np.arange(1, count - len(stamps) + 1)])


class RunningStats:
    """Mean / standard deviation / max of a stream of numbers (Welford 1962), no storage."""

    __slots__ = ('n', 'mean', 'm2', 'max')

    def __init__(self):
        self.n, self.mean, self.m2, self.max = 0, 0.0, 0.0, -math.inf

    def add(self, x):
        self.n += 1
        d = x - self.mean
        self.mean += d / self.n
        self.m2 += d * (x - self.mean)
        if x > self.max:
            self.max = x

    @property
    def std(self):
        return math.sqrt(self.m2 / (self.n - 1)) if self.n > 1 else 0.0


class RealtimePacer:
    """Which steps are due by the wall clock. ``period``: sim seconds per step."""

    def __init__(self, period, speedup=1.0, clock=time.monotonic, max_catchup=MAX_CATCHUP):
        self.period, self.speedup, self.clock = float(period), float(speedup), clock
        self.max_catchup = int(max_catchup)
        self.lateness, self.interval = RunningStats(), RunningStats()
        self.anchor_k = 0
        self.anchor_wall = self.last_publish = None

    @property
    def wall_period(self):
        return self.period / self.speedup

    def start(self, k):
        """Step ``k`` goes out now: the schedule is anchored at it."""
        self.anchor_k = k
        self.anchor_wall = self.last_publish = self.clock()

    def set_speedup(self, speedup, k):
        """A new speedup from step ``k`` (the current one) on: re-anchor the schedule."""
        self.speedup = float(speedup)
        self.anchor_k = k
        self.anchor_wall = self.clock()

    def due(self, k):
        """(the step that should have gone out by now, steps behind when the pace was reset or
        0). With step ``k`` the latest published, steps k+1 .. due are to go out now."""
        now = self.clock()
        due = self.anchor_k + int((now - self.anchor_wall) / self.wall_period)
        behind = due - k
        if behind <= self.max_catchup:
            return due, 0
        due = k + self.max_catchup
        self.anchor_k, self.anchor_wall = due, now
        return due, behind

    def published(self, k):
        """Step ``k`` has just gone out: record its lateness and the interval since the last."""
        t = self.clock()
        self.lateness.add(t - (self.anchor_wall + (k - self.anchor_k) * self.wall_period))
        self.interval.add(t - self.last_publish)
        self.last_publish = t

    def summary(self):
        late, gap = self.lateness, self.interval
        return (f'realtime x{self.speedup:g} pacing over {late.n} steps: lateness mean '
                f'{late.mean * 1e3:.3f} ms, sd {late.std * 1e3:.3f} ms, max {late.max * 1e3:.3f} ms; '
                f'interval mean {gap.mean * 1e3:.3f} ms (nominal {self.wall_period * 1e3:.3f}), '
                f'sd {gap.std * 1e3:.3f} ms')


class StepGate:
    """Lockstep: someone who must keep up with the steps (the recorder, a platoon follower).

    ``acked`` is how many steps it has taken (None before it was heard from); step k may go out
    while k <= acked + window. One that falls behind for a whole lockstep timeout is given up
    (no longer waited for) rather than stopping the run.
    """

    __slots__ = ('name', 'window', 'needed_at_start', 'acked', 'waits', 'given_up', 'sub')

    def __init__(self, name, window, needed_at_start=False, heard=None):
        self.name, self.window, self.needed_at_start = name, int(window), needed_at_start
        self.acked, self.waits, self.given_up, self.sub = heard, 0, False, None

    @property
    def ready(self):
        return not self.needed_at_start or self.acked is not None

    def acknowledge(self, steps):
        self.acked = steps

    def open_for(self, k):
        return self.given_up or self.acked is None or k <= self.acked + self.window


class LockstepPacer:
    """The lockstep state machine (module docstring). The caller supplies the actions:

    ``start()``: publish step 0, return whether the node still runs; ``step(command)``: advance
    one step with ``command`` (rad), publish it, return whether the node still runs;
    ``stop(code)``; ``warn(text)``, ``error(text)``: log; ``graph()``: whether the graph has
    matched (subscribers and publishers there); ``describe_graph()``: what it has, for the
    start-timeout warning. Then it calls ``watchdog()`` periodically, ``on_command(value)`` for
    each command (None: refused, hold the previous one; it still counts as that step's) and
    ``on_gate()`` after a gate heard from its topic.
    """

    def __init__(self, *, start, step, stop, warn, error, graph, describe_graph, timeout,
                 max_timeouts, start_timeout, gates=(), clock=time.monotonic,
                 grace=START_GRACE_S, command=0.0, last_step=None):
        self._start_cb, self._step_cb, self._stop_cb = start, step, stop
        self._warn, self._error = warn, error
        self._graph, self._describe_graph = graph, describe_graph
        self.timeout, self.max_timeouts = float(timeout), int(max_timeouts)
        self.start_timeout, self.grace, self.clock = float(start_timeout), float(grace), clock
        self.gates = list(gates)
        self.last_step = last_step   # None: no end; else stop(0) once it is answered and taken
        self.command = command       # the command held (rad)
        self.pairer = SequencePairer()   # A: steps published, B: commands
        self.k = 0                   # the step published last (awaiting its command)
        self.started = self.running = False
        self.n_timeouts = 0          # steps run with a held command after a timeout
        self.n_consecutive = 0       # timeouts in a row
        self._t_start_wait = clock()
        self._matched_at = self._waiting_since = self._gate_closed_since = None

    @property
    def n_stale(self):
        """Commands that came after their step had gone by on a timeout (dropped)."""
        return self.pairer.n_dropped

    # -- inputs --------------------------------------------------------------------------------
    def on_command(self, value):
        if not self.pairer.push_b(value):
            return   # its step already went by on a timeout: pairing stays aligned
        self.n_consecutive = 0
        self.drain()

    def on_gate(self):
        if self.running:
            self.drain()

    def watchdog(self):
        now = self.clock()
        if not self.started:
            matched = self._graph() and all(g.ready for g in self.gates)
            if matched and self._matched_at is None:
                self._matched_at = now
            if self._matched_at is not None and now - self._matched_at >= self.grace:
                self._start()
            elif now - self._t_start_wait > self.start_timeout:
                self._warn(f'lockstep: after {self.start_timeout:g} s {self._describe_graph()}'
                           + ''.join(f', nothing yet from {g.name}' for g in self.gates
                                     if not g.ready)
                           + '; starting anyway (step 0 may be lost)')
                self._start()
            return
        if not self.running or self.timeout <= 0.0:
            return
        if self._at_end() and not self._ended() and now - self._waiting_since > self.timeout:
            missing = [] if self.pairer.ready else ['its rudder_cmd']
            missing += [g.name for g in self.gates if not self._taken_all(g)]
            self._warn(f'lockstep: the last step {self.k} ends the run without '
                       f'{" and ".join(missing)} after {self.timeout:g} s')
            self._end()
            return
        if self.pairer.ready:  # the command is here: waiting for a gate
            if (self._gate_closed_since is not None
                    and now - self._gate_closed_since > self.timeout):
                for g in self.gates:
                    if not g.open_for(self.k + 1):
                        g.given_up = True
                        self._warn(f'lockstep: {g.name} took {g.acked} steps and no more within '
                                   f'{self.timeout:g} s; going on without waiting for it (it may '
                                   'miss messages)')
                self.drain()
            return
        if self._waiting_since is not None and now - self._waiting_since > self.timeout:
            self.n_timeouts += 1
            self.n_consecutive += 1
            if self.max_timeouts and self.n_consecutive >= self.max_timeouts:
                self._error(
                    f'lockstep: no rudder_cmd for {self.n_consecutive} consecutive steps (up to '
                    f'step {self.k}, {self.timeout:g} s each; lockstep_max_timeouts '
                    f'{self.max_timeouts}): is the controller running? Stopping')
                self.running = False
                self._stop_cb(1)
                return
            self._warn(f'lockstep: no rudder_cmd for step {self.k} within {self.timeout:g} s; '
                       f'holding {self.command:.4f} rad for this step ({self.n_timeouts} timeouts '
                       'so far; the run is no longer deterministic)')
            self.pairer.skip()
            self._step()

    # -- stepping ------------------------------------------------------------------------------
    def _start(self):
        self.started = True
        self.running = bool(self._start_cb())
        self.k = 0
        self.pairer.push_a(0)
        self._waiting_since = self.clock()
        # A command may have come before step 0 went out (it is then step 0's).
        self.drain()

    def gates_open(self):
        """May the next step go out? Every gate must be within its window of it (a closed gate
        counts a wait)."""
        closed = [g for g in self.gates if not g.open_for(self.k + 1)]
        for g in closed:
            g.waits += 1
        return not closed

    def _at_end(self):
        return self.last_step is not None and self.k >= self.last_step

    def _taken_all(self, gate):
        return gate.given_up or gate.acked is None or gate.acked > self.k

    def _end(self):
        self.running = False
        self._stop_cb(0)

    def _ended(self):
        """At the last step: end the run if it is answered and taken (whether it ended)."""
        if self.pairer.ready and all(map(self._taken_all, self.gates)):
            self._end()
            return True
        return False

    def drain(self):
        while self.pairer.ready and self.running:
            if self._at_end():
                self._ended()
                return
            if not self.gates_open():
                if self._gate_closed_since is None:
                    self._gate_closed_since = self.clock()
                return
            self._gate_closed_since = None
            _, value = self.pairer.pop()
            if value is not None:
                self.command = value
            self._step()

    def _step(self):
        self.running = bool(self._step_cb(self.command))
        self.k += 1
        self.pairer.push_a(self.k)
        self._waiting_since = self.clock()
