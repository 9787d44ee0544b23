"""First-order wave loads and wave-frequency motions from RAO tables, MSS ``waveForceRAO.m``
and ``waveMotionRAO.m`` (Fossen 2021, eqs. 10.96 and 10.105: output superposition).

RAO tables (package data ``data/rao_<vessel>.npz``, from MSS ``HYDRO/vessels_shipx``): the
zero-speed slices of the force and motion RAOs of the S-175 container ship (``s175``, Son and
Nomoto's ship, MSS container.m) and of the supply vessel (``supply``), amplitude (N/m, N m/m,
m/m, rad/m) and phase (rad) for 6 DOF [surge, sway, heave, roll, pitch, yaw] (MSS's body
axes), 36 frequencies x 36 headings (0, 10, ..., 350 deg; 0 = following sea, 180 = head sea).

``WaveResponse`` is the persistent cache of the MSS functions made an explicit object: it
holds the RAOs interpolated at the component frequencies and the random phases, so building
a new one is what ``clear waveForceRAO`` is in MSS (whose stale cache across scenarios is thus
knowingly fixed). Reproduced as coded: only the zero-speed RAOs are used whatever U is, the
encounter frequency is |w - w^2 U cos(beta) / g|, and interpolation is linear with linear
extrapolation in frequency and in direction (no wrap-around: beta in (350, 360) deg is
extrapolated from the 340-350 deg segment) unless ``wrap_headings=True`` (the plant's choice:
a 360 deg column equal to the 0 deg one). MSS draws the phases with rng(12345) in MATLAB's
generator; here they are an input (or drawn from a numpy Generator).

``spheroid_rao`` builds the Froude-Krylov force table of a submerged prolate spheroid (an
AUV hull, e.g. the NPS AUV II), MSS ``spheroidRAO.m``.
"""
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np

DATA = Path(__file__).with_name('data')
VESSELS = ('s175', 'supply')


@dataclass(frozen=True)
class RaoTable:
    """One RAO table: ``w`` (n_w, rad/s), ``headings`` (n_h, rad), ``amp`` and ``phase``
    (6 x n_w x n_h), ``g`` (m/s^2, the vessel file's), ``length`` Lpp (m), ``kind`` 'force' or
    'motion', ``vessel`` name, ``scale`` (1, or the Froude scale it was scaled by)."""
    w: np.ndarray
    headings: np.ndarray
    amp: np.ndarray
    phase: np.ndarray
    g: float
    length: float
    kind: str
    vessel: str
    scale: float = 1.0

    def truncated(self, max_freq):
        """The table with only the frequencies <= max_freq (as the MSS examples do)."""
        keep = self.w <= max_freq
        return replace(self, w=self.w[keep], amp=self.amp[:, keep], phase=self.phase[:, keep])

    def froude_scaled(self, length):
        """The table of a geometrically similar ship of Lpp ``length`` (Froude scaling by
        lam = length / Lpp: w / sqrt(lam); motion RAOs m/m unchanged and rad/m / lam; force RAOs
        N/m x lam^2 and N m/m x lam^3; phases unchanged)."""
        lam = float(length) / self.length
        if self.kind == 'motion':
            f = np.array([1.0, 1.0, 1.0, 1.0 / lam, 1.0 / lam, 1.0 / lam])
        else:
            f = np.array([lam ** 2] * 3 + [lam ** 3] * 3)
        return replace(self, w=self.w / np.sqrt(lam), amp=self.amp * f[:, None, None],
                       length=float(length), scale=self.scale * lam)


def load_rao_table(vessel='s175', kind='motion'):
    """The zero-speed ``kind`` ('force' or 'motion') RAO table of ``vessel`` (VESSELS)."""
    if vessel not in VESSELS or kind not in ('force', 'motion'):
        raise ValueError(f'RAO table {vessel!r}/{kind!r}: vessels {", ".join(VESSELS)}, kinds '
                         'force, motion')
    with np.load(DATA / f'rao_{vessel}.npz') as d:
        return RaoTable(w=d[f'{kind}_w'], headings=d['headings'], amp=d[f'{kind}_amp'],
                        phase=d[f'{kind}_phase'], g=float(d['g']), length=float(d['Lpp']),
                        kind=kind, vessel=vessel)


