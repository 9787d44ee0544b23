"""String stability of LOS platoons (Angelopoulos 2011) and the NPS AUV II exact look-ahead (Simakis 1992).

Reference data: tests/data/string_stability_table1.csv (Angelopoulos 2011,
Table 1, Appendix B).
Which printed grid minima are not the exact boundary is decided here by rules taken from the
method of Appendix A (a limit lying on a grid point; the one run whose grid starts at 0.10),
never by row numbers; see ship_guidance/doc/string_stability.md.
"""
from pathlib import Path

import numpy as np
import pytest

from ship_guidance import string_stability as ss
from ship_guidance import string_stability_table1 as table1_scan
from ship_guidance import sway_yaw_lookahead as sy
from ship_guidance.heading_loop import pd_gains
from ship_guidance.los import critical_lookahead, critical_lookahead_nondim, linear_loop_matrix

# provenance: tests/data/README.md
TABLE = Path(__file__).resolve().parents[1] / 'data' / 'string_stability_table1.csv'


@pytest.fixture(scope='module')
def table():
    return np.genfromtxt(TABLE, delimiter=',', names=True)


@pytest.fixture(scope='module')
def minima(table):
    """Exact grid minima of Angelopoulos's scan (0.05:0.01:2) for every printed row."""
    return table1_scan.grid_minima(table['zeta'], table['wn1'], table['wn2'])


def _on_two_decimal_grid(d):
    """The rule, independent of the module: d* equals a multiple of 0.01 (a grid point)."""
    return np.abs(d * 100.0 - np.round(d * 100.0)) < 1e-7


# ------------------------------------------------------------------ single vessel, string

@pytest.mark.parametrize('zeta, omega_n', [(0.4, 1.0), (0.8, 3.0), (1.2, 4.5), (0.7, 0.35)])
def test_eigenvalues_at_the_limit(zeta, omega_n):
    d_star = 1.0 / (2.0 * zeta * omega_n)
    assert critical_lookahead_nondim(zeta, omega_n) == pytest.approx(d_star, rel=1e-15)
    lam = np.sort_complex(np.linalg.eigvals(ss.single_vessel_matrix(zeta, omega_n, d_star)))
    want = np.sort_complex(np.array([1j * omega_n, -1j * omega_n, -2.0 * zeta * omega_n]))
    np.testing.assert_allclose(lam, want, atol=1e-9 * omega_n)
    np.testing.assert_allclose(np.sort_complex(ss.limit_eigenvalues(zeta, omega_n)), want)
    # stable just above the limit, unstable just below, by eigenvalues and by the Routh test
    for f, stable in ((1.01, True), (0.99, False)):
        re = np.linalg.eigvals(ss.single_vessel_matrix(zeta, omega_n, f * d_star)).real.max()
        assert bool(re < 0.0) is stable
        assert bool(ss.is_stable(zeta, omega_n, f * d_star)) is stable
    assert not ss.is_stable(zeta, omega_n, d_star)      # marginal is not asymptotically stable


def test_dimensional_form_agrees_with_los_module():
    zeta, omega_n, speed, d = 0.8, 0.12, 6.0, 40.0     # rad/s, m/s, m
    # the dimensional limit is the theses' d* (ship lengths at omega_n' = omega_n L / U) times L
    length = 160.93
    d_star = critical_lookahead(zeta, omega_n, speed)
    assert d_star == pytest.approx(
        length * critical_lookahead_nondim(zeta, omega_n * length / speed), rel=1e-14)
    # and the LOS loop is marginal there: its slowest eigenvalue sits on the imaginary axis
    re = np.linalg.eigvals(linear_loop_matrix(zeta, omega_n, speed, d_star)).real.max()
    assert abs(re) < 1e-9 * omega_n
    np.testing.assert_allclose(ss.single_vessel_matrix(zeta, omega_n, d, speed),
                               linear_loop_matrix(zeta, omega_n, speed, d))


def test_string_matrix_is_block_triangular_and_its_spectrum_is_the_blocks():
    rng = np.random.default_rng(1)
    n = 5
    zeta, w, d = rng.uniform(0.4, 1.2, n), rng.uniform(0.5, 4.0, n), rng.uniform(0.1, 2.0, n)
    a = ss.string_matrix(zeta, w, d)
    assert a.shape == (3 * n, 3 * n)
    assert np.all(np.triu(a, 3)[np.triu_indices(3 * n, 3)] == 0.0)   # nothing above the blocks
    full = np.sort_complex(np.linalg.eigvals(a))
    blocks = np.sort_complex(ss.string_eigenvalues(zeta, w, d).ravel())
    np.testing.assert_allclose(full, blocks, atol=1e-8)
    # Angelopoulos 2011 eq. 37 for two vessels: the follower's r row sees the leader's y with +w2^2/d2
    a2 = ss.string_matrix([0.8, 0.8], [2.0, 3.0], [0.5, 0.7])
    assert a2[4, 2] == pytest.approx(9.0 / 0.7)
    assert a2[4, 5] == pytest.approx(-9.0 / 0.7)


