r"""The Lie series :math:`z(t) = e^{tL_H} z_0` of paper eq. 1.23.1 (part of :mod:`.symbolic`).

Exact Taylor coefficients of the canonical flow of the free body
(:func:`taylor_coefficients`, :func:`lie_series`), Hamilton's equations in
floats (:func:`hamilton_rhs`) and the check of a truncated series against
them (:func:`check_lie_series`). Re-exported by
:mod:`eulerpoisson.paper.symbolic`.

Examples
--------
>>> MAX_LIE_ORDER
16
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from ..errors import InvalidInputError
from .symbolic_derivation import derive
from .symbolic_rational import Ctx, Rat
from .symbolic_tensors import levi_civita, sympy_module

__all__ = [
    "MAX_LIE_ORDER",
    "lie_series",
    "taylor_coefficients",
    "hamilton_rhs",
    "LieSeriesCheck",
    "check_lie_series",
]

#: Largest order accepted by :func:`lie_series` (the cost grows quickly).
MAX_LIE_ORDER = 16


def _check_order(order) -> int:
    if isinstance(order, bool) or not isinstance(order, (int, np.integer)):
        raise InvalidInputError(f"order must be an integer in [0, {MAX_LIE_ORDER}], got {order!r}")
    order = int(order)
    if not 0 <= order <= MAX_LIE_ORDER:
        raise InvalidInputError(f"order must be an integer in [0, {MAX_LIE_ORDER}], got {order}")
    return order


def _to_rational(x, name):
    sp = sympy_module()
    if isinstance(x, sp.Basic):
        return x
    if isinstance(x, (bool, np.bool_)):
        raise InvalidInputError(f"{name} must contain numbers, got {x!r}")
    if isinstance(x, (int, np.integer)):
        return sp.Integer(int(x))
    if isinstance(x, (float, np.floating)):
        xf = float(x)
        if not math.isfinite(xf):
            raise InvalidInputError(f"{name} must be finite, got {xf}")
        return sp.Rational(repr(xf))
    try:
        return sp.sympify(x)
    except Exception as exc:
        raise InvalidInputError(f"{name} must contain numbers or sympy expressions, got {x!r}") from exc


def _inverse_inertia(inertia):
    """Return (K, back) with K = I^{-1} as a SymPy matrix.

    For symbolic inertia K holds symbols (``K11..`` or ``K1..``) and ``back``
    maps them to the entries of I^{-1} in terms of the inertia symbols of
    :func:`derive`; for numeric inertia K is exact and ``back`` is None.
    """
    sp = sympy_module()
    if inertia is None or (isinstance(inertia, str) and inertia == "general"):
        ks = sp.symbols("K11 K12 K13 K22 K23 K33")
        K = sp.Matrix([[ks[0], ks[1], ks[2]], [ks[1], ks[3], ks[4]], [ks[2], ks[4], ks[5]]])
        d = derive("general")
        back = {ks[0]: (0, 0), ks[1]: (0, 1), ks[2]: (0, 2), ks[3]: (1, 1), ks[4]: (1, 2), ks[5]: (2, 2)}
        return K, (d, back)
    if isinstance(inertia, str):
        if inertia == "diagonal":
            ks = sp.symbols("K1:4")
            d = derive("diagonal")
            return sp.diag(*ks), (d, {ks[0]: (0, 0), ks[1]: (1, 1), ks[2]: (2, 2)})
        raise InvalidInputError(
            f"inertia must be None, 'general', 'diagonal', 3 principal moments or a 3x3 matrix, got {inertia!r}"
        )
    if isinstance(inertia, sp.MatrixBase):
        vals = inertia.tolist() if inertia.cols > 1 else [x for x in inertia]
    else:
        vals = np.asarray(inertia, dtype=object).tolist()
    shape = np.shape(np.asarray(vals, dtype=object))
    if shape == (3,):
        I = sp.diag(*[_to_rational(v, "inertia") for v in vals])
    elif shape == (3, 3):
        I = sp.Matrix([[_to_rational(v, "inertia") for v in row] for row in vals])
        if I != I.T:
            raise InvalidInputError(f"inertia must be symmetric, got {I.tolist()}")
    else:
        raise InvalidInputError(f"inertia must have shape (3,) or (3, 3), got shape {shape}")
    if I.free_symbols:
        raise InvalidInputError(
            "inertia given as a matrix must be numeric; use inertia='general' or 'diagonal' for symbols"
        )
    if I.det() == 0:
        raise InvalidInputError(f"inertia must be invertible, got det(inertia) = 0 for {I.tolist()}")
    return I.inv(), None


def _vector_arg(v, name):
    sp = sympy_module()
    if isinstance(v, sp.MatrixBase):
        vals = list(v)
    else:
        arr = np.asarray(v, dtype=object)
        if arr.ndim != 1:
            raise InvalidInputError(f"{name} must be a 3-vector, got shape {arr.shape}")
        vals = list(arr)
    if len(vals) != 3:
        raise InvalidInputError(f"{name} must be a 3-vector, got {len(vals)} components")
    return sp.Matrix([_to_rational(x, name) for x in vals])


def _lie_coefficients(order, K, pi0, n0, back):
    """Lie-series coefficients as a list of rows of 6 SymPy expressions (private)."""
    sp = sympy_module()
    params = set()
    for e in list(K) + list(pi0) + list(n0):
        params |= e.free_symbols
    extra = []
    known = []
    if back is not None:
        d, _ = back
        extra = [s for s in d.inertia_symbols if s not in params]
        known = [d.detI] if d.inertia == "general" else list(d.inertia_symbols)
    ordered = sorted(params, key=lambda s: s.name)
    dsyms = sp.symbols("_d1:4")
    psyms = sp.symbols("_p1:4")
    ctx = Ctx(list(dsyms) + list(psyms) + ordered + extra, known)
    R = ctx.ring
    d_ = [ctx.gens[x] for x in dsyms]
    p_ = [ctx.gens[x] for x in psyms]

    def conv(e):
        return ctx.poly(e)

    nfull = [conv(n0[i]) + d_[i] for i in range(3)]
    Kr = [[conv(K[i, j]) for j in range(3)] for i in range(3)]
    # (A^{-1} pi)_i = pi_i + (n.pi) n_i + (pi x n)_i, A^{-1} derived in Derivation.Atilde
    npi = sum(nfull[i] * p_[i] for i in range(3))
    v = [
        p_[i] + npi * nfull[i] + sum(levi_civita(i, j, k) * p_[j] * nfull[k] for j in range(3) for k in range(3))
        for i in range(3)
    ]
    H = sum(Kr[i][j] * v[i] * v[j] for i in range(3) for j in range(3)) * sp.QQ(1, 8)
    Hn = [H.diff(x) for x in d_]
    Hp = [H.diff(x) for x in p_]
    nd = len(d_)

    def by_degree(f):
        groups: dict = {}
        for mon, c in f.items():
            groups.setdefault(mon[0] + mon[1] + mon[2], []).append((mon, c))
        return {deg: R.from_terms(terms) for deg, terms in groups.items()}

    Hp_g = [by_degree(h) for h in Hp]
    Hn_g = [by_degree(h) for h in Hn]

    def mul_trunc(f, g_groups, maxdeg):
        # product keeping only terms of degree <= maxdeg in n - n0 (no wasted terms)
        acc = R.zero
        for a, fa in by_degree(f).items():
            for b, gb in g_groups.items():
                if a + b <= maxdeg:
                    acc += fa * gb
        return acc

    def lie(f, maxdeg):
        acc = R.zero
        for i in range(nd):
            acc += mul_trunc(f.diff(d_[i]), Hp_g[i], maxdeg) - mul_trunc(f.diff(p_[i]), Hn_g[i], maxdeg)
        return acc

    def truncate(f, maxdeg):
        return R.from_dict({mon: c for mon, c in f.items() if mon[0] + mon[1] + mon[2] <= maxdeg})

    pi0r = [ctx.from_expr(pi0[i]) for i in range(3)]
    mapping_back = None
    if back is not None:
        dv, backmap = back
        Iinv = dv.Iinv
        mapping_back = {k: ctx.from_expr(Iinv[i, j]) for k, (i, j) in backmap.items() if k in ctx.gens}
    current = [truncate(x, order) for x in (d_[0], d_[1], d_[2], p_[0], p_[1], p_[2])]
    coeffs = []
    fact = 1
    for k in range(order + 1):
        if k > 0:
            fact *= k
        row = []
        for f in current:
            f0 = R.from_dict({mon: c for mon, c in f.items() if mon[0] == mon[1] == mon[2] == 0})
            r = ctx.subs(Rat(ctx, f0, {}), dict(zip(psyms, pi0r)))
            if mapping_back:
                r = ctx.subs(r, mapping_back)
            row.append((r * sp.Rational(1, fact)).normalize().expr())
        coeffs.append(row)
        if k < order:
            current = [lie(f, order - k - 1) for f in current]
    for i in range(3):
        coeffs[0][i] = coeffs[0][i] + n0[i]
    return coeffs


#: highest-order Lie coefficients computed so far, per (inertia, pi0, n0): lower orders are
#: slices of them (a small LRU: insertion order is recency)
_LIE_STORE: dict = {}
_LIE_STORE_SIZE = 32


@functools.lru_cache(maxsize=8)
def _lie_cached(order, inertia_key, pi0_key, n0_key):
    sp = sympy_module()
    inertia = inertia_key if isinstance(inertia_key, str) else sp.Matrix(3, 3, list(inertia_key))
    K, back = _inverse_inertia(inertia)
    pi0 = sp.Matrix(list(pi0_key))
    n0 = sp.Matrix(list(n0_key))
    return sp.Matrix(_lie_coefficients(order, K, pi0, n0, back))


def taylor_coefficients(order: int, inertia=None, pi0=None, n0=None, *, as_float: bool = False):
    r"""Taylor coefficients of the Lie series of eq. 1.23.1.

    .. math:: z^a(t) = \sum_{k=0}^{\text{order}} c_k^a t^k, \qquad
              c_k^a = \frac{1}{k!}\,(L_H^k z^a)\big|_{z = z_0}, \qquad
              L_H f = \{f, H\},

    with :math:`z = (n_1, n_2, n_3, \pi_1, \pi_2, \pi_3)`, the Hamiltonian
    :math:`H = \tfrac18 (\tilde A\pi)^T I^{-1}(\tilde A\pi)` and the canonical
    bracket.  Since :math:`L_H` lowers the degree in
    :math:`\mathbf n - \mathbf n_0` by at most one, :math:`L_H^k z` is
    truncated to degree ``order - k`` in :math:`\mathbf n - \mathbf n_0`
    (exact for the coefficients returned).  These are the Taylor
    coefficients of the exact solution, so a numeric Taylor integrator can be
    compared with them term by term.

    Parameters
    ----------
    order : int
        Highest power of ``t``, ``0 <= order <= 16``.
    inertia : None, "general", "diagonal", array_like (3,) or (3, 3)
        Symbolic general (``None``/"general", symbols ``I11..I33``) or
        diagonal (``I1..I3``) inertia, principal moments, or a symmetric
        matrix.  Floats are converted to the rationals of their decimal repr.
    pi0 : None or array_like (3,)
        Initial momenta; ``None`` gives symbols ``pi0_1..pi0_3``.
    n0 : None or array_like (3,)
        Initial Gibbs vector; ``None`` (default) is the paper's
        :math:`\mathbf n_0 = 0`.
    as_float : bool
        Return a float array (requires numeric ``inertia``, ``pi0``, ``n0``).

    Returns
    -------
    sympy.Matrix, shape (order + 1, 6), or ndarray of float, shape (order + 1, 6)
        Row ``k`` holds :math:`c_k` for :math:`(n_1, n_2, n_3, \pi_1, \pi_2, \pi_3)`.

    Raises
    ------
    InvalidInputError
        Bad ``order`` (not an integer in [0, 16]), bad ``inertia`` / ``pi0`` /
        ``n0`` shapes or values, or ``as_float`` with symbolic input.

    References
    ----------
    Paper eq. 1.23.1; Deriglazov, Universe 8 (2022) 536 (exponential of the
    Hamiltonian vector field).
    """
    sp = sympy_module()
    order = _check_order(order)
    ikey: str | tuple[Any, ...]
    if inertia is None or isinstance(inertia, str):
        ikey = "general" if inertia is None else inertia
        _inverse_inertia(ikey)  # validates the string
    else:
        K, _ = _inverse_inertia(inertia)
        ikey = tuple(K.inv())
    pi0v = sp.Matrix(sp.symbols("pi0_1:4", real=True)) if pi0 is None else _vector_arg(pi0, "pi0")
    n0v = sp.zeros(3, 1) if n0 is None else _vector_arg(n0, "n0")
    key = (ikey, tuple(pi0v), tuple(n0v))
    best = _LIE_STORE.pop(key, None)
    if best is None or best.rows < order + 1:
        best = _lie_cached(order, *key)
    _LIE_STORE[key] = best  # most recently used last
    while len(_LIE_STORE) > _LIE_STORE_SIZE:
        _LIE_STORE.pop(next(iter(_LIE_STORE)))
    M = best[: order + 1, :]
    if as_float:
        if M.free_symbols:
            raise InvalidInputError(
                "as_float=True needs numeric inertia, pi0 and n0; got free symbols "
                f"{sorted(str(s) for s in M.free_symbols)}"
            )
        return np.array([[float(x) for x in row] for row in M.tolist()], dtype=float)
    return M


def lie_series(order: int, inertia=None, pi0=None, n0=None, t=None):
    r"""Truncated Lie series :math:`e^{tL_H}z_0` of eq. 1.23.1.

    Parameters
    ----------
    order : int
        Truncation order (highest power of ``t``), ``0 <= order <= 16``.
    inertia, pi0, n0 :
        As in :func:`taylor_coefficients` (defaults: symbolic general inertia,
        symbolic :math:`\boldsymbol\pi_0`, :math:`\mathbf n_0 = 0`).
    t : sympy.Symbol, optional
        Time symbol (default ``Symbol("t")``).

    Returns
    -------
    n_t, pi_t : sympy.Matrix, shape (3, 1)
        Polynomials in ``t`` of degree ``order``.

    Raises
    ------
    InvalidInputError
        As in :func:`taylor_coefficients`.

    Examples
    --------
    >>> from eulerpoisson.paper.symbolic import lie_series
    >>> n_t, pi_t = lie_series(1, inertia=[1, 2, 3], pi0=[4, 0, 0])
    >>> n_t.T
    Matrix([[t, 0, 0]])
    """
    sp = sympy_module()
    C = taylor_coefficients(order, inertia, pi0, n0)
    t = sp.Symbol("t") if t is None else t
    z = [sum((C[k, a] * t**k for k in range(C.rows)), sp.Integer(0)) for a in range(6)]
    return sp.Matrix(z[:3]), sp.Matrix(z[3:])


def hamilton_rhs(z, Kinv):
    r"""Right-hand side of Hamilton's equations (eq. 1.16, corrected) in NumPy.

    .. math:: \dot n = \tfrac14\tilde A^T K\tilde A\pi, \qquad
              \dot\pi_i = -\tfrac14[\delta_{ij}(n,\pi) + \pi_i n_j
              + \epsilon_{ijk}\pi_k](K\tilde A\pi)_j, \qquad K = I^{-1}.

    Parameters
    ----------
    z : ndarray, shape (6,)
        :math:`(\mathbf n, \boldsymbol\pi)`.
    Kinv : ndarray, shape (3, 3)
        Inverse inertia tensor :math:`I^{-1}`.

    Returns
    -------
    ndarray, shape (6,)

    Raises
    ------
    InvalidInputError
        If the shapes are wrong.
    """
    z = np.asarray(z, dtype=float)
    Kinv = np.asarray(Kinv, dtype=float)
    if z.shape != (6,) or Kinv.shape != (3, 3):
        raise InvalidInputError(f"hamilton_rhs: z must have shape (6,) and Kinv (3, 3), got {z.shape} and {Kinv.shape}")
    n = z[:3]
    p = z[3:]
    nh = np.array([[0.0, n[2], -n[1]], [-n[2], 0.0, n[0]], [n[1], -n[0], 0.0]])  # eps_ijk n_k
    At = np.eye(3) + np.outer(n, n) + nh
    w = Kinv @ (At @ p)
    ph = np.array([[0.0, p[2], -p[1]], [-p[2], 0.0, p[0]], [p[1], -p[0], 0.0]])  # eps_ijk pi_k
    B = np.dot(n, p) * np.eye(3) + np.outer(p, n) + ph
    return np.concatenate([0.25 * At.T @ w, -0.25 * B @ w])


@dataclass(frozen=True)
class LieSeriesCheck:
    """Result of :func:`check_lie_series`.

    Attributes
    ----------
    order : int
        Truncation order of the series.
    times : ndarray, shape (T,)
    errors : ndarray, shape (T,)
        Max-norm difference between the series and the numeric solution.
    slope : float
        Least-squares slope of ``log(errors)`` against ``log(times)``;
        ``order + 1`` is expected.
    """

    order: int
    times: np.ndarray
    errors: np.ndarray
    slope: float

    @property
    def expected_slope(self) -> int:
        return self.order + 1


def check_lie_series(order: int, inertia, pi0, n0=None, times: ArrayLike | None = None) -> LieSeriesCheck:
    r"""Compare the truncated Lie series with a numeric solution of eq. 1.16.

    The reference is :func:`scipy.integrate.solve_ivp` (DOP853, ``rtol=1e-13``,
    ``atol=1e-15``) of :func:`hamilton_rhs`.  The truncation error of an
    order-``k`` series behaves like :math:`C t^{k+1}`, so ``slope`` should be
    close to ``order + 1``.

    Parameters
    ----------
    order : int
        Series order, ``1 <= order <= 16``.
    inertia : array_like (3,) or (3, 3)
        Numeric inertia.
    pi0 : array_like (3,)
        Numeric initial momenta.
    n0 : array_like (3,), optional
        Initial Gibbs vector (default 0).
    times : sequence of float, optional
        Positive times; by default five times, geometrically spaced, where
        :math:`(t/T)^{\text{order}+1}` runs from about ``1e-8`` to ``1e-4``
        (``T = 1/max|Omega0|``), so the truncation error dominates both the
        roundoff and the reference error.

    Returns
    -------
    LieSeriesCheck

    Raises
    ------
    InvalidInputError
        Non-numeric input, bad order, or non-positive times.
    """
    from scipy.integrate import solve_ivp

    order = _check_order(order)
    if order < 1:
        raise InvalidInputError(f"order must be >= 1 for check_lie_series, got {order}")
    if inertia is None or isinstance(inertia, str):
        raise InvalidInputError(f"check_lie_series needs numeric inertia, got {inertia!r}")
    if pi0 is None:
        raise InvalidInputError("check_lie_series needs numeric pi0, got None")
    C = taylor_coefficients(order, inertia, pi0, n0, as_float=True)
    K, _ = _inverse_inertia(inertia)
    Kf = np.array(K.tolist(), dtype=float)
    z0 = C[0]
    if times is None:
        n, p = z0[:3], z0[3:]
        nh = np.array([[0.0, n[2], -n[1]], [-n[2], 0.0, n[0]], [n[1], -n[0], 0.0]])
        Om0 = 0.5 * Kf @ ((np.eye(3) + np.outer(n, n) + nh) @ p)
        T = 1.0 / max(float(np.max(np.abs(Om0))), 1e-12)
        q = order + 1
        t_hi = T * min(0.5, 10.0 ** (-4.0 / q))
        times = np.geomspace(t_hi * 10.0 ** (-4.0 / q), t_hi, 5)
    times = np.asarray(times, dtype=float)
    if times.ndim != 1 or times.size < 2 or not np.all(np.isfinite(times)) or np.any(times <= 0):
        raise InvalidInputError(f"times must be >= 2 positive finite values, got {times!r}")
    ts = np.sort(times)
    sol = solve_ivp(
        lambda _t, z: hamilton_rhs(z, Kf),
        (0.0, float(ts[-1])),
        z0,
        method="DOP853",
        t_eval=ts,
        rtol=1e-13,
        atol=1e-15,
    )
    if not sol.success:  # pragma: no cover - solver failure
        raise InvalidInputError(f"reference integration failed: {sol.message}")
    powers = ts[:, None] ** np.arange(order + 1)[None, :]
    series = powers @ C  # (T, 6)
    errors = np.max(np.abs(series - sol.y.T), axis=1)
    slope = float(np.polyfit(np.log(ts), np.log(np.maximum(errors, 1e-300)), 1)[0])
    return LieSeriesCheck(order=order, times=ts, errors=errors, slope=slope)
