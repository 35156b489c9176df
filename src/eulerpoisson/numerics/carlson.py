r"""Carlson's symmetric elliptic integrals in float64 (part of :mod:`.elliptic`).

:func:`elliprf`, :func:`elliprd`, :func:`elliprj`, :func:`elliprc` by the
duplication algorithm, and their unchecked cores :func:`rf_core`,
:func:`rj_core` (used by the closed form) and :func:`rc1_series` (compiled
into its kernels). Notation and references: see
:mod:`eulerpoisson.numerics.elliptic`, which re-exports every name.

Algorithm
---------
*Carlson integrals* use the duplication theorem with the truncation criteria
and the Taylor series of Carlson (1995) / DLMF 19.36.  In ``R_J`` the
argument ``1 + e_m`` of the ``R_C`` terms is formed as
``2 sqrt(p_m) (p_m + lambda_m) / d_m`` (an exact identity), which removes the
cancellation for ``p << x, y, z``; a term with ``|e_m| <= 2**-5`` (every step
but the first one or two: ``e_m`` falls by about 64 per step) is the
Maclaurin series of ``atan(t)/t`` in ``e = t**2`` (:func:`rc1_series`, eleven
terms, remainder below ``2**-59``) instead of ``atan`` or ``log1p``.
Converged elements leave the working set, so a result does not depend on the
batch it is computed in (bitwise).

Examples
--------
>>> float(elliprc(0.0, 1.0))  # pi/2
1.5707963267948966
"""

from __future__ import annotations

import numpy as np

from ..errors import InvalidInputError
from ..util.jit import jitable
from .elliptic_common import real_array as _as_float_array
from .elliptic_common import scalar_out as _out

__all__ = [
    "elliprf",
    "elliprd",
    "elliprj",
    "elliprc",
    "rf_core",
    "rj_core",
    "rc1_series",
    "RC_SERIES_MAX",
]

_MAX_DUPLICATION = 200
# Carlson's truncation tolerance r (Carlson 1995); with the degree-7 series of
# DLMF 19.36.1 the truncation error is far below one ulp.
_R_TOL = 2.0**-53
_RF_QFAC = (3.0 * _R_TOL) ** (-1.0 / 6.0)
_RDJ_QFAC = (0.25 * _R_TOL) ** (-1.0 / 6.0)
_RC_QFAC = (3.0 * _R_TOL) ** (-1.0 / 8.0)
#: the R_C terms of R_J use the series of atan(t)/t in e = t^2 for |e| <= 2**-5
RC_SERIES_MAX = 2.0**-5


# ---------------------------------------------------------------------------
# Carlson symmetric integrals (duplication algorithm)
# ---------------------------------------------------------------------------
def _duplicate(q, state, step):
    """Run a duplication iteration to convergence, element by element.

    ``state`` is a list of flat arrays whose first two entries are ``A_n``
    and ``4**-n``; an element is converged when ``4**-n q < |A_n|``
    (Carlson 1995).  Converged elements are removed from the working set
    (so the cost follows the active elements and results do not depend on
    the batch they are computed in); returns the final states.
    """
    final = [v.copy() for v in state]
    idx = np.arange(q.size)
    cur = list(state)
    qc = q
    for _ in range(_MAX_DUPLICATION):
        act = cur[1] * qc >= np.abs(cur[0])
        if not np.all(act):
            done = ~act
            di = idx[done]
            for f, c in zip(final, cur):
                f[di] = c[done]
            idx = idx[act]
            if idx.size == 0:
                return final
            qc = qc[act]
            cur = [c[act] for c in cur]
        cur = step(cur)
    for f, c in zip(final, cur):
        f[idx] = c
    return final


def _flat(*args):
    arrs = np.broadcast_arrays(*(np.asarray(a, np.float64) for a in args))
    shape = arrs[0].shape
    return shape, [np.array(a, dtype=np.float64).ravel() for a in arrs]


