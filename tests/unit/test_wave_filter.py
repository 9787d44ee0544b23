"""The autopilot's wave filter (ship_autopilot.wave_filter): frequency response and tracking.

The Tustin (bilinear) discretisation maps the continuous response at the pre-warped
frequency (2/T) tan(w T / 2) exactly onto the discrete one at w, so the steady-state gain of
a sinusoid fitted by least squares (after the transients, time constants of 1 / w_e and
1 / w_f, have decayed by e^-100) equals |h(j w_warped)| to rounding.
"""
import math

import numpy as np
import pytest

from ship_autopilot.wave_filter import WaveFilter

DT = 0.1


def _h(w, w_e, zeta, w_f):
    s = 1j * w
    return (s * s + 2 * zeta * w_e * s + w_e ** 2) / (s + w_e) ** 2 / (s / w_f + 1)


def _gain(filt, w, n=8000):
    t = np.arange(n) * DT
    y = np.array([filt.update(tk, 0.1 * math.sin(w * tk), 0.05 * math.cos(w * tk))
                  for tk in t])
    half = slice(n // 2, None)
    X = np.column_stack([np.sin(w * t[half]), np.cos(w * t[half])])
    c_psi, *_ = np.linalg.lstsq(X, y[half, 0], rcond=None)
    c_r, *_ = np.linalg.lstsq(X, y[half, 1], rcond=None)
    return np.hypot(*c_psi) / 0.1, np.hypot(*c_r) / 0.05


@pytest.mark.parametrize('w', [0.02, 0.1, 0.3, 0.6, 1.0, 2.0])
def test_frequency_response_is_the_notch_and_lowpass(w):
    w_e, zeta = 0.6, 0.1
    g_psi, g_r = _gain(WaveFilter(w_e, zeta=zeta), w)
    warped = 2.0 / DT * math.tan(w * DT / 2.0)
    want = abs(_h(warped, w_e, zeta, w_e))
    assert g_psi == pytest.approx(want, rel=1e-6) and g_r == pytest.approx(want, rel=1e-6)
    if w == w_e:
        assert g_psi < 1.01 * zeta / math.sqrt(2.0)   # notch depth x the low-pass at w_e


def test_heading_wraps_and_constant_heading_passes_unchanged():
    f = WaveFilter(0.5)
    for k in range(200):   # a constant heading just west of south, noise-free
        psi, r = f.update(k * DT, math.pi - 1e-3, 0.0)
    assert psi == pytest.approx(math.pi - 1e-3, abs=1e-12) and r == pytest.approx(0.0, abs=1e-15)
    f = WaveFilter(0.5)
    out = [f.update(k * DT, math.remainder(3.0 + 0.01 * k * DT, 2 * math.pi), 0.01)[0]
           for k in range(3000)]   # a slow turn through +-pi: no jump of 2 pi
    assert max(abs(math.remainder(b - a, 2 * math.pi)) for a, b in zip(out, out[1:])) < 0.01


def test_notch_follows_the_encounter_frequency():
    f = WaveFilter(peak_frequency=0.6, direction=math.pi)   # waves travel south
    f.update(0.0, 0.0, 0.0, speed=7.0)                         # heading north: head sea
    assert f.w_e == pytest.approx(0.6 + 0.36 * 7.0 / 9.81)
    f = WaveFilter(peak_frequency=0.6, direction=math.pi)
    f.update(0.0, math.pi, 0.0, speed=7.0)                     # heading south: following sea
    assert f.w_e == pytest.approx(0.6 - 0.36 * 7.0 / 9.81)


def test_bad_settings_are_refused():
    with pytest.raises(ValueError):
        WaveFilter()
    with pytest.raises(ValueError):
        WaveFilter(0.5, zeta=1.5)
