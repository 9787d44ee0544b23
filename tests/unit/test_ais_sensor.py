"""AIS sensor model (ship_guidance.ais_sensor): report intervals per class and speed (ITU-R
M.1371-5 Tables 1 and 2), the Gilbert-Elliott loss chain against its stationary values, noise
against chi-square bounds, antenna geometry, latency and determinism.

Every statistical bound is derived from the sample size (bounds at about 4.5 standard errors or
a 1e-6 tail, so a correct model fails one of them far less than once in 10^4 runs)."""
import math

import numpy as np
import pytest
from scipy import stats

from ship_guidance.ais import KNOT
from ship_guidance.ais_sensor import (SLOT_SELECTION, AisSensor, GilbertElliott, SensorConfig,
                                      Truth, antenna_position, report_interval)
from ship_sim.geodetic import geodetic_to_ned

ORIGIN = (63.44, 10.40)
Z = 4.5                                    # standard errors of a bound
TAIL = 1e-6                                # chi-square tail of a bound
QUIET = SensorConfig(loss_probability=0.0, position_sigma_m=0.0, sog_sigma_kn=0.0,
                     cog_sigma_deg=0.0, heading_sigma_deg=0.0)


def run(sensor, mmsi, times, sog_mps, rot=0.0, moored=False, psi=0.0):
    """Step a vessel on a straight line (north-going at sog) at ``times``; all reports."""
    out = []
    for t in times:
        out += sensor.step(mmsi, Truth(t, sog_mps * t * math.cos(psi), sog_mps * t * math.sin(psi),
                                       psi, sog_mps, psi, rot, moored))
    return out


# (class, SOG kn, rate of turn deg/min, moored) -> the table's interval, for the cases below
CASES = [('A', 10.0, 0.0, False), ('A', 10.0, 30.0, False), ('A', 18.0, 0.0, False),
         ('A', 18.0, -30.0, False), ('A', 30.0, 0.0, False), ('A', 1.0, 0.0, True),
         ('A', 5.0, 0.0, True), ('B', 1.0, 0.0, False), ('B', 8.0, 0.0, False),
         ('SO', 18.0, 0.0, False)]


@pytest.mark.parametrize('klass,sog_kn,rot_deg_min,moored', CASES)
def test_mean_interval_of_each_speed_class(klass, sog_kn, rot_deg_min, moored):
    """Without losses the mean interval between reports is the table's, within the CLT bound
    of the +-10 % slot selection (sd I * 0.1 / sqrt(3) per interval) plus the step: a report
    due between steps goes out at the next step (at most dt late, never early)."""
    turning = abs(rot_deg_min) >= QUIET.turn_threshold_deg_min
    nominal = report_interval(klass, sog_kn, turning, moored)
    dt = nominal / 40.0
    n = 300
    sensor = AisSensor(*ORIGIN, QUIET)
    sensor.add(1, klass)
    times = np.arange(0.0, (n + 2) * nominal * 1.1, dt)
    reports = run(sensor, 1, times, sog_kn * KNOT, math.radians(rot_deg_min) / 60.0, moored)
    gaps = np.diff([r.t_sent for r in reports])
    assert len(gaps) >= n
    se = nominal * SLOT_SELECTION / math.sqrt(3.0) / math.sqrt(len(gaps))
    assert nominal - Z * se <= gaps.mean() <= nominal + dt + Z * se
    # each single interval within the selection interval, plus the step
    assert gaps.min() >= nominal * (1 - SLOT_SELECTION) - 1e-9
    assert gaps.max() <= nominal * (1 + SLOT_SELECTION) + dt + 1e-9
    assert all(r.turning == turning for r in reports)


def test_interval_table_order():
    """Faster and turning never report less often (class A); class B slower than class A."""
    for turning in (False, True):
        iv = [report_interval('A', s, turning) for s in np.linspace(0.0, 40.0, 401)]
        assert all(a >= b for a, b in zip(iv, iv[1:]))
    for s in np.linspace(0.0, 40.0, 401):
        assert report_interval('A', s, True) <= report_interval('A', s, False)
        assert report_interval('B', s) >= report_interval('A', s)
    with pytest.raises(ValueError, match='class'):
        report_interval('C', 10.0)