def spheroid_rao(a, b, zn, *, signed=False):
    """Froude-Krylov wave force RAO table of a prolate spheroid of semi-axes ``a`` (along the
    body, m) and ``b`` (m) whose centre is ``zn`` m below the surface, MSS ``spheroidRAO.m``.

    Deep water, k = w^2 / g on w = 0.05..4 rad/s (100 points), headings 0..350 deg: heave
    F3 = rho g pi b^2 exp(-k zn), surge and sway F3 cos/sin(beta), roll and pitch moments
    F5 sin/cos(beta) with F5 = (a^2 - b^2) / (5 a) k F3, no yaw; headings 190..350 deg mirror
    170..10 deg with signs (1, -1, 1, -1, 1, -1). As coded in MSS the table is real and its
    amplitude is |Re| with phase 0, so waveForceRAO loses the sign: the sway force at 270 deg
    equals the one at 90 deg. ``signed=True`` knowingly fixes that (phase pi where Re < 0)."""
    if not zn > 0.0:
        raise ValueError(f'spheroid depth zn = {zn!r} m: must be > 0 (submerged)')
    g, rho = 9.81, 1025.0                      # the values coded in spheroidRAO.m
    w = np.linspace(0.05, 4.0, 100)
    k = w ** 2 / g
    F3 = rho * g * np.pi * b ** 2 * np.exp(-k * zn)
    F5 = (a ** 2 - b ** 2) / (5.0 * a) * k * F3
    half = np.deg2rad(np.arange(0.0, 190.0, 10.0))          # 0..180 deg
    c, s = np.cos(half)[None, :], np.sin(half)[None, :]
    re_half = np.stack([F3[:, None] * c, F3[:, None] * s, np.repeat(F3[:, None], half.size, 1),
                        F5[:, None] * s, F5[:, None] * c, np.zeros((w.size, half.size))])
    signs = np.array([1.0, -1.0, 1.0, -1.0, 1.0, -1.0])[:, None, None]
    re = np.concatenate([re_half, signs * re_half[:, :, 17:0:-1]], axis=2)
    phase = np.where(re < 0.0, np.pi, 0.0) if signed else np.zeros_like(re)
    return RaoTable(w=w, headings=np.deg2rad(np.arange(0.0, 360.0, 10.0)), amp=np.abs(re),
                    phase=phase, g=g, length=2.0 * a, kind='force', vessel='spheroid')


#: Complex elements (DOF x vessels x components) of one block of a batch's wave response:
#: 16 bytes each (512 KiB), so the few such temporaries alive at a time fit a core's L2 cache,
#: and a block is large enough that numpy's per-call cost stays small beside its work.
BLOCK_ELEMENTS = 32_768


def _interp_extrap(x, xq):
    """Indices i and weights s of linear interpolation with linear extrapolation (interp1
    'linear', 'extrap'): y(xq) = y[i] + s (y[i+1] - y[i])."""
    i = np.clip(np.searchsorted(x, xq, side='right') - 1, 0, x.size - 2)
    return i, (xq - x[i]) / (x[i + 1] - x[i])