def test_two_vessel_characteristic_polynomial_factorises():
    """Angelopoulos 2011 eq. 38 = product of the two cubics of eq. 39 (eq. 40)."""
    z1, z2, w1, w2, d1, d2 = 0.6, 1.1, 1.7, 3.2, 0.45, 0.2
    full = np.poly(ss.string_matrix([z1, z2], [w1, w2], [d1, d2]))
    prod = np.polymul(ss.characteristic_coefficients(z1, w1, d1),
                      ss.characteristic_coefficients(z2, w2, d2))
    np.testing.assert_allclose(full, prod, rtol=1e-10)
    # eq. 38 written out: the lambda^3 and lambda^0 coefficients
    assert prod[3] == pytest.approx(w1**2 / d1 + w2**2 / d2 + 2 * z1 * w1 * w2**2
                                    + 2 * z2 * w1**2 * w2)
    assert prod[6] == pytest.approx(w1**2 * w2**2 / (d1 * d2))


def test_string_stable_iff_every_vessel_is():
    w, zeta = [2.0, 2.5, 1.5], [0.8, 0.8, 0.8]
    crit = critical_lookahead_nondim(zeta, w)
    ok = ss.string_matrix(zeta, w, crit * 1.05)
    assert np.linalg.eigvals(ok).real.max() < 0.0
    bad = ss.string_matrix(zeta, w, crit * np.array([1.05, 0.95, 1.05]))   # middle vessel
    assert np.linalg.eigvals(bad).real.max() > 0.0


# ------------------------------------------------------------------ Table 1

def test_critical_lookaheads_of_every_row(table):
    for col, w in (('d1_star', table['wn1']), ('d2_star', table['wn2'])):
        ours = critical_lookahead_nondim(table['zeta'], w)
        np.testing.assert_allclose(ours, table[col], atol=5.01e-7)   # printed to 6 decimals


def test_eigenvalue_columns_are_the_limit_frequencies(table):
    for r in table:
        d_star = [1 / (2 * r['zeta'] * r['wn1']), 1 / (2 * r['zeta'] * r['wn2'])]
        lam = ss.string_eigenvalues([r['zeta']] * 2, [r['wn1'], r['wn2']], d_star)
        imag = sorted(np.abs(lam.imag).max(axis=1))
        np.testing.assert_allclose(imag, sorted([r['eig_a'], r['eig_b']]), rtol=1e-9)
        np.testing.assert_allclose(sorted(lam.real.min(axis=1)),
                                   sorted([-2 * r['zeta'] * r['wn1'], -2 * r['zeta'] * r['wn2']]),
                                   rtol=1e-9)


def test_grid_minima_match_rows_with_no_limit_on_the_grid(table, minima):
    d1s = 1 / (2 * table['zeta'] * table['wn1'])
    d2s = 1 / (2 * table['zeta'] * table['wn2'])
    clean = ~_on_two_decimal_grid(d1s) & ~_on_two_decimal_grid(d2s)
    # the one run printed with a grid starting at 0.10 (doc/string_stability.md): clamp there
    run = (table['zeta'] == 1.0) & np.isclose(table['wn2'], 1.5 * table['wn1'])
    floor = np.where(run, 0.10, 0.0)
    np.testing.assert_allclose(table['d1_sim'][clean], np.maximum(minima[0], floor)[clean],
                               atol=1e-9)
    np.testing.assert_allclose(table['d2_sim'][clean], np.maximum(minima[1], floor)[clean],
                               atol=1e-9)
    assert clean.sum() == 517


def test_lower_grid_end_explains_exactly_the_rows_below_0_10(table, minima):
    """Without the 0.10 floor exactly those rows of the zeta = 1, wn2 = 1.5 wn1 run differ whose
    exact grid minimum is below 0.10; every other run reaches below 0.10 where it should."""
    d1, d2 = minima
    wrong = ~np.isclose(table['d2_sim'], d2) & ~_on_two_decimal_grid(
        1 / (2 * table['zeta'] * table['wn2'])) & ~_on_two_decimal_grid(
        1 / (2 * table['zeta'] * table['wn1']))
    run = (table['zeta'] == 1.0) & np.isclose(table['wn2'], 1.5 * table['wn1'])
    np.testing.assert_array_equal(wrong, run & (d2 < 0.10 - 1e-9))
    assert wrong.sum() == 8
    assert np.any(table['d2_sim'][~run] < 0.10 - 1e-9)   # e.g. zeta 1.2 reaches 0.07


