"""Recorded AIS in, CPA/TCPA out: the log reader (ship_guidance.ais_log), the replay through the
tracker (ship_guidance.cpa_replay) against known tracks, a real tag-block log, the script.

Ground truth: ships on straight tracks encoded by ship_guidance.ais_replay (pyais), so the
only error between the log and the truth is AIS's quantisation; the tool's CPA and TCPA must
match the analytic CPA of the true tracks within the worst case that quantisation can cause
through the tracker's own gains (derived in ``quantisation_bound``).

Real log: tests/data/ais/risky_exact_earth_tag_block.txt (tests/data/README.md: 221 lines of
a satellite receiver with NMEA 4.0 tag blocks, g: groups, static data stamped with older
times); what the tool reports is compared with what pyais decodes from the same file.
"""
import csv
import json
import math
from functools import reduce
from pathlib import Path

import numpy as np
import pyais
import pytest

from ship_guidance.ais import KNOT
from ship_guidance.ais_log import LogFormatError, read_log, read_log_file
from ship_guidance.ais_replay import replay_lines
from ship_guidance.cpa import cpa, cpa_sigma
from ship_guidance.cpa_replay import FixedOwnShip, ReplayConfig, ReplayError, replay
from ship_guidance.tracker import AisReport, TrackerConfig, measurement, transition
from ship_sim.geodetic import ned_to_geodetic

DATA = Path(__file__).resolve().parents[1] / 'data' / 'ais'
REAL = DATA / 'risky_exact_earth_tag_block.txt'
ORIGIN = (34.86, 128.73)               # scenarios/routes/busan_passage.yaml
OWN = 257000001
PERIOD_S = 10.0
#: Ships of the known-tracks case: MMSI -> (north m, east m at t = 0, course deg, speed kn).
#: Speeds and courses are not multiples of AIS's 0.1 kn and 0.1 deg, so that every report
#: carries a SOG and COG quantisation error (the same one throughout: the truth is constant).
SHIPS = {OWN: (0.0, 0.0, 3.33, 12.34),
         257000002: (3000.0, 3000.0, 271.27, 10.06),     # crossing from starboard
         257000003: (6000.0, -500.0, 181.61, 14.47),     # nearly head-on, passing 750 m off
         257000004: (1000.0, -4000.0, 58.88, 9.12)}      # crossing from port
DURATION_S = 600.0


def checksum(text):
    return '%02X' % reduce(lambda a, c: a ^ ord(c), text, 0)


def tag_line(fields, sentence):
    return f'\\{fields}*{checksum(fields)}\\{sentence}'


def truth(mmsi, t):
    n0, e0, course, speed = SHIPS[mmsi]
    v = speed * KNOT * np.array([math.cos(math.radians(course)), math.sin(math.radians(course))])
    return np.array([n0, e0]) + v * t, v


def report_times(mmsi):
    """Class A at 10-14 kn reports every 10 s; each ship at its own phase (mmsi % 7 s)."""
    return np.arange(0.0, DURATION_S + 1e-9, 10.0) + mmsi % 7


def known_lines(vdo=False):
    lines = []
    for mmsi, (_, _, course, speed) in SHIPS.items():
        t = report_times(mmsi)
        p = np.array([truth(mmsi, x)[0] for x in t])
        ship = replay_lines(mmsi, t, p[:, 0], p[:, 1], np.full(t.size, speed * KNOT),
                            np.full(t.size, math.radians(course)), *ORIGIN)
        if vdo and mmsi == OWN:
            ship = [as_vdo(x) for x in ship]
        lines += ship
    return lines


def as_vdo(line):
    """The same report as the own ship's transponder sends it (AIVDO), checksum recomputed."""
    t, sentence = line.split(' ')
    body = sentence[1:sentence.index('*')].replace('AIVDM', 'AIVDO')
    return f'{t} !{body}*{checksum(body)}'


# -- the log reader -----------------------------------------------------------------------------

REAL_GROUP = REAL.read_text().splitlines()[:3]     # a g: group of two parts, then a report


def test_replay_form_sorted_comments_skipped():
    a, b = (x.split()[1] for x in known_lines()[:2])
    log = read_log(['# a comment', '', f'20 {b}', f'  3.5   {a}'])
    assert log.form == 'replay' and log.lines == 2 and not log.rejected
    assert log.sentences == [(3.5, a), (20.0, b)]


