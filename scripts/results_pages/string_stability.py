"""Tables of the string-stability study (scripts/string_stability.py, its summary.json):
doc/results/string_stability.md."""
from results_pages.registry import table
from results_pages.tables import markdown_table

#: Table 1 row classes (ship_guidance.string_stability_table1) in words; the explanations are
#: in ship_guidance/doc/string_stability.md
CLASSES = {
    'exact': 'printed = first grid point above the exact limit',
    'd1_limit_on_grid': 'd1* falls exactly on a grid point: the leader is marginally stable '
                        'there and rounding noise in the real part decides where the d2 scan stops',
    'd2_limit_on_grid': 'only d2* is on the grid: d2* or the next grid point',
    'run_grid_starts_0.10': "printed as 0.10: reproduced exactly if that run's grid started "
                            'at 0.10',
}


@table('string_stability', 'table1')
def table1(data):
    t = data['table1']
    n_exact = sum(c['equal_exact_boundary'] for c in t['classes'].values())
    n_consistent = sum(c['consistent_with_method'] for c in t['classes'].values())
    missing = '; '.join(f"zeta {m['zeta']:g}, omega_n1 {m['wn1']:g}, omega_n2 {m['wn2']:g} "
                        f"(d2* {m['d2_star']:.3f})" for m in t['missing'])
    return markdown_table([
        ('rows scanned', 'scanned', 'd'), ('rows printed', 'printed', 'd'),
        ('rows absent (d2* > 2, the grid ends at 2)', 'missing', ''),
        ('largest difference of d1*, d2* to the printed 6 decimals', 'err', '.1e'),
        ('printed grid minima equal to the exact boundary', 'exact', 'd'),
        ("rows Appendix A's method explains", 'consistent', 'd'),
    ], [{'scanned': t['scanned_rows'], 'printed': t['printed_rows'], 'missing': missing,
         'err': t['d_star_max_err'], 'exact': n_exact, 'consistent': n_consistent}])


@table('string_stability', 'table1_classes')
def table1_classes(data):
    rows = [{'class': name, 'why': CLASSES.get(name, ''), **c}
            for name, c in data['table1']['classes'].items()]
    rows.sort(key=lambda r: -r['rows'])
    return markdown_table([
        ('row class', 'class', ''), ('what decides the printed value', 'why', ''),
        ('rows', 'rows', 'd'), ('equal to the exact boundary', 'equal_exact_boundary', 'd'),
        ('printed value as the method predicts', 'consistent_with_method', 'd'),
    ], rows)


@table('string_stability', 'timing')
def timing(data):
    t = data['table1']['timing']
    rows = [{'how': 'Routh test per grid point (block-triangular structure)',
             'best': 1e3 * t['routh']['best_s'], 'median': 1e3 * t['routh']['median_s'],
             'rows': data['table1']['scanned_rows']},
            {'how': 'eigenvalues of the 3x3 diagonal blocks', 'best': 1e3 * t['eig']['best_s'],
             'median': 1e3 * t['eig']['median_s'], 'rows': data['table1']['scanned_rows']}]
    if 'appendix_a_literal_s' in t:
        rows.append({'how': 'literal Appendix A scan (6x6 eig per grid point, numpy), rows not '
                            'of the exact class', 'best': 1e3 * t['appendix_a_literal_s'],
                     'median': None, 'rows': t['appendix_a_literal_rows']})
    same = 'yes' if data['table1']['eig_equals_routh'] else 'NO'
    return markdown_table([
        ('scan of Table 1', 'how', ''), ('rows', 'rows', 'd'), ('best (ms)', 'best', '.1f'),
        ('median (ms)', 'median', '.1f'),
    ], rows) + f'\nRouth and block eigenvalues give identical minima: {same}.\n'


@table('string_stability', 'nps_critical')
def nps_critical(data):
    rows = [{**c, 'ratio': c['exact_routh'] / c['approx']} for c in data['nps_auv2_checks']]
    return markdown_table([
        ('zeta', 'zeta', 'g'), ('omega_n (U/L)', 'omega_n', 'g'), ('k1', 'k1', '.3f'),
        ('k2', 'k2', '.3f'), ('exact critical look-ahead, sway and yaw (L)', 'exact_routh', '.4f'),
        ('independent eigenvalue bisection (L)', 'eigen_bisection', '.4f'),
        ('approximation 1/(2 zeta omega_n) (L)', 'approx', '.4f'),
        ('exact / approximation', 'ratio', '.3f'),
    ], rows)


@table('string_stability', 'sensitivity')
def sensitivity(data):
    doc = data['document_sensitivity']
    rows = [{'name': n, **v, 'doc': f'about {doc[n]:g}' if n in doc else ''}
            for n, v in data['sensitivity_totals'].items()]
    return markdown_table([
        ('coefficient', 'name', ''),
        ('change of d_n over +-50 %, gains fixed', 'fixed', '+.3f'),
        ('gains redesigned', 'redesign', '+.3f'), ('Simakis 1992', 'doc', ''),
    ], rows)


def _pct(values):
    return ', '.join(f'{100 * v:.0f}' for v in values)


@table('string_stability', 'sensitivity_map')
def sensitivity_map(data):
    rows = []
    for name, s in data['sensitivity_map'].items():
        so, sz = s['slice_omega_n'], s['slice_zeta']
        rows.append({
            'name': name, 'max': 100 * s['max'],
            'below20': 100 * s['share_values_below_20'],
            'points20': 100 * s['share_below_20'], 'points40': 100 * s['share_below_40'],
            'slice_w': f"omega_n {so['omega_n']:g}, zeta {so['zetas'][0]:g}-{so['zetas'][-1]:g}: "
                       f"{_pct(so['max_abs_dev'])}",
            'slice_z': f"zeta {sz['zeta']:g}, omega_n {sz['omegas'][0]:g}-{sz['omegas'][-1]:g}: "
                       f"{_pct(sz['max_abs_dev'])}",
        })
    return markdown_table([
        ('coefficient', 'name', ''), ('largest abs(d_n - 1) on the map (%)', 'max', '.0f'),
        ('(variation, grid point) values below 20 % (%)', 'below20', '.0f'),
        ('grid points whose largest deviation is below 20 % (%)', 'points20', '.0f'),
        ('at most 40 % (%)', 'points40', '.0f'),
        ("largest abs(d_n - 1) (%) on the document's slice", 'slice_w', ''),
        ('and on the other slice', 'slice_z', ''),
    ], rows)


@table('string_stability', 'eigenvalue_path')
def eigenvalue_path(data):
    def cell(p):
        return f"{p['pair_real']:+.3f} +- {p['pair_imag']:.3f}i, {p['real']:.3f}"
    rows = [{'zeta': p['zeta'], 'omega_n': p['omega_n'], 'd1_star': p['d1_star'],
             **{q: cell(v) for q, v in p['at'].items()}}
            for p in data['eigenvalue_path']]
    return markdown_table([
        ('zeta', 'zeta', 'g'), ('omega_n (U/L)', 'omega_n', 'g'), ('d1* (L)', 'd1_star', '.4f'),
        ('eigenvalues at 2 d1* (oscillatory pair, real)', '2', ''), ('at d1*', '1', ''),
        ('at d1*/2', '0.5', ''),
    ], rows)
