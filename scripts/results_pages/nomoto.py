"""Tables of the Nomoto identification (scripts/identify_nomoto.py --results):
doc/results/nomoto.md."""
from results_pages.registry import table
from results_pages.tables import markdown_table


@table('nomoto', 'models')
def models(data):
    rows = [{'model': name, **e, 'k1': data['gains'][name]['pd']['k1'],
             'k2': data['gains'][name]['pd']['k2'], 'omega_n': data['gains'][name]['omega_n']}
            for name, e in data['models'].items()]
    return markdown_table([
        ('model', 'model', ''), ('K (1/s)', 'K', '.4g'), ('T (s)', 'T', '.4g'),
        ('R^2', 'r_squared', '.3f'), ('heading predicted by the fit, RMS (deg)',
                                      'heading_rms_deg', '.3f'),
        ('rudder trim (deg)', 'rudder_trim_deg', '.3f'), ('speed (m/s)', 'speed_mps', '.2f'),
        ('PD omega_n (rad/s)', 'omega_n', '.4f'), ('PD k1', 'k1', '.3f'), ('PD k2', 'k2', '.3f'),
    ], rows)


@table('nomoto', 'linear_reference')
def linear_reference(data):
    fit = data['linear_reference']['fit']
    lf = fit['low_frequency']
    rows = [{'what': f"{data['linear_reference']['model']} low-frequency limit "
                     '(K, T = T1 + T2 - T3)', 'K': lf['K'], 'T': lf['T']},
            {'what': f"{data['linear_reference']['model']} fitted on its own "
                     f"{data['settings']['rudder_deg']:g}/{data['settings']['switch_deg']:g} "
                     'zig-zag', 'K': fit['K'], 'T': fit['T']}]
    return markdown_table([('linear second-order Mariner', 'what', ''), ('K (1/s)', 'K', '.3f'),
                           ('T (s)', 'T', '.1f'), ('K/T (1/s^2)', lambda r: r['K'] / r['T'], '.4f')],
                          rows)


@table('nomoto', 'amplitudes')
def amplitudes(data):
    rows = [{'zz': f"{data['amplitudes']['model']} {name}", **e}
            for name, e in data['amplitudes']['fits'].items()]
    return markdown_table([('zig-zag', 'zz', ''), ('K (1/s)', 'K', '.3f'), ('T (s)', 'T', '.1f'),
                           ('R^2', 'r_squared', '.3f')], rows)