def test_turning_shortens_the_next_report_at_once():
    """A vessel that starts turning right after a report sends the next one a turning
    interval after it (within the slot selection), before the straight-line one could end."""
    sensor = AisSensor(*ORIGIN, QUIET)
    sensor.add(1, 'A')
    dt = 0.01
    first = None
    t = 0.0
    while first is None:
        got = sensor.step(1, Truth(t, 0.0, 0.0, 0.0, 10 * KNOT, 0.0))
        first = got[0].t_sent if got else None
        t += dt
    turn = math.radians(30.0) / 60.0
    nxt = None
    while nxt is None:
        got = sensor.step(1, Truth(t, 0.0, 0.0, 0.0, 10 * KNOT, 0.0, turn))
        nxt = got[0].t_sent if got else None
        t += dt
    assert nxt - first <= report_interval('A', 10.0, True) * (1 + SLOT_SELECTION) + dt + 1e-9
    assert report_interval('A', 10.0, True) * (1 + SLOT_SELECTION) < report_interval('A', 10.0) * (
        1 - SLOT_SELECTION)


def test_gilbert_elliott_loss_rate_and_burst_length():
    """The chain's share of losses and mean burst length match its stationary values: loss
    share L = p / (p + r) within Z standard errors of a two-state Markov chain's sample mean
    (variance L (1 - L) (1 + lam) / (1 - lam) / n, lam = 1 - p - r); bursts geometric with
    mean 1 / r, sd sqrt(1 - r) / r."""
    L, b, n = 0.2, 4.0, 200_000
    chain = GilbertElliott.from_loss(L, b, np.random.default_rng(7))
    lost = np.array([chain.lost() for _ in range(n)])
    p, r = chain.p, chain.r
    assert p / (p + r) == pytest.approx(L) and 1.0 / r == pytest.approx(b)
    lam = 1.0 - p - r
    se = math.sqrt(L * (1 - L) * (1 + lam) / (1 - lam) / n)
    assert abs(lost.mean() - L) <= Z * se
    edges = np.flatnonzero(np.diff(np.r_[0, lost.astype(int), 0]))
    bursts = edges[1::2] - edges[::2]
    se_b = math.sqrt(1 - r) / r / math.sqrt(len(bursts))
    assert abs(bursts.mean() - b) <= Z * se_b


def test_sensor_loses_its_loss_probability():
    """Per vessel, the share of transmissions lost and of reports received agree with L (the
    chain's bound as above), and an own ship (AIVDO) loses nothing."""
    L, b = 0.3, 3.0
    cfg = SensorConfig(loss_probability=L, mean_burst_length=b, seed=3)
    sensor = AisSensor(*ORIGIN, cfg)
    sensor.add(1, 'A')
    sensor.add(2, 'A', own=True)
    times = np.arange(0.0, 20_000.0, 0.5)
    got = run(sensor, 1, times, 18 * KNOT)
    own = run(sensor, 2, times, 18 * KNOT)
    v = sensor.vessels[1]
    assert v.sent == len(got) + v.lost
    r = 1.0 / b
    p = r * L / (1 - L)
    lam = 1.0 - p - r
    se = math.sqrt(L * (1 - L) * (1 + lam) / (1 - lam) / v.sent)
    assert abs(v.lost / v.sent - L) <= Z * se
    assert sensor.vessels[2].lost == 0 and len(own) == sensor.vessels[2].sent


def test_noise_standard_deviations():
    """Position (per axis), SOG, COG and heading errors have the configured standard
    deviations (chi-square bounds on the sum of squares, mean zero known) and no bias."""
    cfg = SensorConfig(loss_probability=0.0, position_sigma_m=4.0, sog_sigma_kn=0.2,
                       cog_sigma_deg=2.0, heading_sigma_deg=0.5, seed=11)
    sensor = AisSensor(*ORIGIN, cfg)
    sensor.add(1, 'A')
    sog = 18 * KNOT
    psi = math.radians(30.0)
    reports = run(sensor, 1, np.arange(0.0, 12_000.0, 0.5), sog, psi=psi)
    n = len(reports)
    t = np.array([r.t_sent for r in reports])
    dn = np.array([r.north for r in reports]) - sog * t * math.cos(psi)
    de = np.array([r.east for r in reports]) - sog * t * math.sin(psi)
    dsog = np.array([r.sog_kn for r in reports]) - 18.0
    dcog = (np.array([r.cog_deg for r in reports]) - 30.0 + 180.0) % 360.0 - 180.0
    dhdg = (np.array([r.heading_deg for r in reports]) - 30.0 + 180.0) % 360.0 - 180.0
    lo, hi = stats.chi2.ppf(TAIL, n), stats.chi2.ppf(1 - TAIL, n)
    for err, sigma in ((dn, 4.0), (de, 4.0), (dsog, 0.2), (dcog, 2.0), (dhdg, 0.5)):
        assert lo <= np.sum((err / sigma) ** 2) <= hi
        assert abs(err.mean()) <= Z * sigma / math.sqrt(n)
    # lat/lon are the same noisy position
    north, east = geodetic_to_ned(reports[-1].lat, reports[-1].lon, *ORIGIN)
    assert north == pytest.approx(reports[-1].north, abs=1e-6)
    assert east == pytest.approx(reports[-1].east, abs=1e-6)