def test_rows_with_a_limit_on_the_grid_follow_the_rounding_noise_rule(table):
    """At d = d* on a grid point the marginal eigenvalues' real part is rounding noise and
    Appendix A counts V <= 0 as stable, so: d1* on the grid -> d1_sim = d1* and d2_sim anywhere
    at or above the first grid point >= d2*; only d2* on the grid -> d2_sim is d2* or d2*+0.01."""
    d1s = 1 / (2 * table['zeta'] * table['wn1'])
    d2s = 1 / (2 * table['zeta'] * table['wn2'])
    t1, t2 = _on_two_decimal_grid(d1s), _on_two_decimal_grid(d2s)
    assert t1.sum() == 17 and (t2 & ~t1).sum() == 3
    np.testing.assert_allclose(table['d1_sim'][t1], d1s[t1], atol=1e-9)
    first_d2 = np.ceil(d2s * 100.0 - 1e-6) / 100.0       # ties included
    assert np.all(table['d2_sim'][t1] >= first_d2[t1] - 1e-9)
    only2 = t2 & ~t1
    assert np.all(np.isclose(table['d2_sim'][only2], d2s[only2])
                  | np.isclose(table['d2_sim'][only2], d2s[only2] + 0.01))
    # and the module's classification says the same for every row
    cls, lo1, hi1, lo2, hi2 = table1_scan.classify_table1(table['zeta'], table['wn1'],
                                                          table['wn2'])
    np.testing.assert_array_equal(cls == table1_scan.ROW_TIE_D1, t1)
    np.testing.assert_array_equal(cls == table1_scan.ROW_TIE_D2, only2)
    assert np.all((table['d1_sim'] >= lo1 - 1e-9) & (table['d1_sim'] <= hi1 + 1e-9)
                  & (table['d2_sim'] >= lo2 - 1e-9) & (table['d2_sim'] <= hi2 + 1e-9))


def test_missing_rows_are_those_without_a_stable_grid_point(table):
    z, w1, w2 = table1_scan.table1_parameters()
    assert z.size == 540
    d1, _ = table1_scan.grid_minima(z, w1, w2)
    printed = {(round(a, 6), round(b, 6), round(c, 6))
               for a, b, c in zip(table['zeta'], table['wn1'], table['wn2'])}
    absent = {(round(a, 6), round(b, 6), round(c, 6)) for a, b, c in zip(z, w1, w2)} - printed
    no_point = {(round(a, 6), round(b, 6), round(c, 6))
                for a, b, c, m in zip(z, w1, w2, d1) if np.isnan(m)}
    assert absent == no_point and len(absent) == 3
    assert all(1 / (2 * a * c) > 2.0 for a, _, c in absent)   # d2* beyond the grid's end


def test_block_eigenvalue_scan_equals_routh_scan(table):
    z, w1, w2 = table['zeta'], table['wn1'], table['wn2']
    r1, r2 = table1_scan.grid_minima(z, w1, w2, method='routh')
    e1, e2 = table1_scan.grid_minima(z, w1, w2, method='eig')
    np.testing.assert_array_equal(r1, e1)
    np.testing.assert_array_equal(r2, e2)


def test_literal_appendix_a_scan_equals_fast_scan_on_a_clean_row():
    """Full 6x6 eigenvalues on the 196 x 196 grid vs the block-structured scan."""
    zeta, w1, w2 = 0.6, 2.3, 1.5 * 2.3
    d1, d2, v = table1_scan.appendix_a_scan(zeta, w1, w2)
    f1, f2 = table1_scan.grid_minima(zeta, w1, w2)
    assert (d1, d2) == pytest.approx((f1[0], f2[0]), abs=1e-12)
    assert v.shape == (196, 196)


def test_matlab_colon_grid():
    g = table1_scan.matlab_colon(0.05, 0.01, 2.0)
    assert g.size == 196 and g[0] == 0.05 and g[-1] == 2.0
    np.testing.assert_allclose(g, 0.05 + 0.01 * np.arange(196), atol=1e-15)
    assert table1_scan.matlab_colon(1.0, 0.1, 4.5).size == 36


# ------------------------------------------------------------------ platoon validation