def _rf_step(st):
    a, fac, x, y, z = st
    sx, sy, sz = np.sqrt(x), np.sqrt(y), np.sqrt(z)
    lam = sx * sy + sy * sz + sz * sx
    return [0.25 * (a + lam), 0.25 * fac, 0.25 * (x + lam), 0.25 * (y + lam), 0.25 * (z + lam)]


def rf_core(x, y, z):
    """R_F for non-negative arrays with at most one zero (no checks)."""
    shape, (x, y, z) = _flat(x, y, z)
    a0 = (x + y + z) / 3.0
    q = _RF_QFAC * np.maximum(np.maximum(np.abs(a0 - x), np.abs(a0 - y)), np.abs(a0 - z))
    a, fac, *_ = _duplicate(q, [a0, np.ones_like(a0), x, y, z], _rf_step)
    X = (a0 - x) * fac / a
    Y = (a0 - y) * fac / a
    Z = -(X + Y)
    e2 = X * Y - Z * Z
    e3 = X * Y * Z
    poly = (
        1.0
        - e2 / 10.0
        + e3 / 14.0
        + e2 * e2 / 24.0
        - 3.0 * e2 * e3 / 44.0
        - 5.0 * e2 * e2 * e2 / 208.0
        + 3.0 * e3 * e3 / 104.0
        + e2 * e2 * e3 / 16.0
    )
    return (poly / np.sqrt(a)).reshape(shape)


def _rd_step(st):
    a, fac, x, y, z, acc = st
    sx, sy, sz = np.sqrt(x), np.sqrt(y), np.sqrt(z)
    lam = sx * sy + sy * sz + sz * sx
    return [
        0.25 * (a + lam),
        0.25 * fac,
        0.25 * (x + lam),
        0.25 * (y + lam),
        0.25 * (z + lam),
        acc + fac / (sz * (z + lam)),
    ]


def _rd(x, y, z):
    """R_D for x, y >= 0 (at most one zero), z > 0 (no checks)."""
    shape, (x, y, z) = _flat(x, y, z)
    a0 = (x + y + 3.0 * z) / 5.0
    q = _RDJ_QFAC * np.maximum(np.maximum(np.abs(a0 - x), np.abs(a0 - y)), np.abs(a0 - z))
    st = [a0, np.ones_like(a0), x, y, z, np.zeros_like(a0)]
    a, fac, _, _, _, acc = _duplicate(q, st, _rd_step)
    X = (a0 - x) * fac / a
    Y = (a0 - y) * fac / a
    Z = -(X + Y) / 3.0
    xy = X * Y
    z2 = Z * Z
    e2 = xy - 6.0 * z2
    e3 = (3.0 * xy - 8.0 * z2) * Z
    e4 = 3.0 * (xy - z2) * z2
    e5 = xy * z2 * Z
    poly = (
        1.0
        - 3.0 * e2 / 14.0
        + e3 / 6.0
        + 9.0 * e2 * e2 / 88.0
        - 3.0 * e4 / 22.0
        - 9.0 * e2 * e3 / 52.0
        + 3.0 * e5 / 26.0
    )
    return (fac * poly / (a * np.sqrt(a)) + 3.0 * acc).reshape(shape)


@jitable
def rc1_series(e):
    r"""``R_C(1, 1 + e)`` for ``|e| <= 2**-5`` by its Maclaurin series (DLMF 19.2.18-19).

    ``R_C(1, 1 + e) = atan(sqrt e)/sqrt e = atanh(sqrt(-e))/sqrt(-e) =
    sum_k (-e)^k/(2k + 1)``; eleven terms (Horner, degree 10): the remainder
    is below ``|e|^11/23 < 2**-59`` relative.  Plain arithmetic, so the NumPy
    path and the compiled kernels (which inline it) agree bit for bit; in the
    duplication of ``R_J`` all steps but the first one or two take this branch
    (``e`` falls by about 64 per step), which saves an ``atan`` (or ``log1p``),
    a square root and a division each.
    """
    return 1.0 + e * (
        -1.0 / 3.0
        + e
        * (
            1.0 / 5.0
            + e
            * (
                -1.0 / 7.0
                + e
                * (
                    1.0 / 9.0
                    + e
                    * (
                        -1.0 / 11.0
                        + e * (1.0 / 13.0 + e * (-1.0 / 15.0 + e * (1.0 / 17.0 + e * (-1.0 / 19.0 + e * (1.0 / 21.0)))))
                    )
                )
            )
        )
    )