@pytest.mark.parametrize('psi_deg,expect', [(0.0, (10.0, 2.0)), (90.0, (-2.0, 10.0)),
                                            (180.0, (-10.0, -2.0))])
def test_antenna_offset_geometry(psi_deg, expect):
    """An antenna 10 m forward and 2 m to starboard: heading north it is 10 m north and 2 m
    east of the reference point; heading east, 10 m east and 2 m south."""
    psi = math.radians(psi_deg)
    n, e = antenna_position(100.0, 50.0, psi, 10.0, 2.0)
    assert (n - 100.0, e - 50.0) == pytest.approx(expect, abs=1e-12)
    sensor = AisSensor(*ORIGIN, QUIET)
    sensor.add(1, 'A', antenna=(10.0, 2.0))
    reports = []
    t = 0.0
    while not reports:
        reports = sensor.step(1, Truth(t, 100.0, 50.0, psi, 0.0, psi))
        t += 0.1
    assert (reports[0].north - 100.0, reports[0].east - 50.0) == pytest.approx(expect, abs=1e-9)


def test_latency_applied():
    """Each report is received latency + U(0, jitter) after it was sent, and handed out at the
    first step at or after that, never before."""
    cfg = SensorConfig(loss_probability=0.0, latency_s=2.0, latency_jitter_s=1.0, seed=5)
    sensor = AisSensor(*ORIGIN, cfg)
    sensor.add(1, 'A')
    dt = 0.05
    seen = []
    for t in np.arange(0.0, 2000.0, dt):
        for r in sensor.step(1, Truth(t, 0.0, 0.0, 0.0, 18 * KNOT, 0.0)):
            seen.append((t, r))
    delays = np.array([r.t_received - r.t_sent for _, r in seen])
    assert delays.min() >= 2.0 and delays.max() <= 3.0
    # uniform jitter: mean 2.5 within the CLT bound (sd 1 / sqrt(12))
    assert abs(delays.mean() - 2.5) <= Z / math.sqrt(12 * len(delays))
    assert all(r.t_received <= t < r.t_received + dt + 1e-9 for t, r in seen)


def test_deterministic_whatever_the_interleaving():
    """The same seed and inputs give identical reports, also when the vessels' steps come in a
    different order; another seed gives other reports."""
    def reports(seed, order):
        cfg = SensorConfig(loss_probability=0.2, latency_s=0.5, latency_jitter_s=0.5, seed=seed)
        s = AisSensor(*ORIGIN, cfg)
        s.add(1, 'A')
        s.add(2, 'B')
        out = {1: [], 2: []}
        for t in np.arange(0.0, 600.0, 0.1):
            for m in order:
                out[m] += s.step(m, Truth(t, t * 5.0, -t, 0.2, 5.0, 0.2, 0.001 * m))
        return out
    a, b, c = reports(1, (1, 2)), reports(1, (2, 1)), reports(2, (1, 2))
    assert a == b and len(a[1]) > 10 and len(a[2]) > 5
    assert a[1] != c[1]


@pytest.mark.parametrize('field,value', [('loss_probability', 1.0), ('loss_probability', -0.1),
                                         ('mean_burst_length', 0.5), ('position_sigma_m', -1.0),
                                         ('latency_s', math.nan)])
def test_bad_config_refused_naming_the_field(field, value):
    with pytest.raises(ValueError, match=field):
        AisSensor(*ORIGIN, SensorConfig(**{field: value}))


def test_burst_too_short_for_the_loss_refused():
    with pytest.raises(ValueError, match='mean_burst_length'):
        SensorConfig(loss_probability=0.8, mean_burst_length=3.5).check()
