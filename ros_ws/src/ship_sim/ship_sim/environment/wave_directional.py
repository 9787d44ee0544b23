"""Directional wave spectrum and its wave components, MSS ``waveDirectionalSpectrum.m``.

N frequencies, one per interval of width omega_max / N at a random point of it; with
spreading, D directions relative to the main direction, one per interval of width
pi / (D - 1) at a random point, clamped to [-pi/2, pi/2], with the cos^2 spreading function
M(mu) normalised by the trapezoidal rule; component amplitudes sqrt(2 S(w) M(mu) dw dmu)
(Fossen 2021, Sec. 10.2). The random draws are inputs (``u_mu`` then ``u_omega``, uniform in
[0, 1)), so cases computed elsewhere replay exactly; without them they come from a numpy
Generator in the same order. MSS prints a summary; here ``DirectionalSpectrum.summary()``.
Knowingly departed from MSS: an unknown spectrum name is an error (MSS falls back to
Torsethaugen for any string but 'Modified PM' and 'JONSWAP'; 'Torsethaugen' is the name here).
"""
import math
import warnings
from collections import namedtuple

import numpy as np

from ship_sim.environment.wave_spectra import WaveSpectrumWarning, wave_spectrum

SPECTRA = ('Modified PM', 'JONSWAP', 'Torsethaugen')

_Fields = namedtuple('DirectionalSpectrum', 'S_M Omega Amp S M mu d_omega d_mu spectrum '
                     'parameters')


class DirectionalSpectrum(_Fields):
    """S_M (N x D, m^2 s/rad), Omega (N, rad/s), Amp (N x D, m), S (N), M (D), mu (D, rad),
    the interval widths d_omega (rad/s) and d_mu (rad; 1 without spreading), the spectrum name
    and its parameters [Hs, w0(, gamma)]."""

    def summary(self):
        hs, w0 = self.parameters[0], self.parameters[1]
        t0 = 2.0 * math.pi / w0
        spread = 'no spreading function' if self.M.size == 1 else 'spreading function M(mu)'
        return (f'Spectrum: {self.spectrum} ({spread}); Hs = {hs:g} m; w0 = {w0:g} rad/s '
                f'(T0 = {t0:.4g} s, Tz = 0.710 T0 = {0.71 * t0:.4g} s); '
                f'{self.Omega.size} frequencies, {self.mu.size} directions')


def _spectrum_name(name):
    for s in SPECTRA:
        if name.replace('_', ' ').lower() == s.lower() or \
                name.lower() == s.replace(' ', '_').lower():
            return s
    raise ValueError(f'spectrum {name!r}: allowed {", ".join(SPECTRA)}')


def wave_directional_spectrum(spectrum, parameters, n_freq, omega_max, spreading=False,
                              n_dir=16, *, u_mu=None, u_omega=None, rng=None):
    """DirectionalSpectrum of MSS ``waveDirectionalSpectrum`` (Fossen 2021, Sec. 10.2).

    ``spectrum``: 'Modified PM' (Tz = 0.710 * 2 pi / w0), 'JONSWAP' (needs gamma; w0 sqrt(Hs)
    must be in [0, 1.75]) or 'Torsethaugen'; ``parameters`` [Hs (m), w0 (rad/s)(, gamma)];
    ``n_freq`` N; ``omega_max`` (rad/s); ``spreading`` on/off; ``n_dir`` D (>= 2, ignored
    without spreading). Draws: ``u_mu`` (D) and ``u_omega`` (N) uniform numbers, or ``rng``
    (numpy Generator; default_rng() if neither is given) drawing them in that order.
    """
    name = _spectrum_name(spectrum)
    hs, w0 = float(parameters[0]), float(parameters[1])
    n_freq = int(n_freq)
    if rng is None and (u_omega is None or (spreading and u_mu is None)):
        rng = np.random.default_rng()
    if spreading:
        n_dir = int(n_dir)
        if n_dir < 2:
            raise ValueError(f'n_dir = {n_dir}: spreading needs at least 2 directions')
        d_mu = math.pi / (n_dir - 1)
        u_mu = rng.random(n_dir) if u_mu is None else np.asarray(u_mu, dtype=float)
        mu = -math.pi / 2.0 + np.arange(n_dir) * d_mu + (u_mu - 0.5) * d_mu
        mu = np.clip(mu, -math.pi / 2.0, math.pi / 2.0)
        M = (2.0 / math.pi) * np.cos(mu) ** 2
        M = M / (np.sum(np.diff(mu) * (M[:-1] + M[1:])) / 2.0)   # trapz(mu, M), as Octave
    else:
        M, mu, d_mu = np.ones(1), np.zeros(1), 1.0
    d_omega = omega_max / n_freq
    u_omega = rng.random(n_freq) if u_omega is None else np.asarray(u_omega, dtype=float)
    omega = np.arange(n_freq) * d_omega + d_omega / 2.0 + (u_omega - 0.5) * d_omega
    if name == 'Modified PM':
        S = wave_spectrum(5, [hs, 0.710 * (2.0 * math.pi / w0)], omega)
    elif name == 'JONSWAP':
        if len(parameters) < 3:
            raise ValueError('JONSWAP needs parameters [Hs, w0, gamma]')
        if w0 * math.sqrt(hs) < 0.0 or w0 * math.sqrt(hs) > 1.75:
            raise ValueError(f'JONSWAP: w0 sqrt(Hs) = {w0 * math.sqrt(hs):.4g} is outside '
                             '[0, 1.75] (MSS recommends 1.25 to 1.75)')
        S = wave_spectrum(7, [hs, w0, float(parameters[2])], omega)
    else:
        if w0 < 0.6:
            warnings.warn('For w0 <= 0.6, only one peak in the Torsethaugen spectrum appears',
                          WaveSpectrumWarning, stacklevel=2)
        S = wave_spectrum(8, [hs, w0], omega)
    S_M = S[:, None] * M[None, :]
    amp = np.sqrt(2.0 * S_M * d_omega * d_mu)
    return DirectionalSpectrum(S_M, omega, amp, S, M, mu, d_omega, d_mu, name,
                               [float(x) for x in parameters])
