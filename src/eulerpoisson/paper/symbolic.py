r"""Symbolic (SymPy) derivation of the paper's formulas from its Lagrangian.

Everything here is derived from first principles, never copied from the
paper's printed formulas, so that :mod:`eulerpoisson.paper.audit` can compare the
two:

* the rotation matrix :math:`R(\mathbf n)` from the axis-angle construction
  before eq. 1.7 and the half-angle identities (eq. 1.8-1.9);
* the body angular velocity
  :math:`\Omega_k = -\tfrac12\epsilon_{kij}(R^T\dot R)_{ij}` (eq. 1.10), the
  conversion matrix :math:`A = \tfrac12(\partial\boldsymbol\Omega/
  \partial\dot{\mathbf n})^T` and :math:`\tilde A = A^{-1}` (eq. 1.11-1.12);
* the metric :math:`G_{ij} = \partial^2 L/\partial\dot n_i\partial\dot n_j`
  of :math:`L = \tfrac12\boldsymbol\Omega\cdot I\boldsymbol\Omega`
  (eq. 1.13), its inverse, the Christoffel symbols and the Euler-Lagrange
  (geodesic) equations;
* the momenta :math:`\pi = \partial L/\partial\dot{\mathbf n}`, the Legendre
  transform :math:`H(\mathbf n, \boldsymbol\pi)`, Hamilton's equations
  (eq. 1.14-1.16), the angular momenta :math:`\mathbf m = RI\boldsymbol\Omega`
  and :math:`\mathbf M = I\boldsymbol\Omega` in canonical variables (eq. 1.17),
  and the brackets of the non-canonical coordinates :math:`(\mathbf n,
  \mathbf m)`, :math:`(\mathbf n, \boldsymbol\Omega)`, :math:`(\mathbf n,
  \mathbf M)` computed from the canonical bracket (eq. 1.21, 1.28);
* the Lie series :math:`z(t) = e^{tL_H} z_0` of eq. 1.23.1.

The heavy top (:math:`L = \tfrac12\dot{\mathbf n}^TG\dot{\mathbf n} - U(\mathbf n)`,
:math:`U = -\mu\,\mathbf g\cdot R(\mathbf n)\mathbf c`) is derived on top of
this module in :mod:`eulerpoisson.paper.heavy_top`
(:func:`~eulerpoisson.paper.heavy_top.derive_heavy_top`).

The inertia tensor is either the general symmetric matrix with entries
``I11, I12, I13, I22, I23, I33`` (``inertia="general"``) or
``diag(I1, I2, I3)`` (``inertia="diagonal"``).

Rational expressions are handled as expanded polynomial numerators over
denominators that are products of known factors (:math:`1+\mathbf n^2`,
:math:`\det I`, ...): sums, products, derivatives and substitutions need no
gcd, common factors are removed by exact trial division, and a rational
function is zero exactly when its numerator is (:func:`rsimp`,
:func:`is_zero`).  This is much faster than :func:`sympy.simplify` and makes
the derivation with a general inertia tensor take seconds.

References
----------
A. A. Deriglazov, "Geodesic motion on the symplectic leaf of SO(3) with
distorted e(3) algebra and Liouville integrability of a free rigid body",
eq. 1.1-1.30 (``/work/shared/paper/paper.tex``).
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass
from functools import cached_property
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from ..errors import InvalidInputError, require

__all__ = [
    "INERTIA_KINDS",
    "Derivation",
    "derive",
    "levi_civita",
    "hat",
    "cross",
    "dot",
    "cyclic_tensor",
    "rsimp",
    "rsimp_matrix",
    "is_zero",
    "inverse3",
    "poisson_bracket",
    "rotation_from_axis_angle",
    "rotation_from_quaternion",
    "lie_series",
    "taylor_coefficients",
    "hamilton_rhs",
    "LieSeriesCheck",
    "check_lie_series",
]

#: Accepted values of the ``inertia`` argument of :func:`derive`.
INERTIA_KINDS = ("general", "diagonal")

#: Largest order accepted by :func:`lie_series` (the cost grows quickly).
MAX_LIE_ORDER = 16


_SYMPY = None


def sympy_module():
    global _SYMPY
    if _SYMPY is None:
        _SYMPY = require("sympy", "symbolic")
    return _SYMPY


# ---------------------------------------------------------------------------
# small tensor helpers
# ---------------------------------------------------------------------------


def levi_civita(i: int, j: int, k: int) -> int:
    r"""Levi-Civita symbol :math:`\epsilon_{ijk}` for indices in ``{0, 1, 2}``.

    Parameters
    ----------
    i, j, k : int
        Indices, 0-based.

    Returns
    -------
    int
        ``+1`` for an even permutation of ``(0, 1, 2)``, ``-1`` for an odd one,
        ``0`` otherwise.
    """
    return (i - j) * (j - k) * (k - i) // 2


def hat(v):
    r"""The paper's antisymmetric matrix :math:`\hat v_{ij} = \epsilon_{ijp} v_p`.

    Note :math:`\hat v = -[v]_\times`, i.e. :math:`\hat v w = w\times v`
    (after eq. 1.21 of the paper).

    Parameters
    ----------
    v : sympy.Matrix, shape (3, 1)

    Returns
    -------
    sympy.Matrix, shape (3, 3)
    """
    sp = sympy_module()
    return sp.Matrix(3, 3, lambda i, j: sum(levi_civita(i, j, p) * v[p] for p in range(3)))


def cross(u, v):
    r"""Cross product :math:`[u, v]` of two 3-vectors (the paper's bracket notation).

    Parameters
    ----------
    u, v : sympy.Matrix, shape (3, 1)

    Returns
    -------
    sympy.Matrix, shape (3, 1)
    """
    sp = sympy_module()
    return sp.Matrix(3, 1, lambda i, _: sum(levi_civita(i, j, k) * u[j] * v[k] for j in range(3) for k in range(3)))


def dot(u, v):
    r"""Scalar product :math:`(u, v)` of two 3-vectors."""
    return sum(u[i] * v[i] for i in range(3))


def cyclic_tensor(v):
    r"""The paper's :math:`T_{ijk} = \hat v_{ij} v_k + \text{cycle}(ijk)` (eq. 1.21).

    .. math:: T_{ijk} = \hat v_{ij} v_k + \hat v_{jk} v_i + \hat v_{ki} v_j,
              \qquad \hat v_{ij} = \epsilon_{ijp} v_p .

    It equals :math:`(v\cdot v)\,\epsilon_{ijk}` (a consequence of the
    vanishing of totally antisymmetric 4-index tensors in three dimensions),
    which :mod:`eulerpoisson.paper.audit` verifies.

    Parameters
    ----------
    v : sympy.Matrix, shape (3, 1)

    Returns
    -------
    list of list of list
        ``T[i][j][k]`` as SymPy expressions.
    """
    h = hat(v)
    return [[[h[i, j] * v[k] + h[j, k] * v[i] + h[k, i] * v[j] for k in range(3)] for j in range(3)] for i in range(3)]


# ---------------------------------------------------------------------------
# rational simplification
# ---------------------------------------------------------------------------


def rsimp(expr):
    r"""Normal form of a rational expression, without gcd computations.

    The expression is converted recursively into ``numerator / denominator``
    where the numerator is an expanded polynomial over :math:`\mathbb Q` and
    the denominator a product of powers of the distinct polynomials that occur
    as denominators in ``expr`` (e.g. :math:`(1+\mathbf n^2)^4\det I`);
    common factors are then removed by exact trial division.  The result is
    zero exactly when ``expr`` is identically zero.

    Parameters
    ----------
    expr : sympy.Expr
        A rational function of its symbols (no ``sqrt``, ``sin``, ...).

    Returns
    -------
    sympy.Expr

    Raises
    ------
    InvalidInputError
        If ``expr`` is not a rational function of its symbols, or divides by
        an identically vanishing expression.
    """
    sp = sympy_module()
    expr = sp.sympify(expr)
    if expr.is_Number:
        return expr
    ctx = Ctx(sorted(expr.free_symbols, key=lambda s: s.name))
    return ctx.from_expr(expr).normalize().expr()


def rsimp_matrix(M):
    """Apply :func:`rsimp` to every entry of a SymPy matrix (returns a new matrix)."""
    return M.applyfunc(rsimp)


def is_zero(expr) -> bool:
    """True if the rational expression ``expr`` is identically zero (exact test, see :func:`rsimp`)."""
    sp = sympy_module()
    expr = sp.sympify(expr)
    if expr.is_Number:
        return bool(expr == 0)
    ctx = Ctx(sorted(expr.free_symbols, key=lambda s: s.name))
    return ctx.from_expr(expr).is_zero()


def inverse3(M):
    r"""Exact inverse of a 3x3 matrix of rational functions.

    Computed as :math:`\operatorname{adj}(M)/\det M` on polynomial
    numerators (see :func:`rsimp`).

    Parameters
    ----------
    M : sympy.Matrix, shape (3, 3)

    Returns
    -------
    sympy.Matrix, shape (3, 3)

    Raises
    ------
    InvalidInputError
        If ``M`` is not 3x3 or is singular.
    """
    sp = sympy_module()
    if not isinstance(M, sp.MatrixBase) or M.shape != (3, 3):
        raise InvalidInputError(
            f"inverse3: M must be a sympy Matrix of shape (3, 3), got {getattr(M, 'shape', type(M))}"
        )
    syms = set()
    for e in M:
        syms |= sp.sympify(e).free_symbols
    ctx = Ctx(sorted(syms, key=lambda s: s.name) or [sp.Dummy("x")])
    return ctx.to_matrix(rinv3(ctx.mat(M)))


# ---------------------------------------------------------------------------
# Poisson bracket
# ---------------------------------------------------------------------------


def poisson_bracket(f, g, n, pi):
    r"""Canonical Poisson bracket of phase-space functions.

    .. math:: \{f, g\} = \sum_i \left(\frac{\partial f}{\partial n_i}
              \frac{\partial g}{\partial\pi_i} - \frac{\partial f}{\partial\pi_i}
              \frac{\partial g}{\partial n_i}\right),

    so that :math:`\{n_i, \pi_j\} = \delta_{ij}` (paper eq. 1.15.1).

    Parameters
    ----------
    f, g : sympy.Expr or sympy.Matrix
        Scalars or column vectors (shape ``(k, 1)``).
    n, pi : sequence of sympy.Symbol
        The canonical coordinates and momenta (same length).

    Returns
    -------
    sympy.Expr or sympy.Matrix
        A scalar if both are scalars; a column if one is a vector; the matrix
        ``{f_a, g_b}`` (shape ``(len(f), len(g))``) if both are vectors.
        Entries are returned unsimplified (use :func:`rsimp`).

    Raises
    ------
    InvalidInputError
        If ``n`` and ``pi`` have different lengths or contain non-symbols.
    """
    sp = sympy_module()
    n = list(n)
    pi = list(pi)
    if len(n) != len(pi) or not n:
        raise InvalidInputError(
            f"poisson_bracket: n and pi must be non-empty and of equal length, got {len(n)} and {len(pi)}"
        )
    if not all(isinstance(x, sp.Symbol) for x in n + pi):
        raise InvalidInputError("poisson_bracket: n and pi must contain sympy Symbols only")

    def pb(a, b):
        return sum(sp.diff(a, q) * sp.diff(b, p) - sp.diff(a, p) * sp.diff(b, q) for q, p in zip(n, pi))

    fm = isinstance(f, sp.MatrixBase)
    gm = isinstance(g, sp.MatrixBase)
    if fm and gm:
        fl, gl = list(f), list(g)
        return sp.Matrix(len(fl), len(gl), lambda a, b: pb(fl[a], gl[b]))
    if fm:
        return sp.Matrix([pb(a, g) for a in f])
    if gm:
        return sp.Matrix([pb(f, b) for b in g])
    return pb(f, g)


# ---------------------------------------------------------------------------
# rotation matrices
# ---------------------------------------------------------------------------


def rotation_from_axis_angle(k, cos_a, sin_a):
    r"""Rotation matrix of the construction before eq. 1.7.

    The image of a point is :math:`x' = Px + Nx\cos\alpha + [k, x]\sin\alpha`
    with the projectors :math:`P = kk^T`, :math:`N = 1 - kk^T` (eq. 1.6);
    the matrix is the Jacobian :math:`R_{ij} = \partial x'_i/\partial x_j`.

    Parameters
    ----------
    k : sympy.Matrix, shape (3, 1)
        Unit rotation axis.
    cos_a, sin_a : sympy.Expr
        :math:`\cos\alpha` and :math:`\sin\alpha`.

    Returns
    -------
    sympy.Matrix, shape (3, 3)
    """
    sp = sympy_module()
    x = sp.Matrix(sp.symbols("x_1:4"))
    P = k * k.T
    N = sp.eye(3) - P
    xp = P * x + N * x * cos_a + cross(k, x) * sin_a
    return xp.jacobian(x).applyfunc(sp.expand)


def rotation_from_quaternion(q0, q):
    r"""Active rotation matrix of a (not necessarily unit) quaternion.

    .. math:: R = \frac{(q_0^2 - q\cdot q)\,1 + 2 q q^T + 2 q_0 [q]_\times}
              {q_0^2 + q\cdot q}, \qquad ([q]_\times)_{ij} = -\epsilon_{ijk} q_k .

    Parameters
    ----------
    q0 : sympy.Expr
        Scalar part.
    q : sympy.Matrix, shape (3, 1)
        Vector part.

    Returns
    -------
    sympy.Matrix, shape (3, 3)
    """
    sp = sympy_module()
    qq = dot(q, q)
    qx = -hat(q)
    return ((q0**2 - qq) * sp.eye(3) + 2 * q * q.T + 2 * q0 * qx) / (q0**2 + qq)


# ---------------------------------------------------------------------------
# the derivation
# ---------------------------------------------------------------------------


# ---------------------------------------------------------------------------
# gcd-free rational functions with denominators over a list of known factors
# ---------------------------------------------------------------------------


class Ctx:
    """Polynomial ring over QQ plus a growing list of denominator factors (private).

    Rational functions are kept as ``num / prod(factor_k ** e_k)``; sums,
    products, derivatives and substitutions need no gcd, only polynomial
    products and exact trial divisions by the known factors
    (``1 + n^2``, ``det I``, ...).  This is what makes the derivation with a
    general inertia tensor fast.
    """

    def __init__(self, symbols, factors=()):
        sp = sympy_module()
        from sympy.polys.rings import ring

        self.symbols = tuple(symbols)
        self.ring = ring(list(self.symbols), sp.QQ)[0]
        self.gens = {s: self.ring.gens[i] for i, s in enumerate(self.symbols)}
        self.index = {s: i for i, s in enumerate(self.symbols)}
        self.factors: list = []
        self._fexpr: list = []
        self._pow: dict = {}
        for f in factors:
            self._add_factor(self.poly(f))

    # -- construction ----------------------------------------------------
    def poly(self, expr):
        """Polynomial (ring element) of a polynomial SymPy expression."""
        r = self.from_expr(expr)
        if r.den:
            raise InvalidInputError(f"expected a polynomial, got {str(expr)[:80]!r}")
        return r.num

    def _add_factor(self, p):
        # normalise: positive leading coefficient, monic over QQ
        p = p.monic()
        for i, f in enumerate(self.factors):
            if f == p:
                return i
        self.factors.append(p)
        self._fexpr.append(None)
        return len(self.factors) - 1

    def fpow(self, i, e):
        key = (i, e)
        v = self._pow.get(key)
        if v is None:
            v = self.factors[i] ** e if e > 1 else (self.factors[i] if e == 1 else self.ring.one)
            self._pow[key] = v
        return v

    def factor_known(self, p):
        """Write ``p = c * prod f_k^e_k`` over the known factors (adding a new one if needed)."""
        if p == 0:
            raise InvalidInputError("division by zero (identically vanishing denominator)")
        exps: dict[int, int] = {}
        for i, f in enumerate(self.factors):
            while not p.is_ground:
                q, r = p.div(f)
                if r:
                    break
                p = q
                exps[i] = exps.get(i, 0) + 1
        if not p.is_ground:
            c = p.LC
            i = self._add_factor(p)
            exps[i] = exps.get(i, 0) + 1
            return c, exps
        return p.LC if p else p.ring.domain.zero, exps

    def const(self, c):
        return self.from_expr(c)

    def gen(self, s):
        return Rat(self, self.gens[s], {})

    def from_expr(self, expr):
        """Convert a rational SymPy expression (recursively, no gcd)."""
        sp = sympy_module()
        expr = sp.sympify(expr)
        if expr.is_Number:
            if not expr.is_Rational:
                raise InvalidInputError(f"only rational numbers are supported, got {expr}")
            return Rat(self, self.ring(sp.QQ(int(expr.p), int(expr.q))), {})
        if expr.is_Symbol:
            if expr not in self.gens:
                raise InvalidInputError(f"symbol {expr} is not a generator of this context")
            return Rat(self, self.gens[expr], {})
        if expr.is_Add:
            acc = None
            for a in expr.args:
                r = self.from_expr(a)
                acc = r if acc is None else acc + r
            return acc
        if expr.is_Mul:
            acc = None
            for a in expr.args:
                r = self.from_expr(a)
                acc = r if acc is None else acc * r
            return acc
        if expr.is_Pow and expr.exp.is_Integer:
            base = self.from_expr(expr.base)
            e = int(expr.exp)
            if e >= 0:
                return base**e
            return (self.const(1) / base) ** (-e)
        raise InvalidInputError(f"not a rational function: {str(expr)[:80]!r}")

    def vec(self, v):
        return [self.from_expr(x) for x in v]

    def mat(self, M):
        return [[self.from_expr(M[i, j]) for j in range(M.cols)] for i in range(M.rows)]

    def factor_expr(self, i):
        if self._fexpr[i] is None:
            self._fexpr[i] = self.factors[i].as_expr()
        return self._fexpr[i]

    def to_matrix(self, X):
        sp = sympy_module()
        if X and isinstance(X[0], list):
            return sp.Matrix(len(X), len(X[0]), lambda i, j: X[i][j].expr())
        return sp.Matrix([x.expr() for x in X])

    def subs(self, f, mapping):
        """Substitute rational functions for generators in ``f`` (a Rat)."""
        if not mapping:
            return f
        R = self.ring
        idxs = [self.index[s] for s in mapping]
        vals = [mapping[s] for s in mapping]
        E: dict[int, int] = {}
        for v in vals:
            for k, e in v.den.items():
                E[k] = max(E.get(k, 0), e)
        P = {}
        for i, v in zip(idxs, vals):
            p = v.num
            for k, e in E.items():
                d = e - v.den.get(k, 0)
                if d:
                    p = p * self.fpow(k, d)
            P[i] = p
        pc = {i: [R.one] for i in idxs}
        qc: dict = {}

        def ppow(i, e):
            c = pc[i]
            while len(c) <= e:
                c.append(c[-1] * P[i])
            return c[e]

        def qpow(e):
            if e not in qc:
                q = R.one
                for k, ek in E.items():
                    q = q * self.fpow(k, ek * e)
                qc[e] = q
            return qc[e]

        def peval(poly):
            groups: dict = {}
            for monom, c in poly.terms():
                key = tuple(monom[i] for i in idxs)
                rest = list(monom)
                for i in idxs:
                    rest[i] = 0
                groups.setdefault(key, []).append((tuple(rest), c))
            d = max((sum(k) for k in groups), default=0)
            acc = R.zero
            for key, terms in groups.items():
                part = R.from_terms(terms)
                for i, e in zip(idxs, key):
                    if e:
                        part = part * ppow(i, e)
                if d - sum(key):
                    part = part * qpow(d - sum(key))
                acc += part
            return acc, d

        N, dN = peval(f.num)
        # the denominator of f is a product of known factors, free of the substituted symbols?
        if any(self.factors[k].degree(i) > 0 for k in f.den for i in idxs):
            D = R.one
            for k, e in f.den.items():
                D = D * self.fpow(k, e)
            Dv, dD = peval(D)
            c, exps = self.factor_known(Dv)
            den = dict(exps)
            for k, ek in E.items():
                den[k] = den.get(k, 0) + ek * dN
            num = N * qpow(dD) * (1 / c) if dD else N * (1 / c)
            return Rat(self, num, {k: e for k, e in den.items() if e}).normalize()
        den = dict(f.den)
        for k, ek in E.items():
            den[k] = den.get(k, 0) + ek * dN
        return Rat(self, N, {k: e for k, e in den.items() if e}).normalize()

    def subs_all(self, X, mapping):
        if X and isinstance(X[0], list):
            return [[self.subs(x, mapping) for x in row] for row in X]
        return [self.subs(x, mapping) for x in X]

    def bracket(self, f, g, n, pi):
        acc = self.const(0)
        for q, p in zip(n, pi):
            acc = acc + f.diff(q) * g.diff(p) - f.diff(p) * g.diff(q)
        return acc.normalize()


class Rat:
    """``num / prod(ctx.factors[k] ** den[k])`` (private; see :class:`Ctx`)."""

    __slots__ = ("ctx", "num", "den")

    def __init__(self, ctx, num, den):
        self.ctx = ctx
        self.num = num
        self.den = den

    def _lift(self, other):
        if isinstance(other, Rat):
            return other
        return self.ctx.from_expr(other)

    def _common(self, other):
        E = dict(self.den)
        for k, e in other.den.items():
            E[k] = max(E.get(k, 0), e)
        a, b = self.num, other.num
        for k, e in E.items():
            da = e - self.den.get(k, 0)
            db = e - other.den.get(k, 0)
            if da:
                a = a * self.ctx.fpow(k, da)
            if db:
                b = b * self.ctx.fpow(k, db)
        return a, b, E

    def __add__(self, other):
        other = self._lift(other)
        if not other.num:
            return self
        if not self.num:
            return other
        a, b, E = self._common(other)
        return Rat(self.ctx, a + b, E)

    __radd__ = __add__

    def __neg__(self):
        return Rat(self.ctx, -self.num, dict(self.den))

    def __sub__(self, other):
        return self + (-self._lift(other))

    def __rsub__(self, other):
        return self._lift(other) - self

    def __mul__(self, other):
        other = self._lift(other)
        if not self.num or not other.num:
            return Rat(self.ctx, self.ctx.ring.zero, {})
        den = dict(self.den)
        for k, e in other.den.items():
            den[k] = den.get(k, 0) + e
        return Rat(self.ctx, self.num * other.num, den)

    __rmul__ = __mul__

    def __truediv__(self, other):
        other = self._lift(other)
        c, exps = self.ctx.factor_known(other.num)
        num = self.num * (1 / c)
        for k, e in other.den.items():
            num = num * self.ctx.fpow(k, e)
        den = dict(self.den)
        for k, e in exps.items():
            den[k] = den.get(k, 0) + e
        return Rat(self.ctx, num, den).normalize()

    def __rtruediv__(self, other):
        return self._lift(other) / self

    def __pow__(self, e):
        if e < 0:
            return (self.ctx.const(1) / self) ** (-e)
        return Rat(self.ctx, self.num**e, {k: v * e for k, v in self.den.items()})

    def __bool__(self):
        return bool(self.num)

    def is_zero(self):
        return not self.num

    def diff(self, sym):
        ctx = self.ctx
        x = ctx.gens[sym]
        i = ctx.index[sym]
        dep = [k for k in self.den if ctx.factors[k].degree(i) > 0]
        if not dep:
            return Rat(ctx, self.num.diff(x), dict(self.den))
        # d(N / prod f^e) = [N' prod_dep f - N sum_k e_k f_k' prod_{j != k} f_j] / (prod f^e * prod_dep f)
        prod_all = ctx.ring.one
        for k in dep:
            prod_all = prod_all * ctx.factors[k]
        num = self.num.diff(x) * prod_all
        for k in dep:
            other = ctx.ring.one
            for j in dep:
                if j != k:
                    other = other * ctx.factors[j]
            num = num - self.num * ctx.factors[k].diff(x) * other * self.den[k]
        den = dict(self.den)
        for k in dep:
            den[k] += 1
        return Rat(ctx, num, den).normalize()

    def normalize(self):
        if not self.num:
            return Rat(self.ctx, self.num, {})
        num = self.num
        den = {}
        for k, e in self.den.items():
            f = self.ctx.factors[k]
            while e > 0:
                q, r = num.div(f)
                if r:
                    break
                num = q
                e -= 1
            if e:
                den[k] = e
        return Rat(self.ctx, num, den)

    def expr(self):
        sp = sympy_module()
        num = self.num.as_expr()
        if not self.den:
            return num
        d = sp.Integer(1)
        for k, e in sorted(self.den.items()):
            d = d * self.ctx.factor_expr(k) ** e
        return num / d

    def __repr__(self):  # pragma: no cover - debugging aid
        return f"Rat({self.expr()})"


def rsum(items, ctx):
    acc = ctx.const(0)
    for x in items:
        acc = acc + x
    return acc


def rmm(X, Y):
    """Product of nested-list Rat matrices (or matrix times vector)."""
    ctx = X[0][0].ctx
    if Y and not isinstance(Y[0], list):
        return [rsum((X[i][k] * Y[k] for k in range(len(Y))), ctx).normalize() for i in range(len(X))]
    return [
        [rsum((X[i][k] * Y[k][j] for k in range(len(Y))), ctx).normalize() for j in range(len(Y[0]))]
        for i in range(len(X))
    ]


def rtr(X):
    return [list(r) for r in zip(*X)]


def rinv3(F):
    """Inverse of a 3x3 Rat matrix (private).

    Writes ``F = P / D`` with a polynomial matrix ``P`` and a common
    denominator ``D`` over the known factors, then
    ``F^{-1} = D adj(P) / det(P)`` with ``det(P)`` split over the known
    factors by trial division: no gcd anywhere.
    """
    ctx = F[0][0].ctx
    E: dict[int, int] = {}
    for row in F:
        for x in row:
            for k, e in x.den.items():
                E[k] = max(E.get(k, 0), e)
    P: list[list[Any]] = [[None] * 3 for _ in range(3)]
    for i in range(3):
        for j in range(3):
            p = F[i][j].num
            for k, e in E.items():
                d = e - F[i][j].den.get(k, 0)
                if d:
                    p = p * ctx.fpow(k, d)
            P[i][j] = p
    det = (
        P[0][0] * (P[1][1] * P[2][2] - P[1][2] * P[2][1])
        - P[0][1] * (P[1][0] * P[2][2] - P[1][2] * P[2][0])
        + P[0][2] * (P[1][0] * P[2][1] - P[1][1] * P[2][0])
    )
    if not det:
        raise InvalidInputError("matrix is singular (det = 0 identically)")
    c, exps = ctx.factor_known(det)
    Dpoly = ctx.ring.one
    for k, e in E.items():
        Dpoly = Dpoly * ctx.fpow(k, e)
    scale = Dpoly * (1 / c)
    out: list[list[Any]] = [[None] * 3 for _ in range(3)]
    for i in range(3):
        for j in range(3):
            r = [a for a in range(3) if a != j]
            cc = [b for b in range(3) if b != i]
            minor = P[r[0]][cc[0]] * P[r[1]][cc[1]] - P[r[0]][cc[1]] * P[r[1]][cc[0]]
            if (i + j) % 2:
                minor = -minor
            out[i][j] = Rat(ctx, minor * scale, dict(exps)).normalize()
    return out


class Derivation:
    r"""The paper's quantities derived from the Lagrangian (eq. 1.10).

    Obtain instances with :func:`derive` (cached).  Every public attribute is
    a lazily computed, cached SymPy object whose denominators are products of
    :math:`1+\mathbf n^2` and :math:`\det I` (computations run on polynomial
    numerators over these known factors, no gcd needed).

    Attributes
    ----------
    n, ndot, nddot : Gibbs vector :math:`\mathbf n = \mathbf k\tan(\alpha/2)`
        and its time derivatives (columns of symbols ``n1..``, ``ndot1..``).
    pi : canonical momenta :math:`\pi_i` (symbols ``pi1..``).
    m_sym, Omega_sym, M_sym : symbols used as coordinates in the
        non-canonical charts :math:`(\mathbf n, \mathbf m)`,
        :math:`(\mathbf n, \boldsymbol\Omega)`, :math:`(\mathbf n, \mathbf M)`.
    I, Iinv, inertia_symbols : the inertia tensor, its inverse
        :math:`\operatorname{adj}(I)/\det I` and its symbols.

    Derived quantities (see each attribute's docstring): ``R``,
    ``Omega_of_velocity``, ``omega_of_velocity``, ``A``, ``Atilde``, ``L``,
    ``G``, ``Ginv``, ``christoffel_first``, ``christoffel_second``,
    ``euler_lagrange``, ``geodesic``, ``momenta``, ``velocity_of_momenta``,
    ``H``, ``ndot_canonical``, ``pidot_canonical``, ``Omega_canonical``,
    ``m_canonical``, ``M_canonical``, ``pi_of_m``, ``pi_of_Omega``,
    ``pi_of_M``, and :meth:`brackets` / :meth:`poisson_tensor` per chart.
    """

    def __init__(self, inertia: str = "general"):
        sp = sympy_module()
        if inertia not in INERTIA_KINDS:
            raise InvalidInputError(f"inertia must be one of {INERTIA_KINDS}, got {inertia!r}")
        self.inertia = inertia
        self.n = sp.Matrix(sp.symbols("n1:4", real=True))
        self.ndot = sp.Matrix(sp.symbols("ndot1:4", real=True))
        self.nddot = sp.Matrix(sp.symbols("nddot1:4", real=True))
        self.pi = sp.Matrix(sp.symbols("pi1:4", real=True))
        self.m_sym = sp.Matrix(sp.symbols("m1:4", real=True))
        self.Omega_sym = sp.Matrix(sp.symbols("Omega1:4", real=True))
        self.M_sym = sp.Matrix(sp.symbols("M1:4", real=True))
        if inertia == "general":
            names = ("I11", "I12", "I13", "I22", "I23", "I33")
            I11, I12, I13, I22, I23, I33 = sp.symbols(names, real=True)
            self.I = sp.Matrix([[I11, I12, I13], [I12, I22, I23], [I13, I23, I33]])
            self.inertia_symbols: tuple[Any, ...] = (I11, I12, I13, I22, I23, I33)
        else:
            I1, I2, I3 = sp.symbols("I1:4", positive=True)
            self.I = sp.diag(I1, I2, I3)
            self.inertia_symbols = (I1, I2, I3)
        self.detI = sp.expand(self.I.det())
        self.nsq = dot(self.n, self.n)
        gens = (
            list(self.n)
            + list(self.ndot)
            + list(self.nddot)
            + list(self.pi)
            + list(self.m_sym)
            + list(self.Omega_sym)
            + list(self.M_sym)
            + list(self.inertia_symbols)
        )
        known = [1 + self.nsq] + ([self.detI] if inertia == "general" else list(self.inertia_symbols))
        self.ctx = Ctx(gens, known)
        C = self.ctx
        self._fI = C.mat(self.I)
        self._fIinv = rinv3(self._fI)
        self.Iinv = C.to_matrix(self._fIinv)
        self._fn, self._fnd, self._fndd, self._fpi = (C.vec(v) for v in (self.n, self.ndot, self.nddot, self.pi))

    def __repr__(self) -> str:
        return f"Derivation(inertia={self.inertia!r})"

    # -- kinematics --------------------------------------------------------
    @cached_property
    def R(self):
        r"""Rotation matrix :math:`R(\mathbf n)` derived from eq. 1.7.

        Substitutes :math:`\mathbf k = \mathbf n/t`, :math:`\cos\alpha =
        (1-t^2)/(1+t^2)`, :math:`\sin\alpha = 2t/(1+t^2)` with
        :math:`t = \tan(\alpha/2) = |\mathbf n|` into
        :func:`rotation_from_axis_angle`.
        """
        return self.ctx.to_matrix(self._fR)

    @cached_property
    def _fR(self):
        sp = sympy_module()
        t = sp.Symbol("t", positive=True)
        Rt = rotation_from_axis_angle(self.n / t, (1 - t**2) / (1 + t**2), 2 * t / (1 + t**2))
        Rt = Rt.applyfunc(lambda e: sp.cancel(e).subs(t, sp.sqrt(self.nsq)))
        return [[self.ctx.from_expr(Rt[i, j]).normalize() for j in range(3)] for i in range(3)]

    def R_dot(self, ndot=None):
        r""":math:`\dot R = \sum_l \partial R/\partial n_l\,\dot n_l` by the chain rule.

        Parameters
        ----------
        ndot : sympy.Matrix, shape (3, 1), optional
            Velocity to use (default: the symbols ``ndot``).

        Returns
        -------
        sympy.Matrix, shape (3, 3)
        """
        if ndot is None:
            return self.ctx.to_matrix(self._fRdot())
        sp = sympy_module()
        return sp.Matrix(3, 3, lambda i, j: sum(sp.diff(self.R[i, j], self.n[l]) * ndot[l] for l in range(3)))

    def _fRdot(self):
        return [
            [
                rsum((self._fR[i][j].diff(self.n[l]) * self._fnd[l] for l in range(3)), self.ctx).normalize()
                for j in range(3)
            ]
            for i in range(3)
        ]

    def _axial(self, W):
        sp = sympy_module()
        half = self.ctx.from_expr(sp.Rational(-1, 2))
        return [
            (
                rsum(
                    (W[i][j] * levi_civita(k, i, j) for i in range(3) for j in range(3) if levi_civita(k, i, j)),
                    self.ctx,
                )
                * half
            ).normalize()
            for k in range(3)
        ]

    @cached_property
    def _fOmega_v(self):
        return self._axial(rmm(rtr(self._fR), self._fRdot()))

    @cached_property
    def Omega_of_velocity(self):
        r"""Body angular velocity :math:`\Omega_k = -\tfrac12\epsilon_{kij}(R^T\dot R)_{ij}` (eq. 1.10)."""
        return self.ctx.to_matrix(self._fOmega_v)

    @cached_property
    def _fomega_v(self):
        return self._axial(rmm(self._fRdot(), rtr(self._fR)))

    @cached_property
    def omega_of_velocity(self):
        r"""Space angular velocity :math:`\omega_k = -\tfrac12\epsilon_{kij}(\dot R R^T)_{ij}`."""
        return self.ctx.to_matrix(self._fomega_v)

    @cached_property
    def _fA(self):
        half = self.ctx.from_expr(sympy_module().Rational(1, 2))
        J = [[self._fOmega_v[i].diff(self.ndot[j]) for j in range(3)] for i in range(3)]
        return [[J[j][i] * half for j in range(3)] for i in range(3)]

    @cached_property
    def A(self):
        r"""Conversion matrix :math:`A = \tfrac12(\partial\boldsymbol\Omega/\partial\dot{\mathbf n})^T`, so :math:`\boldsymbol\Omega = 2A^T\dot{\mathbf n}`."""
        return self.ctx.to_matrix(self._fA)

    @cached_property
    def _fAtilde(self):
        return rinv3(self._fA)

    @cached_property
    def Atilde(self):
        r""":math:`\tilde A = A^{-1}` (exact inverse)."""
        return self.ctx.to_matrix(self._fAtilde)

    # -- Lagrangian --------------------------------------------------------
    @cached_property
    def _fL(self):
        half = self.ctx.from_expr(sympy_module().Rational(1, 2))
        Om = self._fOmega_v
        return (rsum((self._fI[i][j] * Om[i] * Om[j] for i in range(3) for j in range(3)), self.ctx) * half).normalize()

    @cached_property
    def L(self):
        r"""Kinetic Lagrangian :math:`L = \tfrac12 I_{ij}\Omega_i\Omega_j` (eq. 1.10)."""
        return self._fL.expr()

    @cached_property
    def _fmomenta(self):
        return [self._fL.diff(x) for x in self.ndot]

    @cached_property
    def momenta(self):
        r"""Canonical momenta :math:`\pi_i = \partial L/\partial\dot n_i` as functions of :math:`(\mathbf n, \dot{\mathbf n})`."""
        return self.ctx.to_matrix(self._fmomenta)

    @cached_property
    def _fG(self):
        return [[self._fmomenta[i].diff(self.ndot[j]) for j in range(3)] for i in range(3)]

    @cached_property
    def G(self):
        r"""Metric :math:`G_{ij} = \partial^2L/\partial\dot n_i\partial\dot n_j` (eq. 1.13)."""
        return self.ctx.to_matrix(self._fG)

    @cached_property
    def _fGinv(self):
        return rinv3(self._fG)

    @cached_property
    def Ginv(self):
        r"""Inverse metric :math:`G^{-1} = \operatorname{adj}G/\det G`."""
        return self.ctx.to_matrix(self._fGinv)

    @cached_property
    def _fdG(self):
        return [[[self._fG[i][j].diff(self.n[k]) for j in range(3)] for i in range(3)] for k in range(3)]

    @cached_property
    def _fchristoffel_first(self):
        half = self.ctx.from_expr(sympy_module().Rational(1, 2))
        dG = self._fdG
        return [
            [[((dG[j][i][k] + dG[k][i][j] - dG[i][j][k]) * half).normalize() for k in range(3)] for j in range(3)]
            for i in range(3)
        ]

    @cached_property
    def christoffel_first(self):
        r""":math:`\Gamma_{ijk} = \tfrac12(\partial_jG_{ik} + \partial_kG_{ij} - \partial_iG_{jk})`, nested lists ``[i][j][k]``."""
        return [[[x.expr() for x in row] for row in mat] for mat in self._fchristoffel_first]

    @cached_property
    def _fchristoffel_second(self):
        G1 = self._fchristoffel_first
        Gi = self._fGinv
        return [
            [
                [rsum((Gi[i][l] * G1[l][j][k] for l in range(3)), self.ctx).normalize() for k in range(3)]
                for j in range(3)
            ]
            for i in range(3)
        ]

    @cached_property
    def christoffel_second(self):
        r""":math:`\Gamma^i{}_{jk} = G^{-1}_{il}\Gamma_{ljk}`, nested lists ``[i][j][k]``."""
        return [[[x.expr() for x in row] for row in mat] for mat in self._fchristoffel_second]

    @cached_property
    def _feuler_lagrange(self):
        out = []
        for i in range(3):
            p_i = self._fmomenta[i]
            dt = rsum(
                (p_i.diff(self.n[j]) * self._fnd[j] + p_i.diff(self.ndot[j]) * self._fndd[j] for j in range(3)),
                self.ctx,
            )
            out.append((dt - self._fL.diff(self.n[i])).normalize())
        return out

    @cached_property
    def euler_lagrange(self):
        r"""Euler-Lagrange expressions :math:`\frac{d}{dt}\partial L/\partial\dot n_i - \partial L/\partial n_i`.

        Linear in ``nddot``; computed directly from :math:`L` by the chain rule.
        """
        return self.ctx.to_matrix(self._feuler_lagrange)

    @cached_property
    def _fgeodesic(self):
        G2 = self._fchristoffel_second
        nd = self._fnd
        return [
            (
                self._fndd[i] + rsum((G2[i][j][k] * nd[j] * nd[k] for j in range(3) for k in range(3)), self.ctx)
            ).normalize()
            for i in range(3)
        ]

    @cached_property
    def geodesic(self):
        r"""Geodesic equations :math:`\ddot n^i + \Gamma^i{}_{jk}\dot n^j\dot n^k` (to be set to zero)."""
        return self.ctx.to_matrix(self._fgeodesic)

    @cached_property
    def _fvelocity(self):
        # pi = dL/dndot = G ndot (L is quadratic in ndot), solved with the exact inverse
        return rmm(self._fGinv, self._fpi)

    @cached_property
    def velocity_of_momenta(self):
        r""":math:`\dot{\mathbf n}(\mathbf n, \boldsymbol\pi)`, the solution of :math:`\boldsymbol\pi = \partial L/\partial\dot{\mathbf n}`."""
        return self.ctx.to_matrix(self._fvelocity)

    # -- Hamiltonian -------------------------------------------------------
    @cached_property
    def euler_homogeneity(self):
        r""":math:`\dot n_i\,\partial L/\partial\dot n_i - 2L` (zero: :math:`L` is quadratic in :math:`\dot{\mathbf n}`)."""
        return (rsum((self._fnd[i] * self._fmomenta[i] for i in range(3)), self.ctx) - self._fL * 2).normalize().expr()

    @cached_property
    def _fH(self):
        # Legendre transform H = pi.v - L(v) at the velocity v(n, pi) solving pi = dL/dndot.
        # L is homogeneous of degree 2 in ndot (see euler_homogeneity), so L(v) = v.pi(v)/2 = v.pi/2.
        v = self._fvelocity
        half = self.ctx.from_expr(sympy_module().Rational(1, 2))
        return (rsum((self._fpi[i] * v[i] for i in range(3)), self.ctx) * half).normalize()

    @cached_property
    def H(self):
        r"""Hamiltonian by Legendre transform :math:`H = \pi_i\dot n_i - L` at :math:`\dot{\mathbf n}(\mathbf n, \boldsymbol\pi)`.

        Since :math:`L` is homogeneous of degree two in :math:`\dot{\mathbf n}`
        (Euler's theorem, checked by :attr:`euler_homogeneity`),
        :math:`H = \tfrac12\pi_i\dot n_i(\mathbf n, \boldsymbol\pi)`.
        """
        return self._fH.expr()

    def bracket(self, f, g):
        """Canonical bracket of SymPy expressions/vectors (see :func:`poisson_bracket`)."""
        return poisson_bracket(f, g, self.n, self.pi)

    def _fbracket(self, f, g):
        return self.ctx.bracket(f, g, self.n, self.pi)

    @cached_property
    def _fndot_c(self):
        return [self._fbracket(x, self._fH) for x in self._fn]

    @cached_property
    def ndot_canonical(self):
        r"""Hamilton's equation :math:`\dot n_i = \{n_i, H\}`."""
        return self.ctx.to_matrix(self._fndot_c)

    @cached_property
    def _fpidot_c(self):
        return [self._fbracket(x, self._fH) for x in self._fpi]

    @cached_property
    def pidot_canonical(self):
        r"""Hamilton's equation :math:`\dot\pi_i = \{\pi_i, H\}`."""
        return self.ctx.to_matrix(self._fpidot_c)

    @cached_property
    def _fOmega_c(self):
        return self.ctx.subs_all(self._fOmega_v, dict(zip(self.ndot, self._fndot_c)))

    @cached_property
    def Omega_canonical(self):
        r""":math:`\boldsymbol\Omega(\mathbf n, \boldsymbol\pi)`: eq. 1.10's :math:`\boldsymbol\Omega` at :math:`\dot{\mathbf n} = \{\mathbf n, H\}`."""
        return self.ctx.to_matrix(self._fOmega_c)

    @cached_property
    def _fM_c(self):
        return rmm(self._fI, self._fOmega_c)

    @cached_property
    def M_canonical(self):
        r"""Body angular momentum :math:`\mathbf M = I\boldsymbol\Omega` in canonical variables."""
        return self.ctx.to_matrix(self._fM_c)

    @cached_property
    def _fm_c(self):
        return rmm(self._fR, self._fM_c)

    @cached_property
    def m_canonical(self):
        r"""Space angular momentum :math:`\mathbf m = RI\boldsymbol\Omega` in canonical variables."""
        return self.ctx.to_matrix(self._fm_c)

    def _solve_linear_in_pi(self, fexpr, target):
        J = [[fexpr[i].diff(p) for p in self.pi] for i in range(3)]
        return rmm(rinv3(J), self.ctx.vec(target))

    @cached_property
    def _fpi_of(self):
        return {
            "nm": self._solve_linear_in_pi(self._fm_c, self.m_sym),
            "nOmega": self._solve_linear_in_pi(self._fOmega_c, self.Omega_sym),
            "nM": self._solve_linear_in_pi(self._fM_c, self.M_sym),
        }

    @cached_property
    def pi_of_m(self):
        r""":math:`\boldsymbol\pi(\mathbf n, \mathbf m)`, inverse of :math:`\mathbf m(\mathbf n, \boldsymbol\pi)`."""
        return self.ctx.to_matrix(self._fpi_of["nm"])

    @cached_property
    def pi_of_Omega(self):
        r""":math:`\boldsymbol\pi(\mathbf n, \boldsymbol\Omega)`, inverse of :math:`\boldsymbol\Omega(\mathbf n, \boldsymbol\pi)`."""
        return self.ctx.to_matrix(self._fpi_of["nOmega"])

    @cached_property
    def pi_of_M(self):
        r""":math:`\boldsymbol\pi(\mathbf n, \mathbf M)`, inverse of :math:`\mathbf M(\mathbf n, \boldsymbol\pi)`."""
        return self.ctx.to_matrix(self._fpi_of["nM"])

    def _chart(self, fexpr, chart: str):
        if chart == "canonical":
            return fexpr
        if chart not in ("nm", "nOmega", "nM"):
            raise InvalidInputError(f"chart must be one of 'canonical', 'nm', 'nOmega', 'nM', got {chart!r}")
        mapping = dict(zip(self.pi, self._fpi_of[chart]))
        if isinstance(fexpr, list):
            return self.ctx.subs_all(fexpr, mapping)
        return self.ctx.subs(fexpr, mapping)

    def to_chart(self, expr, chart: str):
        r"""Rewrite a SymPy function of :math:`(\mathbf n, \boldsymbol\pi)` in another chart.

        Parameters
        ----------
        expr : sympy.Expr or sympy.Matrix
            Rational in the derivation's symbols.
        chart : {"canonical", "nm", "nOmega", "nM"}
            Target variables :math:`(\mathbf n, \boldsymbol\pi)`,
            :math:`(\mathbf n, \mathbf m)`, :math:`(\mathbf n, \boldsymbol\Omega)`
            or :math:`(\mathbf n, \mathbf M)`.

        Returns
        -------
        Same type as ``expr``.

        Raises
        ------
        InvalidInputError
            For an unknown chart.
        """
        sp = sympy_module()
        C = self.ctx
        if isinstance(expr, sp.MatrixBase):
            return C.to_matrix(self._chart(C.mat(expr), chart))
        return self._chart(C.from_expr(expr), chart).expr()

    @cached_property
    def _fbr(self):
        out = {}
        for chart, coord in (("nm", self._fm_c), ("nOmega", self._fOmega_c), ("nM", self._fM_c)):
            nX = [[self._fbracket(a, b) for b in coord] for a in self._fn]
            XX: list[list[Any]] = [[None] * 3 for _ in range(3)]
            for i in range(3):
                XX[i][i] = self.ctx.const(0)
                for j in range(i + 1, 3):
                    XX[i][j] = self._fbracket(coord[i], coord[j])
                    XX[j][i] = -XX[i][j]
            out[chart] = (nX, XX)
        return out

    def _fbrackets_chart(self, chart):
        nX, XX = self._fbr[chart]
        return self._chart(nX, chart), self._chart(XX, chart)

    @functools.cache  # noqa: B019 - one instance per inertia case, kept for the process by derive()'s own cache
    def brackets(self, chart: str):
        r"""(``{n_i, X_j}``, ``{X_i, X_j}``) as SymPy matrices in the chart ``"nm"``, ``"nOmega"`` or ``"nM"``.

        ``X`` is :math:`\mathbf m`, :math:`\boldsymbol\Omega` or :math:`\mathbf M`;
        the brackets are computed with the canonical bracket in
        :math:`(\mathbf n, \boldsymbol\pi)` and then rewritten in the chart.
        :math:`\{n_i, n_j\} = 0` in every chart.

        Raises
        ------
        InvalidInputError
            For an unknown chart.
        """
        if chart not in ("nm", "nOmega", "nM"):
            raise InvalidInputError(f"chart must be one of 'nm', 'nOmega', 'nM', got {chart!r}")
        B, C = self._fbrackets_chart(chart)
        return self.ctx.to_matrix(B), self.ctx.to_matrix(C)

    _QUANTITIES = ("H", "ndot", "pidot", "pi", "Omega", "m", "M", "omega", "Omegadot", "mdot", "Mdot")

    def _fquantity(self, name):
        if name == "H":
            return self._fH
        if name == "ndot":
            return self._fndot_c
        if name == "pidot":
            return self._fpidot_c
        if name == "pi":
            return self._fpi
        if name == "Omega":
            return self._fOmega_c
        if name == "m":
            return self._fm_c
        if name == "M":
            return self._fM_c
        if name == "omega":
            return self.ctx.subs_all(self._fomega_v, dict(zip(self.ndot, self._fndot_c)))
        if name in ("Omegadot", "mdot", "Mdot"):
            base = {"Omegadot": self._fOmega_c, "mdot": self._fm_c, "Mdot": self._fM_c}[name]
            return [self._fbracket(x, self._fH) for x in base]
        raise InvalidInputError(f"quantity name must be one of {self._QUANTITIES}, got {name!r}")

    @functools.cache  # noqa: B019 - one instance per inertia case, kept for the process by derive()'s own cache
    def quantity(self, name: str, chart: str = "canonical"):
        r"""A phase-space quantity as a function of the chart's variables.

        Parameters
        ----------
        name : {"H", "ndot", "pidot", "pi", "Omega", "m", "M", "omega", "Omegadot", "mdot", "Mdot"}
            :math:`H`, Hamilton's :math:`\dot{\mathbf n}, \dot{\boldsymbol\pi}`,
            :math:`\boldsymbol\pi`, :math:`\boldsymbol\Omega`, :math:`\mathbf m = RI\boldsymbol\Omega`,
            :math:`\mathbf M = I\boldsymbol\Omega`, the space angular velocity
            :math:`\boldsymbol\omega`, and the time derivatives
            :math:`\{X, H\}` of :math:`\boldsymbol\Omega, \mathbf m, \mathbf M`.
        chart : {"canonical", "nm", "nOmega", "nM"}

        Returns
        -------
        sympy.Expr (for ``"H"``) or sympy.Matrix, shape (3, 1)

        Raises
        ------
        InvalidInputError
            Unknown name or chart.
        """
        f = self._chart(self._fquantity(name), chart)
        if isinstance(f, list):
            return self.ctx.to_matrix(f)
        return f.expr()

    def poisson_tensor(self, chart: str):
        r"""The 6x6 Poisson tensor of the chart ``"canonical"``, ``"nm"``, ``"nOmega"`` or ``"nM"``.

        Blocks :math:`\{n_i, n_j\} = 0`, :math:`\{n_i, X_j\}`,
        :math:`\{X_i, n_j\}`, :math:`\{X_i, X_j\}`, all computed from the
        canonical bracket.

        Raises
        ------
        InvalidInputError
            For an unknown chart.
        """
        sp = sympy_module()
        Z = sp.zeros(3, 3)
        if chart == "canonical":
            return sp.BlockMatrix([[Z, sp.eye(3)], [-sp.eye(3), Z]]).as_explicit()
        B, C = self.brackets(chart)
        return sp.BlockMatrix([[Z, B], [-B.T, C]]).as_explicit()


@functools.cache
def derive(inertia: str = "general") -> Derivation:
    r"""The (cached) derivation of the paper's quantities.

    Parameters
    ----------
    inertia : {"general", "diagonal"}
        General symmetric inertia tensor (six symbols) or principal axes
        ``diag(I1, I2, I3)``.

    Returns
    -------
    Derivation
        Lazily evaluated; each attribute is computed once.

    Raises
    ------
    InvalidInputError
        If ``inertia`` is not one of :data:`INERTIA_KINDS`.

    Examples
    --------
    >>> from eulerpoisson.paper.symbolic import derive
    >>> d = derive("diagonal")
    >>> d.Atilde[0, 1]
    n1*n2 + n3
    """
    return Derivation(inertia)


# ---------------------------------------------------------------------------
# Lie series (eq. 1.23.1)
# ---------------------------------------------------------------------------


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