def test_check_platoon_flags_vessels_below_their_limit():
    # SI: U = 5 m/s, omega_n = 0.1 rad/s, zeta = 0.8 -> limit 31.25 m
    vessels = [dict(zeta=0.8, omega_n=0.1, lookahead=60.0, speed=5.0, name='leader'),
               ss.LookaheadLoop(0.8, 0.1, 30.0, 5.0, 'f1'),
               ss.LookaheadLoop(1.0, 0.1, 30.0, 5.0, 'f2')]        # limit 25 m
    checks = ss.check_platoon(vessels)
    assert [c.ok for c in checks] == [True, False, True]
    assert checks[1].critical == pytest.approx(31.25)
    assert checks[1].ratio == pytest.approx(30.0 / 31.25)
    assert [c.name for c in ss.unstable_vessels(vessels)] == ['f1']
    assert 'BELOW' in checks[1].message() and 'f1' in checks[1].message()
    # a safety margin of 1.3 also refuses the 25 m limit at 30 m
    assert [c.name for c in ss.unstable_vessels(vessels, margin=1.3)] == ['f1', 'f2']
    # exactly at the limit is marginal: refused
    assert not ss.check_platoon([dict(zeta=0.5, omega_n=1.0, lookahead=1.0)])[0].ok
    # Angelopoulos's non-dimensional form: speed 1, look-ahead in ship lengths
    assert ss.check_platoon([dict(zeta=0.8, omega_n=3.0, lookahead=0.21)])[0].ok
    with pytest.raises(ValueError):
        ss.check_platoon([dict(zeta=0.8, omega_n=3.0, lookahead=-1.0)])
    with pytest.raises(ValueError):
        ss.check_platoon(vessels, margin=0.5)


# ------------------------------------------------------------------ NPS AUV II (Simakis 1992)

def test_nps_auv2_gains_match_the_document():
    """Simakis 1992 Sec. III.B: at omega_n = 3, zeta = 0.8 the gains are 'about 3.2 and 1.2'."""
    k1, k2 = pd_gains(*sy.nps_auv2_nomoto(), zeta=0.8, omega_n=3.0)
    assert k1 == pytest.approx(3.2, abs=0.1)
    assert k2 == pytest.approx(1.2, abs=0.1)


def test_sway_yaw_characteristic_terms_match_the_matrix():
    plant = sy.nps_auv2_plant()
    k1, k2 = pd_gains(*sy.nps_auv2_nomoto(plant), zeta=0.8, omega_n=3.0)
    b, c1, c2, d1, d2, e = sy.sway_yaw_char_terms(plant, k1, k2)
    for d in (0.2, 0.7):
        np.testing.assert_allclose(np.poly(sy.sway_yaw_matrix(plant, k1, k2, d)),
                                   [1.0, b, c1 + c2 / d, d1 + d2 / d, e / d], rtol=1e-9, atol=1e-12)


def test_nps_auv2_exact_critical_lookahead_vs_eigenvalue_scan():
    plant = sy.nps_auv2_plant()
    k1, k2 = pd_gains(*sy.nps_auv2_nomoto(plant), zeta=0.8, omega_n=3.0)
    d_routh = float(sy.nps_auv2_critical_lookahead(0.8, 3.0))
    d_eig = sy.critical_lookahead_by_eigenvalues(plant, k1, k2, 0.05, 2.0)
    assert d_routh == pytest.approx(d_eig, rel=1e-8)
    # stable above, unstable below
    for f, sign in ((1.001, -1), (0.999, 1)):
        re = np.linalg.eigvals(sy.sway_yaw_matrix(plant, k1, k2, f * d_routh)).real.max()
        assert np.sign(re) == sign


def test_exact_limit_reduces_to_nomoto_limit_without_sway_coupling():
    """No sway in y' and no sway/yaw coupling: the quartic is the cubic times (s - a11)."""
    plant = sy.SwayYawPlant(a11=-1.5, a12=0.0, a21=0.0, a22=-1.2, b1=0.0, b2=-2.5)
    for zeta, w in ((0.4, 1.0), (0.8, 3.0), (1.2, 2.0)):
        k1, k2 = pd_gains(plant.a22, plant.b2, zeta=zeta, omega_n=w)
        assert float(sy.sway_yaw_critical_lookahead(plant, k1, k2)) == pytest.approx(
            1 / (2 * zeta * w), rel=1e-12)


