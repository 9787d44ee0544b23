"""Tables of the MSS accuracy study (scripts/mss_accuracy.py): doc/results/mss_models.md and the
wave ports in doc/results/wind_waves.md."""
from results_pages.registry import table
from results_pages.tables import markdown_table


@table('mss_accuracy', 'golden')
def golden(data):
    rows = [{'model': name, **r} for name, r in data['golden'].items()]
    return markdown_table([
        ('model', 'model', ''), ('golden cases', 'cases', 'd'),
        ('worst relative error, vector rhs', 'vector_worst_relative_error', '.1e'),
        ('worst relative error, float rhs', 'float_worst_relative_error', '.1e'),
        ('components where MSS gives 0', 'zero_reference_components', 'd'),
        ('worst absolute error there', 'vector_worst_absolute_error_at_zero', '.1e'),
    ], rows)


def _scenario(s):
    """'tanker +10 deg, 80 rpm, h 1000 m' from the scenario's model, native command and
    parameters."""
    parts = [f"{s['model']} {s['native_rudder_deg']:+.0f} deg"]
    if s['shaft_rpm'] is not None:
        parts.append(f"{s['shaft_rpm']:.0f} rpm")
    parts += [f'{k} {v:g} m' for k, v in s['params'].items()]
    return ', '.join(parts)


@table('mss_accuracy', 'turns')
def turns(data):
    rows = []
    for s in data['manoeuvres']['turning_circle'].values():
        o = s['ours']
        rows.append({'scenario': _scenario(s), **o,
                     'side': 'starboard' if s['direction'] > 0 else 'port',
                     'same_side': 'yes' if s['direction'] == s['mss_direction'] else 'NO',
                     'adv_tr': f"{o['advance_m']:.2f} / {o['transfer_m']:.2f}",
                     'worst': s['worst_relative_difference']})
    return markdown_table([
        ('scenario (native rudder sign)', 'scenario', ''), ('turns to', 'side', ''),
        ('as MSS', 'same_side', ''),
        ('advance / transfer at 90 deg (m)', 'adv_tr', ''),
        ('tactical diameter (m)', 'tactical_diameter_m', '.2f'),
        ('U/r radius (m)', 'steady_radius_m', '.2f'), ('final U (m/s)', 'final_speed_mps', '.3f'),
        ('worst relative difference to MSS', 'worst', '.1e'),
    ], rows)


@table('mss_accuracy', 'zigzag')
def zigzag(data):
    rows = [{'zz': f'Mariner {name}',
             'ours': ' / '.join(f'{v:.3f}' for v in z['ours_overshoots_deg']),
             'mss': ' / '.join(f'{v:.3f}' for v in z['mss_overshoots_deg']),
             'worst': max(abs(a - b) / abs(b) for a, b in zip(z['ours_overshoots_deg'],
                                                              z['mss_overshoots_deg']))}
            for name, z in data['manoeuvres']['zigzag_mariner'].items()]
    return markdown_table([
        ('zig-zag', 'zz', ''), ('first / second overshoot (deg)', 'ours', ''),
        ('MSS under Octave (deg)', 'mss', ''), ('worst relative difference', 'worst', '.1e'),
    ], rows)


@table('mss_accuracy', 'nps_auv2')
def nps_auv2(data):
    return markdown_table([
        ("a' (time in L/U)", 'a_prime', '.3f'), ("b'", 'b_prime', '.3f'),
        ('omega_n (U/L)', 'omega_n', 'g'), ('zeta', 'zeta', 'g'),
        ('k1', 'k1', '.3f'), ('k2', 'k2', '.3f'),
    ], [data['nps_auv2']])


@table('mss_accuracy', 'wave_ports')
def wave_ports(data):
    rows = [{'fn': fn, 'cases': r['cases'],
             'errors': ', '.join(f'{k} {v:.1e}' for k, v in r['worst_relative_error'].items()),
             'overall': r['overall']}
            for fn, r in data['wave_ports'].items()]
    return markdown_table([
        ('MSS function', 'fn', ''), ('shared cases', 'cases', 'd'),
        ('worst error relative to the largest value of the case, per output', 'errors', ''),
        ('worst', 'overall', '.1e'),
    ], rows)
