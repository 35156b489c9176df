r"""Rational functions without gcd computations (part of :mod:`.symbolic`).

Rational expressions are handled as expanded polynomial numerators over
denominators that are products of known factors (:math:`1+\mathbf n^2`,
:math:`\det I`, ...): sums, products, derivatives and substitutions need no
gcd, common factors are removed by exact trial division, and a rational
function is zero exactly when its numerator is (:func:`rsimp`,
:func:`is_zero`). :class:`Ctx` is the ring with its list of factors,
:class:`Rat` one rational function, :func:`rsum`, :func:`rmm`, :func:`rtr`,
:func:`rinv3` the matrix operations on them. Every name is re-exported by
:mod:`eulerpoisson.paper.symbolic`.

Examples
--------
>>> sp = sympy_module()
>>> x = sp.Symbol("x")
>>> is_zero(1 / (1 + x**2) - 1 / (1 + x**2))
True
"""

from __future__ import annotations

from typing import Any

from ..errors import InvalidInputError
from .symbolic_tensors import sympy_module

__all__ = [
    "Ctx",
    "Rat",
    "rsum",
    "rmm",
    "rtr",
    "rinv3",
    "rsimp",
    "rsimp_matrix",
    "is_zero",
    "inverse3",
]

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
    """The sum of the :class:`Rat` ``items`` (0 of ``ctx`` when empty)."""
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
    """The trace of a 3x3 matrix of :class:`Rat`."""
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