def test_tag_block_times_groups_and_milliseconds():
    log = read_log(REAL_GROUP)
    assert log.form == 'tag_block' and log.unix_time
    # The group's second part has no c: and takes its first part's time.
    assert [t for t, _ in log.sentences] == [1334337317.0] * 3 and log.inherited == 1
    assert log.sentences[1][1].startswith('!AIVDM,2,2,9,B,')
    sentence = REAL_GROUP[2].split('\\')[2]
    ms = read_log([tag_line('c:1334337317250', sentence)])
    assert ms.sentences == [(1334337317.25, sentence)]


def test_bad_tag_blocks_and_lines_are_counted_not_used():
    good = REAL_GROUP[2]
    bad_sum = good.replace('*58\\', '*59\\')
    no_sum = good.replace('*58\\', '\\')
    log = read_log([good, bad_sum, no_sum, 'IamNotAnAisMessage1111', '12.0 not-a-sentence',
                    tag_line('c:soon', good.split('\\')[2])])
    assert dict(log.rejected) == {'tag_block_checksum': 1, 'bad_tag_block': 1,
                                  'not_a_sentence': 2, 'bad_time': 1}
    assert len(log.sentences) == 1


def test_untimed_lines_at_the_stated_rate():
    lines = (DATA / 'pyais_samples.nmea').read_text().splitlines()
    with pytest.raises(LogFormatError, match='no times'):
        read_log(lines)
    log = read_log(lines, rate=2.0)
    assert log.form == 'untimed'
    times = [t for t, _ in log.sentences]
    assert times[:3] == [0.0, 0.5, 1.0]
    # The two sentences of the message 5 (part 2 follows part 1) share one time.
    i = next(k for k, (_, s) in enumerate(log.sentences) if s.startswith('!AIVDM,2,2,'))
    assert times[i] == times[i - 1]


def test_ambiguous_logs_are_refused_in_one_line():
    timed = known_lines()[:2]
    for lines, rate, what in ((timed + REAL_GROUP, None, 'two clocks'),
                              (timed, 1.0, 'only for logs without times'),
                              (['hello', '# nothing'], None, 'no line')):
        with pytest.raises(LogFormatError, match=what) as exc:
            read_log(lines, rate)
        assert '\n' not in str(exc.value)
    # A line without time before the first timed one has no time to take.
    plain = timed[0].split()[1]
    log = read_log([plain] + timed)
    assert log.rejected == {'no_time': 1} and len(log.sentences) == 2


# -- the CPA sigma --------------------------------------------------------------------------------

def test_cpa_sigma_is_the_covariance_through_cpa():
    """Against the Jacobian of ``cpa`` by central differences (states with DCPA well away from
    0, where |s| and DCPA have the same gradient up to sign)."""
    rng = np.random.default_rng(7)
    for _ in range(20):
        p = rng.uniform(-5000.0, 5000.0, 2)
        v = rng.uniform(-8.0, 8.0, 2)
        A = rng.normal(size=(4, 4)) * [1.0, 1.0, 0.05, 0.05]
        cov = A @ A.T
        tc, dc = cpa(np.zeros(2), np.zeros(2), p, v)
        if dc < 100.0:
            continue
        jac = np.zeros((2, 4))
        x = np.concatenate([p, v])
        for k, h in enumerate((1e-3, 1e-3, 1e-6, 1e-6)):
            d = np.zeros(4)
            d[k] = h
            hi = cpa(np.zeros(2), np.zeros(2), (x + d)[:2], (x + d)[2:])
            lo = cpa(np.zeros(2), np.zeros(2), (x - d)[:2], (x - d)[2:])
            jac[:, k] = (np.array(hi) - np.array(lo)) / (2.0 * h)
        want = np.sqrt(np.diag(jac @ cov @ jac.T))
        got = cpa_sigma(np.zeros(2), np.zeros(2), p, v, cov)
        np.testing.assert_allclose(got, want, rtol=1e-5)


# -- known tracks -------------------------------------------------------------------------------

#: Worst-case AIS quantisation of what the tracker is given (ship_guidance.ais_replay encodes,
#: pyais decodes): latitude and longitude rounded to 1/600000 deg by the encoder and then to
#: 1e-6 deg by pyais's decoder, at most 0.5/600000 + 0.5e-6 deg, times at most 111.7 km per
#: degree (a degree of latitude at the poles, the longest; a degree of longitude is shorter);
#: SOG and COG rounded to 0.1 kn and 0.1 deg (exactly: pyais encodes tenths without error).
Q_POSITION_M = (0.5 / 600000.0 + 0.5e-6) * 111_700.0
Q_SOG_MPS = 0.05 * KNOT
Q_COG_RAD = math.radians(0.05)


