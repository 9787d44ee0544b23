"""Wind coefficients and loads of Isherwood (1972) and Blendermann (1994), as coded in MSS.

Source: Fossen, Marine Systems Simulator (github.com/cybergalactic/MSS, commit 736a3d1),
``LIBRARY/environment/isherwood72.m`` and ``blendermann94.m``; Isherwood 1972 (Wind resistance
of merchant ships, Trans. RINA 115), Blendermann 1994 (Parameter identification of wind loads
on ships, J. Wind Eng. Ind. Aerodyn. 51), Fossen 2021 (Handbook, Ch. 10.1).

Units: angles rad, speeds m/s, lengths m, areas m^2; forces N, moments N m. The relative wind
angle gamma_r is measured from the bow, gamma_r = -atan2(v_rw, u_rw) (Fossen 2021), so
gamma_r = 0 is a head wind (surge force aft, CX < 0) and the sway force has the sign of
gamma_r. Air density 1.224 kg/m^3 as in MSS.

Both functions reproduce the MSS arithmetic (tested against the MSS functions run in Octave)
and take scalars or arrays of gamma_r (any shape, element by element). Quirks of the MSS code:

isherwood72
- reproduced: the coefficients are interpolated at the angle folded into [0, 180] deg, but
  the sway force and yaw moment are multiplied by sign(gamma_r) of the RAW angle, so 270 deg
  gives the loads of +90 deg (not of -90 deg); gamma_r = 0 gives Y = N = 0 exactly.
- fixed: MSS folds angles above 180 deg only if ALL elements of a vector exceed 180 deg (an
  ``if`` on a vector); otherwise the others give NaN. Here every element is folded, as a scalar
  call would.
- no roll coefficient: K is not part of the method (the loads here return none).
blendermann94
- reproduced: no angle wrapping; the stern drag coefficient is taken where |gamma_r| > pi/2
  (so 3 pi/2 < gamma_r <= 2 pi uses it), and CN = (sL/Loa - 0.18 (gamma_r - pi/2)) CY is not
  mirror-symmetric, so only gamma_r in [0, pi] gives the intended physics (ship_sim.environment
  .wind evaluates it at |gamma_r| and mirrors, see there).
- argument order as coded: AFw before ALw. sH acts as the vertical lever of the roll moment
  (CK = kappa sH / Hm CY) and sL as the longitudinal one, as in Fossen 2021 (the MSS header's
  descriptions of the two are swapped).
- CK is returned; the roll moment K = 1/2 rho_a V_r^2 ALw Hm CK (Fossen 2021) is given by
  ``blendermann94_roll`` (MSS returns no roll load).
"""
import functools

import numpy as np

from ..models.math_backends import ARRAY_OPS

RHO_AIR = 1.224   # kg/m^3, MSS

_DEG = np.arange(0.0, 181.0, 10.0)

# Isherwood (1972) coefficient tables as tabulated in isherwood72.m, rows at 0:10:180 deg.
# CX: A0..A6, CY: B0..B6, CN: C0..C5.
_ISHERWOOD_A = np.array([
    [2.152, -5.00, 0.243, -0.164, 0, 0, 0],
    [1.714, -3.33, 0.145, -0.121, 0, 0, 0],
    [1.818, -3.97, 0.211, -0.143, 0, 0, 0.033],
    [1.965, -4.81, 0.243, -0.154, 0, 0, 0.041],
    [2.333, -5.99, 0.247, -0.190, 0, 0, 0.042],
    [1.726, -6.54, 0.189, -0.173, 0.348, 0, 0.048],
    [0.913, -4.68, 0, -0.104, 0.482, 0, 0.052],
    [0.457, -2.88, 0, -0.068, 0.346, 0, 0.043],
    [0.341, -0.91, 0, -0.031, 0, 0, 0.032],
    [0.355, 0, 0, 0, -0.247, 0, 0.018],
    [0.601, 0, 0, 0, -0.372, 0, -0.020],
    [0.651, 1.29, 0, 0, -0.582, 0, -0.031],
    [0.564, 2.54, 0, 0, -0.748, 0, -0.024],
    [-0.142, 3.58, 0, 0.047, -0.700, 0, -0.028],
    [-0.677, 3.64, 0, 0.069, -0.529, 0, -0.032],
    [-0.723, 3.14, 0, 0.064, -0.475, 0, -0.032],
    [-2.148, 2.56, 0, 0.081, 0, 1.27, -0.027],
    [-2.707, 3.97, -0.175, 0.126, 0, 1.81, 0],
    [-2.529, 3.76, -0.174, 0.128, 0, 1.55, 0]])