def test_exact_limit_vectorises_over_zeta_and_omega():
    w = np.array([1.0, 2.0, 3.0])
    z = np.array([[0.6], [0.8]])
    grid = sy.nps_auv2_critical_lookahead(z, w)
    assert grid.shape == (2, 3)
    assert grid[1, 2] == pytest.approx(float(sy.nps_auv2_critical_lookahead(0.8, 3.0)))
    assert np.all(np.diff(grid, axis=1) < 0)      # more bandwidth, shorter look-ahead (Simakis 1992)


def test_sensitivity_zero_coefficients_and_relative_size():
    """Y_r = N_v = 0 for the NPS AUV II: +-50 % changes nothing. The added-mass/damping sway
    terms move the limit about 3-4 times more than the yaw terms (Simakis 1992 Sec. III.C)."""
    f = np.array([0.5, 1.0, 1.5])
    for name in ('Yr', 'Nv'):
        np.testing.assert_allclose(sy.nps_auv2_sensitivity(name, f), 1.0, atol=1e-12)
    total = {n: abs(np.ptp(sy.nps_auv2_sensitivity(n, f))) for n in ('Yv', 'Yvdot', 'Nr', 'Nrdot')}
    assert min(total['Yv'], total['Yvdot']) > 2.5 * max(total['Nr'], total['Nrdot'])
    assert sy.nps_auv2_sensitivity('Yv', [1.0])[0] == pytest.approx(1.0)


# ---------------------------------------------------------------- Angelopoulos 2011 Fig. 16

@pytest.mark.parametrize('zeta, omega_n', [(0.8, 1.0), (0.4, 2.5), (1.2, 4.0)])
def test_eigenvalue_path_crosses_the_imaginary_axis_once_and_only_at_the_limit(zeta, omega_n):
    """As d1 falls from 4 d1* to d1*/2 the oscillatory pair's real part rises monotonically
    (d/dd of the cubic's last coefficient U w^2 / d is negative) and changes sign once, between
    the grid points around d1* (the value AT d1* is test_eigenvalues_at_the_limit's); the real
    eigenvalue stays negative all along."""
    import string_stability as cli   # scripts/string_stability.py
    ratios = np.geomspace(4.0, 0.5, 400)
    lam, d_star = cli.eigenvalue_path(zeta, omega_n, ratios)
    assert d_star == pytest.approx(1.0 / (2 * zeta * omega_n))
    pair = np.array([row[np.argmax(row.imag)] for row in lam])
    real = np.array([row[np.argmin(np.abs(row.imag))] for row in lam])
    assert np.all(pair.imag > 0.0) and np.all(real.real < 0.0)
    assert np.all(np.diff(pair.real) > 0.0)
    # (at d1* itself the real part is 0 up to rounding, either sign)
    crossing = np.flatnonzero(np.diff(pair.real > 0.0))
    assert crossing.size == 1
    assert ratios[crossing[0]] >= 1.0 - 1e-9 and ratios[crossing[0] + 1] <= 1.0 + 1e-9


def test_sensitivity_map_at_the_thesis_design_is_figures_5_and_6():
    """The map's (zeta 0.8, omega_n 3) point equals the Figs. 5-6 curves of the same module,
    and a coefficient at its nominal value changes nothing (d_n = 1)."""
    import string_stability as cli
    factors = np.array([0.5, 1.0, 1.5])
    maps, nominal = cli.sensitivity_map([0.6, 0.8], [2.0, 3.0], factors)
    for name in cli.MAP_COEFFS:
        np.testing.assert_allclose(maps[name][1, 1], sy.nps_auv2_sensitivity(name, factors),
                                   rtol=1e-12)
        np.testing.assert_allclose(maps[name][..., 1], 1.0, rtol=1e-12)
    assert nominal[1, 1] == pytest.approx(sy.nps_auv2_critical_lookahead(0.8, 3.0))


def test_gain_curves_grow_as_the_pole_placement_says():
    """Simakis 1992 Fig. 4: k1 = -omega_n^2 / b does not depend on zeta and quadruples when
    omega_n doubles; k2 = -(a + 2 zeta omega_n) / b is linear in omega_n with slope -2 zeta / b."""
    import string_stability as cli
    a, b = sy.nps_auv2_nomoto()
    k1, k2 = cli.gain_curves(np.array([1.5, 3.0]), np.array([0.6, 0.8]))
    assert k1.shape == k2.shape == (2, 2)
    np.testing.assert_allclose(k1[0], k1[1])
    assert k1[0, 1] == pytest.approx(4 * k1[0, 0])
    np.testing.assert_allclose(k2[:, 1] - k2[:, 0], -2 * np.array([0.6, 0.8]) * 1.5 / b)