def sensitivities(mmsi, config):
    """Per report k of the ship: [(t_k, [S_j])] with S_j = d x_k / d z_j, the filter's
    estimate after report k against report j's measurement (north, east, v_north, v_east),
    and the M_j mapping (d north, d east, d SOG, d COG) to d z_j.

    The filter is linear in its measurements for given gains: after report k,
    x_k = (I - K_k) F x_(k-1) + K_k z_k (H = I), started from x_0 = z_0; so
    d x_k / d z_j = (I - K_k) F d x_(k-1) / d z_j and d x_k / d z_k = K_k, with K_k =
    P_pred (P_pred + R_k)^-1. The gains are computed here from the tracker's own model
    (tracker.transition, tracker.measurement) at the true SOG and COG; the quantised values
    change them by a relative 1e-3, a second-order effect on the error."""
    _, _, course, speed = SHIPS[mmsi]
    sog, cog = speed * KNOT, math.radians(course)
    c, s = math.cos(cog), math.sin(cog)
    M = np.zeros((4, 4))
    M[0, 0] = M[1, 1] = 1.0
    M[2:, 2:] = [[c, -sog * s], [s, sog * c]]                # polar -> NED velocity
    out, S, P, t_prev = [], [], None, None
    for t in report_times(mmsi):
        _, _, R = measurement(AisReport(mmsi, t, 0.0, 0.0, sog, cog), config)
        if P is None:
            S, P = [np.eye(4)], R.copy()
        else:
            F, Q = transition(t - t_prev, config.process_noise)
            P_pred = F @ P @ F.T + Q
            K = P_pred @ np.linalg.inv(P_pred + R)
            A = (np.eye(4) - K) @ F
            S = [A @ x for x in S] + [K]
            P = (np.eye(4) - K) @ P_pred @ (np.eye(4) - K).T + K @ R @ K.T
        out.append((t, list(S), M))
        t_prev = t
    return out


def quantisation_bound(grad, t, sens):
    """Worst case of grad . (error of the estimate at t) over the quantisation box, to first
    order: sum over the reports j and the quantities m of |grad . F(t - t_k) S_j M[:, m]| q_m,
    with k the ship's newest report at t."""
    t_k, S, M = max((x for x in sens if x[0] <= t), key=lambda x: x[0])
    F, _ = transition(t - t_k, 0.0)
    q = np.array([Q_POSITION_M, Q_POSITION_M, Q_SOG_MPS, Q_COG_RAD])
    return sum(float(np.abs(grad @ F @ Sj @ M) @ q) for Sj in S)


def cpa_gradients(p, v):
    """Gradients of (TCPA, DCPA) over the relative state (p, v), by central differences."""
    x = np.concatenate([p, v])
    out = np.zeros((2, 4))
    for k, h in enumerate((1e-2, 1e-2, 1e-5, 1e-5)):
        d = np.zeros(4)
        d[k] = h
        hi = cpa(np.zeros(2), np.zeros(2), (x + d)[:2], (x + d)[2:])
        lo = cpa(np.zeros(2), np.zeros(2), (x - d)[:2], (x - d)[2:])
        out[:, k] = (np.array(hi) - np.array(lo)) / (2.0 * h)
    return out


@pytest.fixture(scope='module')
def known():
    return replay(read_log(known_lines()), own_mmsi=OWN, config=ReplayConfig(PERIOD_S))


def row_bounds(r, sens):
    """(true TCPA, true DCPA, bound on the TCPA error, bound on the DCPA error) of a row: the
    worst case of AIS quantisation through the tracker (``quantisation_bound``, own ship and
    target both: their errors add), plus 10 % for the second-order terms: those are of
    relative size (velocity error / relative speed) ~ 1e-3 here (Q_SOG_MPS and SOG * Q_COG_RAD
    against relative speeds of 5 m/s and more), as is the gains' change with the quantised SOG
    and COG. A fixed own ship (no entry in ``sens``) adds nothing."""
    po, vo = truth(OWN, r.t_s)
    pt, vt = truth(r.mmsi, r.t_s)
    tcpa, dcpa = cpa(po, vo, pt, vt)
    g_t, g_d = cpa_gradients(pt - po, vt - vo)
    ships = [m for m in (r.mmsi, OWN) if m in sens]
    return (float(tcpa), float(dcpa),
            1.1 * sum(quantisation_bound(g_t, r.t_s, sens[m]) for m in ships),
            1.1 * sum(quantisation_bound(g_d, r.t_s, sens[m]) for m in ships))