_ISHERWOOD_B = np.array([
    [0, 0, 0, 0, 0, 0, 0],
    [0.096, 0.22, 0, 0, 0, 0, 0],
    [0.176, 0.71, 0, 0, 0, 0, 0],
    [0.225, 1.38, 0, 0.023, 0, -0.29, 0],
    [0.329, 1.82, 0, 0.043, 0, -0.59, 0],
    [1.164, 1.26, 0.121, 0, -0.242, -0.95, 0],
    [1.163, 0.96, 0.101, 0, -0.177, -0.88, 0],
    [0.916, 0.53, 0.069, 0, 0, -0.65, 0],
    [0.844, 0.55, 0.082, 0, 0, -0.54, 0],
    [0.889, 0, 0.138, 0, 0, -0.66, 0],
    [0.799, 0, 0.155, 0, 0, -0.55, 0],
    [0.797, 0, 0.151, 0, 0, -0.55, 0],
    [0.996, 0, 0.184, 0, -0.212, -0.66, 0.34],
    [1.014, 0, 0.191, 0, -0.280, -0.69, 0.44],
    [0.784, 0, 0.166, 0, -0.209, -0.53, 0.38],
    [0.536, 0, 0.176, -0.029, -0.163, 0, 0.27],
    [0.251, 0, 0.106, -0.022, 0, 0, 0],
    [0.125, 0, 0.046, -0.012, 0, 0, 0],
    [0, 0, 0, 0, 0, 0, 0]])
_ISHERWOOD_C = np.array([
    [0, 0, 0, 0, 0, 0],
    [0.0596, 0.061, 0, 0, 0, -0.074],
    [0.1106, 0.204, 0, 0, 0, -0.170],
    [0.2258, 0.245, 0, 0, 0, -0.380],
    [0.2017, 0.457, 0, 0.0067, 0, -0.472],
    [0.1759, 0.573, 0, 0.0118, 0, -0.523],
    [0.1925, 0.480, 0, 0.0115, 0, -0.546],
    [0.2133, 0.315, 0, 0.0081, 0, -0.526],
    [0.1827, 0.254, 0, 0.0053, 0, -0.443],
    [0.2627, 0, 0, 0, 0, -0.508],
    [0.2102, 0, -0.0195, 0, 0.0335, -0.492],
    [0.1567, 0, -0.0258, 0, 0.0497, -0.457],
    [0.0801, 0, -0.0311, 0, 0.0740, -0.396],
    [-0.0189, 0, -0.0488, 0.0101, 0.1128, -0.420],
    [0.0256, 0, -0.0422, 0.0100, 0.0889, -0.463],
    [0.0552, 0, -0.0381, 0.0109, 0.0689, -0.476],
    [0.0881, 0, -0.0306, 0.0091, 0.0366, -0.415],
    [0.0851, 0, -0.0122, 0.0025, 0, -0.220],
    [0, 0, 0, 0, 0, 0]])

#: Blendermann (1994) vessel types, numbered 1..17 as in blendermann94.m.
BLENDERMANN_TYPES = (
    'car carrier', 'cargo vessel, loaded', 'cargo vessel, container on deck',
    'container ship, loaded', 'destroyer', 'diving support vessel', 'drilling vessel', 'ferry',
    'fishing vessel', 'liquified natural gas tanker', 'offshore supply vessel',
    'passenger liner', 'research vessel', 'speed boat', 'tanker, loaded', 'tanker, in ballast',
    'tender')

# Rows [CD_t, CD_l_AF(bow), CD_l_AF(stern), delta, kappa] per vessel type (Fossen 2021,
# Ch. 10.1.2, as tabulated in blendermann94.m).
_BLENDERMANN = np.array([
    [0.95, 0.55, 0.60, 0.80, 1.2],
    [0.85, 0.65, 0.55, 0.40, 1.7],
    [0.85, 0.55, 0.50, 0.40, 1.4],
    [0.90, 0.55, 0.55, 0.40, 1.4],
    [0.85, 0.60, 0.65, 0.65, 1.1],
    [0.90, 0.60, 0.80, 0.55, 1.7],
    [1.00, 0.5 * (0.70 + 1.00), 0.5 * (0.75 + 1.10), 0.10, 1.7],
    [0.90, 0.45, 0.50, 0.80, 1.1],
    [0.95, 0.70, 0.70, 0.40, 1.1],
    [0.70, 0.60, 0.65, 0.50, 1.1],
    [0.90, 0.55, 0.80, 0.55, 1.2],
    [0.90, 0.40, 0.40, 0.80, 1.2],
    [0.85, 0.55, 0.65, 0.60, 1.4],
    [0.90, 0.55, 0.60, 0.60, 1.1],
    [0.70, 0.90, 0.55, 0.40, 3.1],
    [0.70, 0.75, 0.55, 0.40, 2.2],
    [0.85, 0.55, 0.55, 0.65, 1.1]])


