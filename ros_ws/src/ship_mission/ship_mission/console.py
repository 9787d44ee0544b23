"""What a run prints for a person in the terminal: the progress lines and the closing metrics
summary (ship_mission.launcher, run_mission.py). No ROS.

Rules: a value not yet defined (no cross-track error received, no sim time elapsed) or not
defined for this run (a statistic whose settling window the run never reached, a route not
completed) reads "n/a", with the reason once at the end of the summary line; never nan, inf or
None. Angles read in degrees: a metric named ``*_rad`` (or ``*_rad_per_s``) is shown as
``*_deg`` (``*_deg_per_s``) converted; metrics.json keeps its keys and radians. The
cumulative Gaussian reward is shown to 0.1 (its terms are at most 1 per step of 0.1 s): a
vessel more than a few sigma from the path earns exp(-e^2 / 2 sigma^2), e.g. 1e-35 at 127 m
with sigma = 10 m, which is 0 to that resolution and is shown so.
"""
import math

from ship_mission.metric_info import DISPLAY, VESSEL, plain_name, shown

NA = 'n/a'

#: Metrics whose statistics count only after the settling window (ship_mission.metrics).
WINDOWED_PREFIXES = ('xte_rms', 'xte_max', 'xte_mean', 'rudder_', 'heading_error_')
#: Metrics of the summary line, by name prefix.
SUMMARY_PREFIXES = ('xte_rms', 'xte_max', 'time_to_complete', 'reward', 'rudder_mean')
#: Reward sums and integrals: at most one per step, shown to this many decimals.
REWARD_SUMS = ('reward_gaussian_sum', 'reward_gaussian_integral_s')
REWARD_DECIMALS = 1


def _defined(x):
    return x is not None and not (isinstance(x, float) and not math.isfinite(x))


def progress_line(t, duration_s, xte_by_ns, rtf, eta_s):
    """One progress line: sim time of the run's duration, each vessel's latest cross-track
    error (m; NaN or None until its first message), the real-time factor so far and the wall
    time left at that pace (inf or None before the sim clock has moved)."""
    xte = '  '.join(f'{ns} xte ' + (f'{e:+8.1f} m' if _defined(e) else f'{NA:>8}  ')
                    for ns, e in xte_by_ns.items())
    pace = (f'x{rtf:5.1f} real time' if _defined(rtf) and rtf > 0 else f'real time factor {NA}')
    left = f'at most {eta_s:4.0f} s left' if _defined(eta_s) else f'time left {NA}'
    return f'  t = {t:7.1f} / {duration_s:.0f} s  {xte}  {pace}, {left}'


def metric_text(key, value):
    """(shown key, shown value) of one metric: angles in degrees under a key naming them
    (units from ship_mission.metric_info, the one table of them), reward sums to their resolution,
    other floats to 4 significant digits, undefined as n/a."""
    unit = VESSEL.get(key, ('', ''))[0]
    if _defined(value):
        value, shown_unit = shown(value, unit)
    else:
        shown_unit = DISPLAY.get(unit, (1.0, unit))[1]
    if shown_unit != unit:      # an angle: the key names the unit shown
        key = f"{plain_name(key, unit)}_{shown_unit.replace('/', '_per_')}"
    if not _defined(value):
        return key, NA
    if key in REWARD_SUMS:
        return key, f'{value:.{REWARD_DECIMALS}f}'
    if isinstance(value, float):
        return key, f'{value:.4g}'
    return key, str(value)


def _reasons(m, undefined):
    """Why the metrics in ``undefined`` (names as in metrics.json) have no value."""
    out = []
    duration, settle = m.get('duration_s'), m.get('settle_s')
    if any(k.startswith(WINDOWED_PREFIXES) for k in undefined):
        if _defined(duration) and _defined(settle) and duration <= settle:
            out.append(f'the run ({duration:.1f} s) is shorter than the settling window '
                       f'({settle:.0f} s)')
        else:
            out.append('no samples after the settling window')
    if 'time_to_complete_s' in undefined:
        out.append('route not completed')
    return out


def _rounded_reward_note(m):
    """A note when the reward is positive but shows as 0.0, or None."""
    r = m.get('reward_gaussian_integral_s')
    if _defined(r) and 0 < r < 0.5 * 10 ** -REWARD_DECIMALS:
        sigma = m.get('reward_sigma_m')
        return (f'reward_gaussian_integral_s {r:.1e} shows as 0.0: the Gaussian term is about 0 '
                f'more than a few sigma ({sigma:g} m) from the path' if _defined(sigma) else None)
    return None


def summary_line(ns, m):
    """The closing line of one vessel's metrics (``m``: its dict in metrics.json)."""
    keys = sorted(k for k in m if k.startswith(SUMMARY_PREFIXES))
    shown = [metric_text(k, m[k]) for k in keys]
    undefined = [k for k in keys if not _defined(m[k])]
    line = f'{ns}: ' + ', '.join(f'{k} = {v}' for k, v in sorted(shown))
    reasons = _reasons(m, undefined)
    if reasons:
        line += f' ({NA}: {"; ".join(reasons)})'
    note = _rounded_reward_note(m)
    if note:
        line += f' ({note})'
    return line