def test_known_tracks_cpa_within_the_quantisation_bound(known):
    """Every row's CPA and TCPA against the analytic CPA of the true tracks (``row_bounds``).
    Early rows err most: a 0.05 deg COG error predicted 500 s ahead is metres, and the filter
    has few reports to average; the error shrinks as positions accumulate."""
    sens = {m: sensitivities(m, TrackerConfig()) for m in SHIPS}
    worst = {m: [0.0, 0.0] for m in SHIPS if m != OWN}
    for r in known.rows:
        tcpa, dcpa, bound_t, bound_d = row_bounds(r, sens)
        assert abs(r.cpa_m - dcpa) <= bound_d, (r, dcpa, bound_d)
        assert abs(r.tcpa_s - tcpa) <= bound_t, (r, tcpa, bound_t)
        w = worst[r.mmsi]
        w[0] = max(w[0], abs(r.cpa_m - dcpa) / bound_d)
        w[1] = max(w[1], abs(r.tcpa_s - tcpa) / bound_t)
    # Every target gives a row every period from the time both ships have a report.
    assert {m: sum(r.mmsi == m for r in known.rows) for m in worst} == {
        m: int((DURATION_S - max(m % 7, OWN % 7)) // PERIOD_S) + 1 for m in worst}
    print('largest error / bound (CPA, TCPA):', worst)


def test_known_tracks_summary(known):
    s = known.summary
    assert s['own_ship']['source'] == 'mmsi' and s['own_ship']['mmsi'] == OWN
    assert s['tracker']['tracks_opened'] == 4 and s['tracker']['tracks_deleted'] == 0
    assert s['log']['rejected'] == {} and s['decoder']['rejected'] == {}
    sens = {m: sensitivities(m, TrackerConfig()) for m in SHIPS}
    for d in s['targets']:
        ahead = [r for r in known.rows if r.mmsi == d['mmsi'] and r.tcpa_s >= 0.0]
        best = min(ahead, key=lambda r: r.cpa_m)
        assert (d['min_cpa']['t_s'], d['min_cpa']['cpa_m']) == (best.t_s, best.cpa_m)
        assert d['min_cpa']['t_cpa_s'] == best.t_s + best.tcpa_s
        tcpa, dcpa, bound_t, bound_d = row_bounds(best, sens)
        assert abs(d['min_cpa']['cpa_m'] - dcpa) <= bound_d
    # Sorted by the smallest CPA ahead (true DCPAs about 245, 750 and 2240 m).
    assert [d['mmsi'] for d in s['targets']] == [257000002, 257000003, 257000004]


def test_aivdo_own_ship_gives_the_same_rows(known):
    """The own ship's reports as AIVDO: found without an MMSI, the same rows."""
    got = replay(read_log(known_lines(vdo=True)), config=ReplayConfig(PERIOD_S))
    assert got.summary['own_ship']['source'] == 'aivdo'
    assert got.summary['own_ship']['mmsi'] == OWN
    assert got.rows == known.rows
    # A second ship in AIVDO is ambiguous: refused.
    lines = known_lines(vdo=True)
    other = next(x for x in lines if '!AIVDM' in x and ' ' in x)
    with pytest.raises(ReplayError, match='two MMSIs'):
        replay(read_log(lines + [as_vdo(other)]), config=ReplayConfig(PERIOD_S))
    with pytest.raises(ReplayError, match='no AIVDO'):
        replay(read_log(known_lines()), config=ReplayConfig(PERIOD_S))


def test_fixed_own_ship_is_exact():
    """A fixed own ship (the true own track, given on the command line) has no error of its
    own: the rows' errors are the target's only, within the target's part of the bound."""
    _, _, course, speed = SHIPS[OWN]
    lines = [x for x in known_lines() if pyais.decode(x.split()[1]).mmsi != OWN]
    log = read_log(lines)
    # The fixed ship starts at the log's first time at the own ship's true position then.
    t0 = log.sentences[0][0]
    p0, _ = truth(OWN, t0)
    lat, lon = ned_to_geodetic(p0[0], p0[1], *ORIGIN)
    got = replay(log, own_fixed=FixedOwnShip(lat, lon, course, speed),
                 config=ReplayConfig(PERIOD_S))
    sens = {m: sensitivities(m, TrackerConfig()) for m in SHIPS if m != OWN}
    assert got.rows
    for r in got.rows:
        tcpa, dcpa, bound_t, bound_d = row_bounds(r, sens)
        assert abs(r.cpa_m - dcpa) <= bound_d, r
        assert abs(r.tcpa_s - tcpa) <= bound_t, r


# -- a real log ---------------------------------------------------------------------------------

def pyais_positions(path):
    """MMSI -> position reports, counted with pyais alone from the file's sentences (the
    tag blocks cut off; single-sentence position messages with a position)."""
    out = {}
    for line in path.read_text().splitlines():
        sentence = line.split('\\')[-1]
        if not sentence.startswith('!') or sentence.split(',')[1] != '1':
            continue
        msg = pyais.decode(sentence)
        if msg.msg_type in (1, 2, 3, 18, 19) and abs(msg.lat) <= 90 and abs(msg.lon) <= 180:
            out[msg.mmsi] = out.get(msg.mmsi, 0) + 1
    return out


@pytest.fixture(scope='module')
def real():
    return replay(read_log_file(REAL), own_mmsi=212250000,
                  config=ReplayConfig(period_s=5.0, max_range_m=1e7))


def test_real_log_tracks_every_ship_pyais_reads(real):
    s = real.summary
    counts = pyais_positions(REAL)
    assert s['log']['form'] == 'tag_block' and s['log']['rejected'] == {}
    # Every group's second part took its first part's time: no message 5 lost as 'fragment'.
    assert s['decoder']['rejected'] == {}
    assert s['decoder']['decoded_types']['5'] == REAL.read_text().count('\\g:1-2-')
    assert s['tracker']['tracks_opened'] == len(counts)
    assert {d['mmsi']: d['position_reports'] for d in s['targets']} == {
        m: n for m, n in counts.items() if m != 212250000}
    # Static data stamped days before the positions still names its ship.
    assert next(d for d in s['targets'] if d['mmsi'] == 431908000)['name'] == 'AL WAJBAH'


def test_real_log_rows_are_consistent(real):
    rows = real.rows
    assert rows
    for r in rows:
        # The closest point of the straight-line prediction is never farther than now.
        assert 0.0 <= r.cpa_m <= r.range_m + 1e-6
        assert r.cpa_sigma_m >= 0.0 and r.tcpa_sigma_s >= 0.0
    # TCPA's sign against the range's change to the next row of the same target, where
    # neither ship reported in between (one straight-line prediction): closing while the
    # closest point is more than a period ahead, opening once it is past.
    by = {}
    for r in rows:
        by.setdefault(r.mmsi, []).append(r)
    own = [t for t, x in read_log_file(REAL).sentences
           if x.split(',')[1] == '1' and pyais.decode(x).mmsi == 212250000]
    checked = 0
    for mine in by.values():
        for a, b in zip(mine, mine[1:]):
            if b.report_age_s != a.report_age_s + (b.t_s - a.t_s) \
                    or any(a.t_s < t <= b.t_s for t in own):
                continue
            if a.tcpa_s > b.t_s - a.t_s:
                assert b.range_m < a.range_m, (a, b)
                checked += 1
            elif a.tcpa_s < 0.0:
                assert b.range_m > a.range_m, (a, b)
                checked += 1
    assert checked > 50


# -- the script ---------------------------------------------------------------------------------

def test_script_writes_csv_json_png(tmp_path):
    import ais_cpa
    log = tmp_path / 'case.nmea'
    log.write_text('\n'.join(known_lines()) + '\n')
    out = tmp_path / 'out'
    assert ais_cpa.main([str(log), '--own-mmsi', str(OWN), '--out', str(out)]) == 0
    with open(out / 'ais_cpa.csv') as f:
        rows = list(csv.DictReader(f))
    summary = json.loads((out / 'ais_cpa.json').read_text())
    assert len(rows) == summary['rows'] > 0
    assert set(rows[0]) >= {'t_s', 'mmsi', 'name', 'range_m', 'bearing_deg', 'cpa_m', 'tcpa_s',
                            'cpa_sigma_m', 'tcpa_sigma_s'}
    assert summary['provenance']['log_sha256']
    assert (out / 'ais_cpa.png').stat().st_size > 10_000


@pytest.mark.parametrize('args, what', [
    (['missing.nmea'], 'no such file'),
    ([str(DATA)], 'it is a directory, not a regular file'),
    ([str(DATA / 'pyais_samples.nmea')], 'no times'),
    ([str(REAL), '--rate', '2'], 'only for logs without times'),
    ([str(REAL)], 'no AIVDO'),
    ([str(REAL), '--period', '0'], 'must be a finite number > 0'),
])
def test_script_refuses_in_one_line(args, what, tmp_path, capsys):
    import ais_cpa
    with pytest.raises(SystemExit) as exc:
        ais_cpa.main(args + ['--out', str(tmp_path / 'o')])
    assert exc.value.code == 2
    err = capsys.readouterr().err.strip()
    assert what in err and '\n' not in err
    assert not (tmp_path / 'o').exists()