def _interp_rows(table, deg):
    """Each column of ``table`` (rows at _DEG) linearly interpolated at ``deg``: (..., ncols)."""
    return np.stack([np.interp(deg, _DEG, col) for col in table.T], axis=-1)


def _series(coef, terms):
    """coef[..., 0] + coef[..., 1] terms[0] + ..., summed left to right as MSS writes it."""
    total = coef[..., 0]
    for k, t in enumerate(terms, start=1):
        total = total + coef[..., k] * t
    return total


def isherwood72(gamma_r, V_r, Loa, B, ALw, AFw, A_SS, S, C, M):
    """Isherwood (1972) wind loads and coefficients, MSS isherwood72.m.

    Returns (tau, CX, CY, CN) with tau = (X, Y, N) stacked on the last axis (..., 3) for array
    gamma_r, a length-3 array for a scalar. CX, CY, CN are those of the folded angle, unsigned.
    """
    gamma_r = np.asarray(gamma_r, dtype=float)
    deg = np.mod(gamma_r * (180.0 / np.pi), 360.0)
    deg = np.where(deg > 180.0, 360.0 - deg, deg)
    a = _interp_rows(_ISHERWOOD_A, deg)
    b = _interp_rows(_ISHERWOOD_B, deg)
    c = _interp_rows(_ISHERWOOD_C, deg)
    # The regressors of Isherwood's formulas, in MSS's order (A6 multiplies M, B6 A_SS/ALw).
    terms = [2 * ALw / Loa ** 2, 2 * AFw / B ** 2, Loa / B, S / Loa, C / Loa]
    CX = -_series(a, terms + [M])
    CY = _series(b, terms + [A_SS / ALw])
    CN = _series(c, terms)
    q = 0.5 * RHO_AIR * V_r ** 2
    sign = np.sign(gamma_r)
    tau = np.stack([q * CX * AFw, q * CY * ALw * sign, q * CN * ALw * Loa * sign], axis=-1)
    return tau, CX, CY, CN


def blendermann94(gamma_r, V_r, AFw, ALw, sH, sL, Loa, vessel_no):
    """Blendermann (1994) wind loads and coefficients, MSS blendermann94.m (AFw before ALw).

    ``vessel_no`` 1..17 (BLENDERMANN_TYPES). Returns (tau, CX, CY, CK, CN) with tau = (X, Y, N)
    on the last axis as in ``isherwood72``; CK (roll) is returned but not part of tau, as in
    MSS (``blendermann94_roll`` gives the moment).
    """
    X, Y, N, CX, CY, CK, CN = blendermann94_terms(ARRAY_OPS, np.asarray(gamma_r, dtype=float),
                                                  V_r, AFw, ALw, sH, sL, Loa,
                                                  blendermann_row(vessel_no))
    return np.stack([X, Y, N], axis=-1), CX, CY, CK, CN


@functools.lru_cache(maxsize=None)
def blendermann_row(vessel_no):
    """(CD_t, CD_l_AF bow, CD_l_AF stern, delta, kappa) of a vessel type 1..17, as floats."""
    if not (isinstance(vessel_no, (int, np.integer)) and 1 <= vessel_no <= len(_BLENDERMANN)):
        raise ValueError(f'vessel_no = {vessel_no!r} is out of range; allowed: 1..'
                         f'{len(_BLENDERMANN)} (BLENDERMANN_TYPES)')
    return tuple(float(c) for c in _BLENDERMANN[vessel_no - 1])


def blendermann94_terms(ops, gamma_r, V_r, AFw, ALw, sH, sL, Loa, row):
    """The arithmetic of blendermann94.m on floats or arrays (ship_sim.models.math_backends):
    returns X, Y, N, CX, CY, CK, CN for the type's ``blendermann_row``."""
    CDt, bow, stern, delta, kappa = row
    CDlAF = ops.where(abs(gamma_r) <= np.pi / 2, bow, stern)
    CDl = CDlAF * AFw / ALw
    den = 1 - 0.5 * delta * (1 - CDl / CDt) * ops.sin(2 * gamma_r) ** 2
    CX = -CDlAF * ops.cos(gamma_r) / den
    CY = CDt * ops.sin(gamma_r) / den
    CK = kappa * (sH / (ALw / Loa)) * CY
    CN = (sL / Loa - 0.18 * (gamma_r - np.pi / 2)) * CY
    q = 0.5 * RHO_AIR * V_r ** 2
    return q * CX * AFw, q * CY * ALw, q * CN * ALw * Loa, CX, CY, CK, CN


def blendermann94_roll(CK, V_r, ALw, Loa):
    """Roll moment (N m) K = 1/2 rho_a V_r^2 ALw Hm CK, Hm = ALw / Loa (Fossen 2021, Ch. 10.1)."""
    return 0.5 * RHO_AIR * V_r ** 2 * ALw * (ALw / Loa) * CK