def _rc1(e, y):
    """``R_C(1, y)`` with ``y = 1 + e``, both given accurately, ``y > 0``.

    ``|e| <= 2**-5``: the series :func:`rc1_series`.  Otherwise the closed
    forms (DLMF 19.2.18-19): ``atan(t)/t`` with ``t = sqrt(e)`` for
    ``e > 0``; ``atanh(t)/t = log1p(2 t (1 + t) / y) / (2 t)`` with
    ``t = sqrt(-e)`` for ``e < 0`` (``1 - t = y / (1 + t)``: no cancellation
    as ``y -> 0``).
    """
    small = np.abs(e) <= RC_SERIES_MAX
    ser = rc1_series(e)
    if np.all(small):
        return ser
    t = np.sqrt(np.abs(e))
    ts = np.where(t > 0.0, t, 1.0)
    pos = e > 0.0
    if np.all(pos | small):
        return np.where(small, ser, np.arctan(t) / ts)
    neg = 0.5 * np.log1p(2.0 * t * (1.0 + t) / y) / ts
    if not np.any(pos & ~small):
        return np.where(small, ser, np.where(e < 0.0, neg, 1.0))
    return np.where(small, ser, np.where(pos, np.arctan(t) / ts, np.where(e < 0.0, neg, 1.0)))


