"""Wave spectra S(w) (m^2 s) of MSS ``waveSpectrum.m`` (types 1-8) and ``torsetSpectrum.m``.

Ports of Fossen's Marine Systems Simulator (MSS, ``LIBRARY/environment/``), equal to the
original within rounding: Bretschneider, Pierson-Moskowitz, three ITTC-modified PM forms,
JONSWAP from wind and fetch, JONSWAP (Hs, w0, gamma) with the DNV gamma rule, and the
two-peak Torsethaugen spectrum (Torsethaugen and Haver 2004, as coded in MSS).
Frequencies w are in rad/s; the density is per rad/s. As in MSS, a first frequency of exactly
0 is replaced by 1e-4 (only the first one is checked). MSS prints its warnings; here they are
``WaveSpectrumWarning`` warnings with the same text.
"""
import cmath
import math
import warnings

import numpy as np

G = 9.81          # the value coded in waveSpectrum.m and torsetSpectrum.m
EPSILON = 1e-4    # replaces a first frequency of exactly 0

#: spectrumType -> (name, parameters), as in waveSpectrum.m.
SPECTRUM_TYPES = {
    1: ('Bretschneider', '[A, B]'),
    2: ('Pierson-Moskowitz', '[Vwind20]'),
    3: ('ITTC-modified Pierson-Moskowitz', '[Hs, T0]'),
    4: ('ITTC-modified Pierson-Moskowitz', '[Hs, T1]'),
    5: ('ITTC-modified Pierson-Moskowitz', '[Hs, Tz]'),
    6: ('JONSWAP', '[Vwind10, fetch]'),
    7: ('JONSWAP', '[Hs, w0, gamma]'),
    8: ('Torsethaugen', '[Hs, w0]'),
}


class WaveSpectrumWarning(UserWarning):
    """A message waveSpectrum.m / torsetSpectrum.m prints (input outside the validity range)."""


def _frequencies(W):
    w = np.array(W, dtype=float).ravel()
    if w.size and w[0] == 0.0:
        w[0] = EPSILON
    return w


def _bretschneider(A, B, w):
    # MSS evaluates A * w^(-5) * exp(-B / w^4) one scalar at a time (arrayfun).
    return A * w ** -5.0 * np.exp(-B / w ** 4.0)


def _jonswap_shape(alpha, w0, gamma, w):
    sigma = np.where(w < w0, 0.07, 0.09)
    s1 = alpha * G ** 2 * w ** -5.0 * np.exp(-(5.0 / 4.0) * (w0 / w) ** 4)
    s2 = gamma ** np.exp(-(w - w0) ** 2 / (2.0 * (sigma * w0) ** 2))
    return s1, s2


def dnv_gamma(Hs, w0):
    """JONSWAP peak enhancement by the DNV rule MSS uses when gamma is 0 or outside [1, 7]."""
    k = 2.0 * math.pi / (w0 * math.sqrt(Hs))
    if k <= 3.6:
        return 5.0
    if k <= 5.0:
        return math.exp(5.75 - 1.15 * k)
    return 1.0


def wave_spectrum(spectrum_type, parameter, W):
    """S(w) (m^2 s, 1-D) of MSS ``waveSpectrum(spectrumType, Parameter, W, 0)``.

    ``parameter`` as in SPECTRUM_TYPES (m, s, m/s, rad/s); ``W`` frequencies (rad/s).
    """
    w = _frequencies(W)
    p = np.atleast_1d(np.asarray(parameter, dtype=float))
    t = int(spectrum_type)
    if t == 1:
        return _bretschneider(p[0], p[1], w)
    if t == 2:
        return _bretschneider(8.1e-3 * G ** 2, 0.74 * (G / p[0]) ** 4, w)
    if t in (3, 4, 5):
        a, b = {3: (487.0, 1949.0), 4: (173.0, 691.0), 5: (123.0, 495.0)}[t]
        Hs, T = p[0], p[1]
        return _bretschneider(a * Hs ** 2 / T ** 4, b / T ** 4, w)
    if t == 6:
        V, fetch = p[0], p[1]
        xt = G * fetch / V ** 2
        w0 = 2.0 * math.pi * (3.5 * (G / V) * xt ** -0.33)
        s1, s2 = _jonswap_shape(0.076 * xt ** -0.22, w0, 3.3, w)
        return s1 * s2
    if t == 7:
        Hs, w0, gamma = p[0], p[1], p[2]
        alpha = (5.0 / 16.0) * Hs ** 2 * w0 ** 4 / G ** 2
        if gamma < 1.0 or gamma > 7.0:
            if gamma != 0.0:
                warnings.warn('Warning: gamma value is outside validity range, using DNV formula',
                              WaveSpectrumWarning, stacklevel=2)
            gamma = dnv_gamma(Hs, w0)
        s1, s2 = _jonswap_shape(alpha, w0, gamma, w)
        return (1.0 - 0.287 * math.log(gamma)) * s1 * s2
    if t == 8:
        return torset_spectrum(p[0], p[1], w)
    raise ValueError(f'spectrum type {spectrum_type!r}: allowed 1, 2, ..., 8')


# -- Torsethaugen -------------------------------------------------------------------------------

def _pow(a, b):
    """Octave's real ^: a negative base with a fractional exponent gives a complex number."""
    if a < 0.0 and b != int(b):
        return complex(a) ** b
    if a == 0.0 and b < 0.0:
        return math.inf
    return a ** b


def _log(a):
    return cmath.log(a) if a < 0.0 else (-math.inf if a == 0.0 else math.log(a))