class WaveResponse:
    """First-order wave response of one vessel to one set of wave components.

    ``table``: RaoTable; ``Omega`` (N, rad/s) and ``mu`` (D, rad, relative to the main wave
    direction) and ``Amp`` (N x D, m) from ``wave_directional_spectrum``; ``phases`` (N x D,
    rad) or ``rng`` (numpy Generator) to draw them uniformly in [0, 2 pi).

    A batch of vessels, each with its own components (the batched closed loop): ``Omega``
    (B x N), ``mu`` (B x D), ``Amp`` and ``phases`` (B x N x D); the methods then take U, psi
    and beta_wave as arrays (B) and return 6 x B (the same arithmetic per vessel). Vessels
    with equal component frequencies (one sea state) share their stored RAOs, and ``motion``
    and ``force`` run over blocks of vessels (``BLOCK_ELEMENTS``).
    """

    def __init__(self, table, Omega, mu, Amp, phases=None, *, rng=None, wrap_headings=False):
        self.table = table
        Omega = np.asarray(Omega, dtype=float)
        mu = np.asarray(mu, dtype=float)
        # Leading axes of a 2-D Omega are a batch of vessels (each its own components).
        self.batch_shape = Omega.shape[:-1] if Omega.ndim > 1 else ()
        self.Omega = Omega.reshape(self.batch_shape + (-1,))
        self.mu = mu.reshape(self.batch_shape + (-1,))
        shape = self.Omega.shape + self.mu.shape[-1:]
        self.Amp = np.asarray(Amp, dtype=float).reshape(shape)
        if phases is None:
            phases = 2.0 * np.pi * (rng or np.random.default_rng()).random(shape)
        self.phases = np.asarray(phases, dtype=float).reshape(shape)
        self.g = table.g
        re = table.amp * np.cos(table.phase)         # 6 x n_w x n_h
        im = table.amp * np.sin(table.phase)
        headings = table.headings
        if wrap_headings:
            headings = np.append(headings, headings[0] + 2.0 * np.pi)
            re = np.concatenate([re, re[:, :, :1]], axis=2)
            im = np.concatenate([im, im[:, :, :1]], axis=2)
        if len(self.batch_shape) > 1:
            raise ValueError('WaveResponse takes one batch axis')
        # The RAOs depend on the component frequencies only: vessels whose frequencies are
        # equal (one sea state, e.g. a shared seed) share one copy; self._vessel maps each
        # vessel to its row of the stored RAOs.
        Omega_rao, self._vessel = self.Omega, None
        if self.batch_shape:
            Omega_rao, inverse = np.unique(self.Omega, axis=0, return_inverse=True)
            self._vessel = inverse.reshape(-1)[:, None]
        self._re, self._im = re, im
        self._w_index = _interp_extrap(table.w, Omega_rao)
        self._rao = {}
        self._headings = headings
        # w^2 / g of every component: depends on the sea only, not on the step.
        self._om2_g = self.Omega[..., :, None] ** 2 / self.g

    def _stored_rao(self, dofs=None):
        """The RAOs of DOF ``dofs`` (None: all 6) at the component frequencies, made once:
        [unique frequency sets x] n_h x len(dofs) x N complex (the MSS cache), so that
        picking a heading per vessel and direction copies whole blocks. One complex array
        (the real and imaginary parts interpolated alike: a real weight times a complex
        number scales both parts, the same numbers as two real interpolations); the rows of
        a subset of DOF are computed from the table's rows of those DOF alone (element-wise,
        the same numbers as the full table's rows), so a 3-DOF loop never stores all 6."""
        rao = self._rao.get(dofs)
        if rao is None:
            rows = slice(None) if dofs is None else list(dofs)
            re, im = self._re[rows], self._im[rows]
            i, s = self._w_index
            s = s[None, ..., None]
            rao = (re[:, i] + s * (re[:, i + 1] - re[:, i])) \
                + 1j * (im[:, i] + s * (im[:, i + 1] - im[:, i]))     # dofs x [S x] N x n_h
            rao = self._rao[dofs] = np.ascontiguousarray(np.moveaxis(rao, [0, -1], [-2, -3]))
        return rao

    def _at(self, U, psi, beta_wave, dofs=None, vessels=slice(None)):
        """Encounter frequencies ([batch x] N x D) and complex RAOs (6 x [batch x] N x D) for
        one heading per vessel (U, psi, beta_wave: scalars, or arrays of the batch shape);
        ``dofs`` (indices into the 6 DOF): the RAOs of those DOF only (len(dofs) x ...);
        ``vessels``: a slice of the batch (U, psi, beta_wave then of that slice)."""
        U, psi, beta_wave = (np.asarray(a, dtype=float)[..., None] for a in (U, psi, beta_wave))
        beta = np.mod(beta_wave - psi + self.mu[vessels], 2.0 * np.pi)
        Om = self.Omega[vessels][..., :, None]
        Oe = np.abs(Om - self._om2_g[vessels] * U[..., None] * np.cos(beta)[..., None, :])
        i, s = _interp_extrap(self._headings, beta)
        z0, z1 = (self._pick(j, dofs, vessels) for j in (i, i + 1))
        s = s[None, ..., None, :]
        return Oe, z0 + s * (z1 - z0)

    def _pick(self, i, dofs=None, vessels=slice(None)):
        """RAOs at heading-table column i ([batch x] D) -> 6 (or len(dofs)) x [batch x] N x D
        (contiguous); ``vessels``: the slice of the batch that i is of."""
        rao = self._stored_rao(dofs)
        z = rao[i] if self._vessel is None else rao[self._vessel[vessels], i]
        return np.ascontiguousarray(np.moveaxis(z, [-3, -2], [-1, 0]))

    def response_amplitudes(self, U, psi, beta_wave):
        """(encounter frequencies N x D, response amplitudes |RAO| Amp 6 x N x D) of every
        component: which components dominate the response, and at which frequency."""
        Oe, Z = self._at(U, psi, beta_wave)
        return Oe, np.abs(Z) * self.Amp

    def _phasors(self, Oe, t, vessels=slice(None)):
        """Amp exp(i (w_e t + phase)) of every component (N x D): |Z| Amp cos(w_e t + arg Z +
        phase) summed over the components is Re(sum Z times this), evaluated that way."""
        return self.Amp[vessels] * np.exp(1j * (Oe * t + self.phases[vessels]))

    def _by_blocks(self, f, n_dofs, U, psi, beta_wave):
        """f(vessels, U, psi, beta_wave) -> arrays (... x B) evaluated on blocks of vessels,
        each block's (n_dofs x block x N x D) complex temporaries small enough to stay in
        the CPU cache: the cost per vessel then does not grow with the batch, and a step's
        arrays stay far below the mmap threshold ship_sim.allocator sets. Each vessel's
        numbers are those of one evaluation of the whole batch (the same element-wise
        arithmetic and the same sum over its own components)."""
        if not self.batch_shape:
            return f(slice(None), U, psi, beta_wave)
        n = self.batch_shape[0]
        size = max(1, BLOCK_ELEMENTS // (n_dofs * self.Amp[0].size))
        if n <= size:
            return f(slice(None), U, psi, beta_wave)
        U, psi, beta_wave = np.broadcast_arrays(*(np.asarray(a, dtype=float)
                                                  for a in (U, psi, beta_wave)))
        if U.shape != self.batch_shape:
            raise ValueError(f'U, psi and beta_wave of shape {U.shape}: expected '
                             f'{self.batch_shape} or scalars')
        out = None
        for lo in range(0, n, size):
            v = slice(lo, lo + size)
            part = f(v, U[v], psi[v], beta_wave[v])
            if out is None:
                out = [None if p is None else np.empty(p.shape[:-1] + (n,)) for p in part]
            for o, p in zip(out, part):
                if p is not None:
                    o[..., v] = p
        return tuple(out)

    def elevation(self, t, U, psi, beta_wave):
        """Wave elevation (m) the vessel sees at time t (s), MSS waveElevation."""
        Oe = self._at(U, psi, beta_wave)[0]
        out = np.sum(self.Amp * np.cos(Oe * t + self.phases), axis=(-2, -1))
        return float(out) if not self.batch_shape else out

    def force(self, t, U, psi, beta_wave):
        """First-order wave loads tau_wave1 (6: N, N, N, N m, N m, N m) at time t (s), speed U
        (m/s), heading psi (rad) and main wave direction beta_wave (rad, 0 = following sea
        for psi = 0), MSS waveForceRAO (Fossen 2021, eq. 10.96)."""
        def block(v, U, psi, beta_wave):
            Oe, Z = self._at(U, psi, beta_wave, vessels=v)
            return (np.real(np.sum(Z * self._phasors(Oe, t, v), axis=(-2, -1))),)
        return self._by_blocks(block, 6, U, psi, beta_wave)[0]

    def motion(self, t, U, psi, beta_wave, rates=True, accelerations=True, dofs=None):
        """Wave-frequency motion (eta_WF, nu_WF, nudot_WF), 6 each (m, rad; per s; per s^2), MSS
        waveMotionRAO (Fossen 2021, eq. 10.105); ``rates=False`` returns eta_WF only,
        ``accelerations=False`` None for nudot_WF (not computed). ``dofs``: a tuple of DOF
        indices (e.g. SURGE_SWAY_YAW) to compute, the others not computed and NaN; the
        computed ones are the numbers of the full computation, bit for bit (the same
        element-wise arithmetic and the same sum over each DOF's components)."""
        def block(v, U, psi, beta_wave):
            Oe, Z = self._at(U, psi, beta_wave, dofs, v)
            zp = Z * self._phasors(Oe, t, v)
            eta = _rows(np.real(np.sum(zp, axis=(-2, -1))), dofs)
            if not rates:
                return eta, None, None
            izp = 1j * Oe * zp
            nu = _rows(np.real(np.sum(izp, axis=(-2, -1))), dofs)
            if not accelerations:
                return eta, nu, None
            return eta, nu, _rows(np.real(np.sum(1j * Oe * izp, axis=(-2, -1))), dofs)
        eta, nu, nudot = self._by_blocks(block, 6 if dofs is None else len(dofs), U, psi,
                                         beta_wave)
        return (eta, nu, nudot) if rates else eta


#: The DOF a 3-DOF (surge, sway, yaw) manoeuvring model uses, for ``WaveResponse.motion``.
SURGE_SWAY_YAW = (0, 1, 5)


def _rows(values, dofs):
    """len(dofs) x ... -> 6 x ...: the computed DOF in their rows, NaN in the others."""
    if dofs is None:
        return values
    out = np.full((6,) + values.shape[1:], np.nan)
    out[list(dofs)] = values
    return out
