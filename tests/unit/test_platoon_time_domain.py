"""Fast time-domain check of the platoon stability limit (scripts/platoon_time_domain.py):
a 3-vessel platoon of linear Nomoto ships (ship_sim 'nomoto1', PD autopilot of Angelopoulos 2011 eq. 20, LOS
leader, followers on Angelopoulos 2011 eq. 31) decays above the limit and grows below it, with envelope growth
rates of the sign (and for the leader the value) of the linearised eigenvalues."""
import math

import numpy as np
import pytest

from ship_autopilot import platoon_simulation as ptd
from ship_sim.models import make_model


@pytest.fixture(scope='module')
def nomoto_runs():
    loop = ptd.make_loop('nomoto1')
    dt, n = 1.0, 3
    ratios = (1.2, 0.8)
    d = np.repeat(np.array(ratios)[:, None] * loop.d_crit, n, axis=1)
    run = ptd.simulate_platoon(loop, d, t_end=12000.0, dt=dt, y0=1e-6, stop_amplitude=1.0)
    return loop, dt, ratios, run


def test_document_eigenvalues_are_the_limit_of_the_sampled_loop():
    """The sampled-loop linearisation against Angelopoulos 2011 eq. 30 (an independent formula): the gap
    between them comes from the rudder servo lag and the zero-order hold, so it halves when both
    delays halve and vanishes with them."""
    loop = ptd.make_loop('nomoto1')
    for ratio in (0.8, 1.2):
        d = ratio * loop.d_crit
        doc = ptd.dominant_pair(ptd.doc_eigenvalues(loop, d))
        errs = []
        for tau, dt in ((0.1, 0.02), (0.05, 0.01)):
            loop.model = make_model('nomoto1', rudder_time_constant=tau)
            smp = ptd.dominant_pair(ptd.sampled_eigenvalues(loop, d, dt))
            errs.append(abs(smp - doc))
        assert 0.4 < errs[1] / errs[0] < 0.6
        assert errs[1] < 0.02 * abs(doc.real)


def test_above_the_limit_decays_below_it_grows(nomoto_runs):
    loop, dt, ratios, run = nomoto_runs
    period = 2 * math.pi / loop.omega_n
    for c, ratio in enumerate(ratios):
        d = ratio * loop.d_crit
        lam_smp = ptd.dominant_pair(ptd.sampled_eigenvalues(loop, d, dt)).real
        lam_doc = ptd.dominant_pair(ptd.doc_eigenvalues(loop, d)).real
        expect = 1.0 if ratio < 1.0 else -1.0
        assert np.sign(lam_smp) == np.sign(lam_doc) == expect
        for i in range(3):
            dy = run['dy'][:, c, i]
            _, amp = ptd.envelope_peaks(run['t'], dy)
            sigma, peaks = ptd.envelope_rate(run['t'], dy, t_skip=4 * period,
                                             floor=1e-6 * np.nanmax(amp), ceiling=0.1, power=i)
            assert peaks >= 6
            assert np.sign(sigma) == expect, (ratio, i, sigma, lam_smp)
            if i == 0:   # the leader's deviation is one mode: its rate is the eigenvalue's
                assert sigma == pytest.approx(lam_smp, rel=0.05)
    # above: the run went to the end and every vessel is far below its largest deviation;
    # below: the growth reached the stop amplitude
    above, below = run['dy'][:, 0, :], run['dy'][:, 1, :]
    assert math.isnan(run['stopped_at'][0]) and run['stopped_at'][1] > 0.0
    last = above[-int(period / dt):]
    assert np.all(np.max(np.abs(last), axis=0) < 1e-3 * np.max(np.abs(above), axis=0))
    assert np.nanmax(np.abs(below[:, 2])) > 1.0


def test_envelope_rate_of_a_known_signal():
    t = np.arange(0.0, 5000.0, 0.5)
    y = 1e-3 * t ** 2 * np.exp(-8e-4 * t) * np.cos(0.05 * t + 0.3) + 0.01 * t / 5000.0
    sigma, _ = ptd.envelope_rate(t, y, t_skip=500.0, power=2)
    assert sigma == pytest.approx(-8e-4, rel=1e-3)


# ---------------------------------------------------------------- Angelopoulos 2011 Figs. 17-21

def _thesis_x0(y=(0.0, 0.0), psi=(0.0, 0.0), r=(0.0, 0.0)):
    return np.array([psi[0], r[0], y[0], psi[1], r[1], y[1]])


@pytest.mark.parametrize('ratio', [1.5, 0.8])
def test_thesis_initial_conditions_decay_above_the_limit_and_grow_below_at_the_eigenvalue_rate(
        ratio):
    """Two vessels of the thesis's model (eq. 36, zeta 0.8, omega_n 1) from Fig. 17's start
    (y1, y2) = (1, 1.5): the leader's envelope changes at Re of its dominant eigenvalue (eq. 30),
    negative above d*, positive below; a follower started alone (Fig. 19) likewise."""
    from ship_guidance.string_stability import string_eigenvalues
    zeta, w = 0.8, 1.0
    d = ratio / (2 * zeta * w)
    period = 2 * math.pi / w
    lam = ptd.dominant_pair(string_eigenvalues([zeta], [w], [d])[0]).real
    assert np.sign(lam) == (1.0 if ratio < 1.0 else -1.0)
    for x0, vessel in ((_thesis_x0(y=(1.0, 1.5)), 0), (_thesis_x0(y=(0.0, 1.0)), 1)):
        t, x = ptd.linear_string_response(zeta, w, [d, d], x0, 10 * period, period / 200)
        y = x[:, 2 + 3 * vessel]
        sigma, peaks = ptd.envelope_rate(t, y, t_skip=2 * period)
        assert peaks >= 10
        assert sigma == pytest.approx(lam, rel=0.02)
        if vessel == 1:   # the leader stays on the path when it starts there
            assert np.all(x[:, 2] == 0.0)


def test_ship_platoon_starts_from_the_given_deviations_and_recovers_above_the_limit():
    """simulate_platoon's x_dev puts each vessel off its equilibrium by (y, psi, r); above the
    limit the Nomoto ship with its rudder limit returns to the path (Fig. 20's start)."""
    loop = ptd.make_loop('nomoto1')
    length = 161.0          # the nomoto1 mariner preset (Lee 2004 Table 2.2)
    dev = np.array([[[0.0, 0.5, 0.0], [0.0, 0.3, 0.0]], [[0.3 * length, 0.0, 0.0],
                                                         [0.0, 0.0, 0.01]]])
    period = 2 * math.pi / loop.omega_n
    run = ptd.simulate_platoon(loop, np.full((2, 2), 1.5 * loop.d_crit), 8 * period, 1.0, 0.0,
                               x_dev=dev)
    np.testing.assert_allclose(run['dy'][0], dev[..., 0], atol=1e-12)
    lam = ptd.dominant_pair(ptd.doc_eigenvalues(loop, 1.5 * loop.d_crit)).real
    last = np.max(np.abs(run['dy'][-int(period):, :, 0]), axis=0)
    peak = np.max(np.abs(run['dy'][:, :, 0]), axis=0)
    # linear decay over the last 6 periods would leave exp(6 period Re lambda) ~ 4e-3 of the
    # peak; saturation slows only the first swing: a factor 10 of margin
    assert np.all(last < 10 * math.exp(6 * period * lam) * peak)