def _g0(n, m):
    arg = (n - 1.0) / m
    if arg < 0.0:
        return 1.0 / ((1.0 / m) * math.gamma(arg) * ((n / m) ** (-arg)))
    return 1.0 / ((1.0 / m) * math.gamma(arg) / ((n / m) ** arg))


def _f12(n, m):
    """The f1, f2 shape factors of torsetSpectrum.m for spectral parameters n, m."""
    a1m = 4.1
    b1m = 2.0 * (m ** 0.28) - 5.3
    c1m = -1.45 * (m ** 0.1) + 0.96
    a2m = 2.2 / (m ** 3.3) + 0.57
    b2m = -0.58 * (m ** 0.37) + 0.53
    c2m = -1.04 / (m ** 1.9) + 0.94
    f1 = a1m / _pow(n - b1m, -c1m) if c1m < 0 else a1m * _pow(n - b1m, c1m)
    f2 = a2m / _pow(n, -b2m) + c2m if b2m < 0 else a2m * _pow(n, b2m) + c2m
    return f1, f2


def _agamma(f1, f2, gamma):
    lg = _log(gamma)
    if isinstance(lg, complex) or isinstance(f1, complex) or isinstance(f2, complex):
        return (1.0 + f1 * complex(lg) ** f2) / gamma
    return (1.0 + f1 * _pow(lg, f2)) / gamma


def _peak(f, tp, n, m, g0, agamma, gamma, fdenorm):
    sigma_a2, sigma_b2 = 2.0 * 0.07 ** 2, 2.0 * 0.09 ** 2
    fn = f * tp
    below = np.flatnonzero(fn < 1.0)
    last = below[-1] if below.size else -1   # find(fn < 1, 1, 'last')
    sigma2 = np.where(np.arange(fn.size) <= last, sigma_a2, sigma_b2)
    gamma_f = gamma ** np.exp(-((fn - 1.0) ** 2) / sigma2)
    shape = fn ** (-n) * np.exp(-(n / m) * fn ** (-m))
    return g0 * agamma * shape * gamma_f * fdenorm / (2.0 * math.pi)


def torset_spectrum(Hs, wo, W):
    """Torsethaugen two-peak spectrum S(w) (m^2 s, 1-D) of MSS ``torsetSpectrum(Hs, wo, W)``.

    Hs (m), peak frequency wo (rad/s), W (rad/s). Hs <= 0 gives zeros; a complex result
    (inputs outside the validity range) gives zeros and a WaveSpectrumWarning, as in MSS.
    """
    w = _frequencies(W)
    if not Hs > 0.0:
        return np.zeros_like(w)
    Tp = 2.0 * math.pi / wo
    kg, kg0, kg1, r, k0, k00, m0 = 35.0, 3.5, 1.0, 0.857, 0.5, 3.2, 4.0
    tf = 6.6 * Hs ** (1.0 / 3.0)
    if Tp < tf:   # wind sea dominates
        tl = 2.0 * Hs ** 0.5
        eps1 = (tf - Tp) / (tf - tl)
        rpw = (1.0 - 0.7) * math.exp(-((eps1 / 0.5) ** 2)) + 0.7
        hsw, hss = rpw * Hs, math.sqrt(1.0 - rpw ** 2) * Hs
        tpw, tps = Tp, tf + 2.0
        sp = (2.0 * math.pi / 9.81) * hsw / Tp ** 2
        gammaw = kg * (1.0 + kg0 * math.exp(-Hs / kg1)) * _pow(sp, r)
        gammas = 1.0
        nw = k0 * math.sqrt(Hs) + k00
        mw = m0
        ns, ms = nw, max(mw, 1.0)
        g0s, g0w = _g0(ns, ms), _g0(nw, mw)
    else:         # swell dominates
        epsu = (Tp - tf) / (25.0 - tf)
        rps = (1.0 - 0.6) * math.exp(-((epsu / 0.3) ** 2)) + 0.6
        hss, hsw = rps * Hs, math.sqrt(1.0 - rps ** 2) * Hs
        tps = Tp
        ns = k0 * math.sqrt(Hs) + k00
        ms = m0
        nw = ns
        mw = m0 * (1.0 - 0.7 * math.exp(-Hs / 3.0))
        s4 = 0.08 * (1.0 - math.exp(-Hs / 3.0))
        g0s, g0w = _g0(ns, ms), _g0(nw, mw)
        tpw = _pow((g0w * hsw ** 2) / (16.0 * s4 * (0.4 ** nw)), 1.0 / (nw - 1.0))
        sf = (2.0 * math.pi / 9.81) * Hs / tf ** 2
        gammaw = 1.0
        gammas = kg * (1.0 + kg0 * math.exp(-Hs / kg1)) * _pow(sf, r) * (1.0 + 6.0 * epsu)
    f1w, f2w = _f12(nw, mw)
    f1s, f2s = _f12(ns, ms)
    agw = _agamma(f1w, f2w, gammaw)
    ags = _agamma(f1s, f2s, gammas)
    f = w / (2.0 * math.pi)
    with np.errstate(all='ignore'):
        S = (_peak(f, tpw, nw, mw, g0w, agw, gammaw, tpw * hsw ** 2 / 16.0)
             + _peak(f, tps, ns, ms, g0s, ags, gammas, tps * hss ** 2 / 16.0))
    if np.iscomplexobj(S):
        if np.sum(S.imag) != 0.0:
            warnings.warn('Torsethaugen spectrum input outside validity range, complex output '
                          'set to zero', WaveSpectrumWarning, stacklevel=2)
            return np.zeros_like(w)
        S = S.real
    return S
