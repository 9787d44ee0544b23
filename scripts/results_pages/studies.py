"""Each study's tables, rendered from its results file: ``render(study, table, data)``.

A study registers its renderers in ``TABLES`` under its name; a renderer takes the results
file's dict and returns Markdown. Ratios and summaries a page states in words are tables here
too, so that no number in the text is typed by hand.
"""
from results_pages.registry import TABLES, render, table  # noqa: F401 (render: the API)
from results_pages.tables import markdown_table

# --- wave filter (scripts/wave_filter_comparison.py) -------------------------------------

WAVE_FILTER_METRICS = (
    ('mean abs rudder rate (deg/s)', 'mean_abs_rudder_rate_deg_s', '.3f'),
    ('rudder total variation (deg/h)', 'rudder_total_variation_deg_per_h', '.0f'),
    ('heading error RMS (deg)', 'heading_error_rms_deg', '.3f'),
    ('wave yaw RMS (deg)', 'wave_yaw_rms_deg', '.3f'),
)


def _spread(values, spec):
    """'mean' for one value, 'mean [min, max]' over seeds."""
    mean = sum(values) / len(values)
    if len(values) == 1:
        return format(mean, spec)
    return f'{mean:{spec}} [{min(values):{spec}}, {max(values):{spec}}]'


def _mean(per_seed, key):
    return sum(r[key] for r in per_seed) / len(per_seed)


@table('wave_filter', 'runs')
def wave_filter_runs(data):
    rows = []
    for key, by_input in data['runs'].items():
        model, sea = key.split(', ', 1)
        for label, per_seed in by_input.items():
            row = {'model': model, 'sea': sea, 'input': label}
            for _, metric, spec in WAVE_FILTER_METRICS:
                row[metric] = _spread([r[metric] for r in per_seed], spec)
            rows.append(row)
    return markdown_table([('model', 'model', ''), ('sea', 'sea', ''),
                           ('autopilot input', 'input', '')]
                          + [(title, metric, '') for title, metric, _ in WAVE_FILTER_METRICS],
                          rows)


@table('wave_filter', 'ratios')
def wave_filter_ratios(data):
    """Unfiltered over filtered rudder activity (mean |rudder rate|, means over the seeds; the
    total variation is the same ratio), per model and sea: how many times the filter cuts it;
    and the change of the heading error."""
    rows = []
    for key, by_input in data['runs'].items():
        model, sea = key.split(', ', 1)
        raw, filt = by_input['no filter'], by_input['wave filter']
        rows.append({
            'model': model, 'sea': sea,
            'rate': _mean(raw, 'mean_abs_rudder_rate_deg_s')
            / _mean(filt, 'mean_abs_rudder_rate_deg_s'),
            'dh': _mean(filt, 'heading_error_rms_deg') - _mean(raw, 'heading_error_rms_deg'),
        })
    return markdown_table([
        ('model', 'model', ''), ('sea', 'sea', ''),
        ('rudder activity, no filter / filter', 'rate', '.1f'),
        ('heading error RMS, filter minus no filter (deg)', 'dh', '+.3f'),
    ], rows)


@table('wave_filter', 'sensitivity')
def wave_filter_sensitivity(data):
    rows = [{'model': model, **r} for model, runs in data['sensitivity'].items() for r in runs]
    return markdown_table([
        ('model', 'model', ''), ('Hs relative change', 'hs_relative_change', '+.0e'),
        ('autopilot input', 'input', ''),
        ('mean abs rudder rate (deg/s)', 'mean_abs_rudder_rate_deg_s', '.4f'),
        ('heading error RMS (deg)', 'heading_error_rms_deg', '.4f'),
    ], rows)


# --- studies with their own module register their tables on import -----------------------
from results_pages import mss_accuracy  # noqa: E402, F401
from results_pages import string_stability  # noqa: E402, F401
from results_pages import nomoto  # noqa: E402, F401
from results_pages import table1  # noqa: E402, F401
from results_pages import wind_study  # noqa: E402, F401
from results_pages import missions  # noqa: E402, F401
from results_pages import seed_scenarios  # noqa: E402, F401
from results_pages import bench  # noqa: E402, F401
from results_pages import reacting_traffic  # noqa: E402, F401
from results_pages import degraded_sensors  # noqa: E402, F401
from results_pages import colregs_judge  # noqa: E402, F401
from results_pages import land  # noqa: E402, F401
from results_pages import imazu  # noqa: E402, F401
from results_pages import sweeps  # noqa: E402, F401
from results_pages import chart_planning  # noqa: E402, F401
from results_pages import platoon_time_domain  # noqa: E402, F401
from results_pages import failure_search  # noqa: E402, F401