def _rj_delta(x, y, z, p):
    r"""``(delta, sc)``: :math:`\delta = (p-x)(p-y)(p-z)`, scaled against underflow.

    :math:`|p-x|\le(\sqrt p+\sqrt x)^2`, so :math:`|\delta|\le d^2` in every
    duplication step, and ``e = fac^3 delta / d^2`` is O(1) even when both
    underflow (``p``, ``x``, ``y`` of order 1e-162 and below: the regime-B
    integral ``R_J(0, m1, 1, m1 c)`` near the separatrix). Where
    :math:`|\delta| < 2^{-960}` the two small factors are scaled by powers of
    two into ``[1/2, 1)`` and ``sc`` is the square root of the total scale, so
    that ``e = fac^3 delta / (d sc)^2`` exactly as before; elsewhere ``sc = 1``
    and nothing changes (bit for bit).
    """
    f1, f2, f3 = p - x, p - y, p - z
    delta = f1 * f2 * f3
    sc = np.ones_like(delta)
    tiny = (np.abs(delta) < 2.0**-960) & (f1 != 0) & (f2 != 0) & (f3 != 0)
    if np.any(tiny):
        e1 = np.where(tiny & (np.abs(f1) < 0.5), -np.frexp(f1)[1], 0)
        e2 = np.where(tiny & (np.abs(f2) < 0.5), -np.frexp(f2)[1], 0)
        e1 = e1 + (e1 + e2) % 2  # an even total: sc is an exact power of two
        delta = np.where(tiny, np.ldexp(f1, e1) * np.ldexp(f2, e2) * f3, delta)
        sc = np.where(tiny, np.ldexp(1.0, (e1 + e2) // 2), sc)
    return delta, sc


def _rj_step(st):
    a, fac, x, y, z, p, acc, delta, sc = st
    sx, sy, sz, sp = np.sqrt(x), np.sqrt(y), np.sqrt(z), np.sqrt(p)
    lam = sx * sy + sy * sz + sz * sx
    d = (sp + sx) * (sp + sy) * (sp + sz)
    dd = d * sc
    with np.errstate(over="ignore"):  # (d sc)^2 = inf only where e underflows to 0 anyway
        e = (fac * fac * fac) * delta / (dd * dd)
    # 1 + e = 2 sqrt(p) (p + lambda) / d exactly (expand the products), which
    # avoids the cancellation in 1 + e for p << x, y, z
    y1 = 2.0 * sp * (p + lam) / d
    return [
        0.25 * (a + lam),
        0.25 * fac,
        0.25 * (x + lam),
        0.25 * (y + lam),
        0.25 * (z + lam),
        0.25 * (p + lam),
        acc + fac * _rc1(e, y1) / d,
        delta,
        sc,
    ]


def rj_core(x, y, z, p):
    """R_J for x, y, z >= 0 (at most one zero), p > 0 (no checks)."""
    shape, (x, y, z, p) = _flat(x, y, z, p)
    a0 = (x + y + z + 2.0 * p) / 5.0
    delta, sc = _rj_delta(x, y, z, p)
    q = _RDJ_QFAC * np.maximum(
        np.maximum(np.abs(a0 - x), np.abs(a0 - y)),
        np.maximum(np.abs(a0 - z), np.abs(a0 - p)),
    )
    st = [a0, np.ones_like(a0), x, y, z, p, np.zeros_like(a0), delta, sc]
    a, fac, _, _, _, _, acc, _, _ = _duplicate(q, st, _rj_step)
    X = (a0 - x) * fac / a
    Y = (a0 - y) * fac / a
    Z = (a0 - z) * fac / a
    P = -(X + Y + Z) / 2.0
    xyz = X * Y * Z
    p2 = P * P
    e2 = X * Y + X * Z + Y * Z - 3.0 * p2
    e3 = xyz + 2.0 * e2 * P + 4.0 * p2 * P
    e4 = (2.0 * xyz + e2 * P + 3.0 * p2 * P) * P
    e5 = xyz * p2
    poly = (
        1.0
        - 3.0 * e2 / 14.0
        + e3 / 6.0
        + 9.0 * e2 * e2 / 88.0
        - 3.0 * e4 / 22.0
        - 9.0 * e2 * e3 / 52.0
        + 3.0 * e5 / 26.0
    )
    return (fac * poly / (a * np.sqrt(a)) + 6.0 * acc).reshape(shape)


def _rc_step(st):
    a, fac, x, y = st
    lam = 2.0 * np.sqrt(x) * np.sqrt(y) + y
    return [0.25 * (a + lam), 0.25 * fac, 0.25 * (x + lam), 0.25 * (y + lam)]


def _rc(x, y):
    """R_C for x >= 0, y > 0 (no checks), by duplication (Carlson 1995)."""
    shape, (x, y) = _flat(x, y)
    a0 = (x + 2.0 * y) / 3.0
    q = _RC_QFAC * np.abs(a0 - x)
    a, fac, _, _ = _duplicate(q, [a0, np.ones_like(a0), x, y], _rc_step)
    s = (y - a0) * fac / a
    poly = 1.0 + s * s * (
        3.0 / 10.0 + s * (1.0 / 7.0 + s * (3.0 / 8.0 + s * (9.0 / 22.0 + s * (159.0 / 208.0 + s * 9.0 / 8.0))))
    )
    return (poly / np.sqrt(a)).reshape(shape)


def _check_nonneg(name, arr):
    if np.any(arr < 0.0):
        bad = arr[arr < 0.0].ravel()[0].item()
        raise InvalidInputError(f"{name} must be >= 0, got {name}={bad!r}")


def elliprf(x, y, z):
    r"""Carlson's symmetric integral of the first kind.

    .. math:: R_F(x,y,z) = \frac12\int_0^\infty
              \frac{dt}{\sqrt{(t+x)(t+y)(t+z)}}

    Duplication algorithm (Carlson 1995, DLMF 19.36.1), relative error of a
    few ulp.

    Parameters
    ----------
    x, y, z : array_like
        Non-negative, at most one of them zero (broadcast together).

    Returns
    -------
    ndarray

    Raises
    ------
    InvalidInputError
        On negative or non-finite arguments or if two or more are zero.
    """
    x, y, z = (_as_float_array(v, n) for v, n in ((x, "x"), (y, "y"), (z, "z")))
    for n, v in (("x", x), ("y", y), ("z", z)):
        _check_nonneg(n, v)
    zeros = (x == 0.0).astype(int) + (y == 0.0) + (z == 0.0)
    if np.any(zeros >= 2):
        raise InvalidInputError("elliprf: at most one of x, y, z may be zero (R_F diverges)")
    return _out(rf_core(x, y, z))


def elliprd(x, y, z):
    r"""Carlson's symmetric integral of the second kind.

    .. math:: R_D(x,y,z) = \frac32\int_0^\infty
              \frac{dt}{\sqrt{(t+x)(t+y)}\,(t+z)^{3/2}}

    Parameters
    ----------
    x, y : array_like
        Non-negative, not both zero.
    z : array_like
        Positive.

    Returns
    -------
    ndarray

    Raises
    ------
    InvalidInputError
        On negative/non-finite arguments, ``z <= 0`` or ``x = y = 0``.
    """
    x, y, z = (_as_float_array(v, n) for v, n in ((x, "x"), (y, "y"), (z, "z")))
    _check_nonneg("x", x)
    _check_nonneg("y", y)
    if np.any(z <= 0.0):
        raise InvalidInputError(f"elliprd: z must be > 0, got z={z[z <= 0.0].ravel()[0].item()!r}")
    if np.any((x == 0.0) & (y == 0.0)):
        raise InvalidInputError("elliprd: x and y must not both be zero (R_D diverges)")
    return _out(_rd(x, y, z))


def elliprj(x, y, z, p):
    r"""Carlson's symmetric integral of the third kind.

    .. math:: R_J(x,y,z,p) = \frac32\int_0^\infty
              \frac{dt}{(t+p)\sqrt{(t+x)(t+y)(t+z)}}

    Duplication algorithm with the ``R_C`` correction terms (Carlson 1995,
    DLMF 19.36.ii).  Only ``p > 0`` (no Cauchy principal value).

    Parameters
    ----------
    x, y, z : array_like
        Non-negative, at most one zero.
    p : array_like
        Positive.

    Returns
    -------
    ndarray

    Raises
    ------
    InvalidInputError
        On negative/non-finite arguments, ``p <= 0`` or two zeros among
        ``x, y, z``.
    """
    x, y, z, p = (_as_float_array(v, n) for v, n in ((x, "x"), (y, "y"), (z, "z"), (p, "p")))
    for n, v in (("x", x), ("y", y), ("z", z)):
        _check_nonneg(n, v)
    if np.any(p <= 0.0):
        raise InvalidInputError(
            f"elliprj: p must be > 0 (principal values are not supported), got p={p[p <= 0.0].ravel()[0].item()!r}"
        )
    zeros = (x == 0.0).astype(int) + (y == 0.0) + (z == 0.0)
    if np.any(zeros >= 2):
        raise InvalidInputError("elliprj: at most one of x, y, z may be zero (R_J diverges)")
    return _out(rj_core(x, y, z, p))


def elliprc(x, y):
    r"""Carlson's degenerate integral ``R_C(x, y) = R_F(x, y, y)``.

    .. math:: R_C(x,y) = \frac12\int_0^\infty \frac{dt}{\sqrt{t+x}\,(t+y)}

    Duplication algorithm (no cancellation for ``x ~ y``).

    Parameters
    ----------
    x : array_like
        Non-negative.
    y : array_like
        Positive (no principal value).

    Returns
    -------
    ndarray

    Raises
    ------
    InvalidInputError
        On negative/non-finite ``x`` or ``y <= 0``.
    """
    x = _as_float_array(x, "x")
    y = _as_float_array(y, "y")
    _check_nonneg("x", x)
    if np.any(y <= 0.0):
        raise InvalidInputError(f"elliprc: y must be > 0, got y={y[y <= 0.0].ravel()[0].item()!r}")
    return _out(_rc(x, y))
