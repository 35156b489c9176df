r"""Comparison and display of printed and derived values in the paper audit (part of :mod:`.audit`).

:func:`compare` decides whether a printed value equals the derived one,
exactly (numerators over the known denominators) and at
:data:`N_POINTS` random rational points (:func:`random_point`); a
disagreement of the two verdicts is an :class:`AuditError`. The display
helpers (:func:`latex_of`, :func:`display_values`, :func:`short_difference`)
write values and differences for the report.

Examples
--------
>>> N_POINTS
4
"""

from __future__ import annotations

from dataclasses import dataclass, field

from ..errors import AuditError, InvalidInputError
from . import symbolic as _sym
from .audit_language import T3 as _T3
from .audit_language import as_object as _as_object
from .audit_language import flatten as _flatten
from .audit_language import resolve as _resolve
from .symbolic import sympy_module as _sp

__all__ = [
    "AuditError",
    "N_POINTS",
    "prepare",
    "random_point",
    "compare",
    "latex_of",
    "display_values",
    "display_object",
    "safe_text",
    "constant_ratio",
    "short_difference",
]

#: Random points per comparison.
N_POINTS = 4

_DISPLAY_LIMIT = 2500


# ---------------------------------------------------------------------------
# comparison engine
# ---------------------------------------------------------------------------


def prepare(expr, ns):
    """Rationalise trigonometric functions of alpha (alpha = 2 atan(tau))."""
    sp = _sp()
    if "alpha" in ns and isinstance(expr, sp.Basic) and expr.has(ns["alpha"]):
        tau = sp.Symbol("tau", real=True)
        expr = sp.expand_trig(expr.xreplace({ns["alpha"]: 2 * sp.atan(tau)}))
    return expr


def random_point(syms, rng, evaluator=None, tries=25):
    """A random rational point of ``syms`` where ``evaluator`` (if given) is finite."""
    sp = _sp()
    for _ in range(tries):
        pt = {s: sp.Rational(rng.randint(-7, 7), rng.randint(1, 5)) for s in syms}
        if evaluator is None:
            return pt
        try:
            v = evaluator(pt)
        except ZeroDivisionError:
            continue
        vals = _flatten(v) if not isinstance(v, sp.Basic) or isinstance(v, sp.MatrixBase) else [v]
        if any(x.has(sp.zoo, sp.nan, sp.oo, -sp.oo) for x in vals if isinstance(x, sp.Basic)):
            continue
        return pt
    raise AuditError("could not find a regular random point")


def _numeric_value(x, pt):
    """Exact value at a point (rational), or a 50-digit float for non-rational expressions."""
    sp = _sp()
    v = x.xreplace(pt)
    if v.is_Rational or v.has(sp.zoo, sp.nan):
        return v
    v = sp.nsimplify(v) if v.is_number and not v.free_symbols else v
    if v.is_Rational:
        return v
    return sp.N(v, 50)


@dataclass
class _Cmp:
    equal: bool
    method: str
    witness: dict | None = None
    differing: list = field(default_factory=list)


def compare(p_list, d_list, ns, rng, symbolic=True) -> _Cmp:
    """Compare printed and derived components, exactly and at random points."""
    sp = _sp()
    if len(p_list) != len(d_list):
        raise AuditError(f"shape mismatch: {len(p_list)} printed vs {len(d_list)} derived components")
    diffs = [prepare(sp.sympify(_resolve(p)) - sp.sympify(_resolve(d)), ns) for p, d in zip(p_list, d_list)]
    methods = []
    exact = None
    if symbolic:
        try:
            zeros = [_sym.is_zero(x) for x in diffs]
            exact = all(zeros)
            methods.append("simplify")
        except InvalidInputError:
            exact = None
            try:
                zeros = [sp.simplify(x) == 0 for x in diffs]
                exact = all(zeros)
                methods.append("simplify")
            except Exception:  # pragma: no cover - defensive
                exact = None
    free = set()
    for x in diffs:
        free |= x.free_symbols
    syms = sorted(free, key=lambda s: s.name)
    numeric_equal = True
    witness = None
    differing = []

    for _ in range(ns.get("_points", N_POINTS)):
        vals = None
        for _try in range(25):
            pt = random_point(syms, rng)
            vals = [_numeric_value(x, pt) for x in diffs]
            if not any(v.has(sp.zoo, sp.nan, sp.oo, -sp.oo) for v in vals):
                break
        else:
            raise AuditError("could not find a regular random point")
        bad = [i for i, v in enumerate(vals) if (v != 0 if v.is_Rational else abs(v) > sp.Float(10) ** -35)]
        if bad:
            numeric_equal = False
            if witness is None:
                witness = {str(k): str(v) for k, v in pt.items()}
                differing = bad
    methods.append("random-points")
    if exact is not None and exact != numeric_equal:
        raise AuditError("exact and random-point comparisons disagree")
    if not numeric_equal and exact is None:
        exact = False
    equal = numeric_equal if exact is None else exact
    if not equal and not differing:
        differing = [i for i, x in enumerate(diffs) if not _sym.is_zero(x)]
    return _Cmp(equal=equal, method="+".join(methods), witness=witness, differing=differing)


def latex_of(x) -> str:
    """LaTeX of a value (a :class:`~eulerpoisson.paper.audit_language.T3` as a 9x3 matrix)."""
    sp = _sp()
    x = _resolve(x)
    if isinstance(x, _T3):
        x = sp.Matrix(9, 3, _flatten(x))
    return sp.latex(x)


def _size(v) -> int:
    sp = _sp()
    if not isinstance(v, sp.Basic):
        return 1
    return sum(len(sp.Add.make_args(x)) for x in (sp.numer(v), sp.denom(v))) if v.is_Mul or v.is_Add or v.is_Pow else 1


def display_values(values: list, index: str, D) -> str:
    """LaTeX of a derived tensor; large general-inertia expressions shown for diagonal I."""
    sp = _sp()
    small = sum(_size(v) for v in values) <= 400
    if small:
        obj = _as_object([_sym.rsimp(v) if _is_rational(v) else v for v in values], index)
        s = latex_of(obj)
        if len(s) <= _DISPLAY_LIMIT:
            return s
    if D.inertia == "general":
        rep = _diag_rep(D)
        vals = [_sym.rsimp(v.xreplace(rep)) if _is_rational(v) else v for v in values]
        s2 = latex_of(_as_object(vals, index))
        if len(s2) <= _DISPLAY_LIMIT:
            return s2 + r"\quad\text{(shown for } I=\mathrm{diag}(I_1,I_2,I_3)\text{; checked for general } I)"
        values = vals
    first = values[0]
    s3 = latex_of(first)
    if len(s3) > _DISPLAY_LIMIT:
        n_terms = len(sp.Add.make_args(sp.numer(sp.together(first))))
        return rf"\text{{[component 1: rational expression, {n_terms} terms in the numerator]}}"
    return s3 + r"\quad\text{(component 1 of " + str(len(values)) + ")}"


def display_object(obj, D) -> str:
    """LaTeX of a scalar or matrix of any shape, shortened like :func:`display_values`."""
    sp = _sp()
    if isinstance(obj, sp.MatrixBase):
        vals = list(obj)
        small = sum(_size(v) for v in vals) <= 400
        if small:
            s = latex_of(obj.applyfunc(lambda v: _sym.rsimp(v) if _is_rational(v) else v))
            if len(s) <= _DISPLAY_LIMIT:
                return s
        if D.inertia == "general":
            rep = _diag_rep(D)
            M2 = obj.applyfunc(lambda v: _sym.rsimp(v.xreplace(rep)) if _is_rational(v) else v)
            s2 = latex_of(M2)
            if len(s2) <= 2 * _DISPLAY_LIMIT:
                return s2 + r"\quad\text{(shown for } I=\mathrm{diag}(I_1,I_2,I_3)\text{; computed for general } I)"
        return r"\text{[" + f"{obj.rows}x{obj.cols} matrix, too large to display" + "]}"
    return display_values([obj], "", D)


def _diag_rep(D):
    sp = _sp()
    I11, I12, I13, I22, I23, I33 = D.inertia_symbols
    I1, I2, I3 = sp.symbols("I1:4", positive=True)
    return {I12: 0, I13: 0, I23: 0, I11: I1, I22: I2, I33: I3}


def safe_text(s: str, limit: int = 200) -> str:
    """Text safe inside \\text{} for both LaTeX and MathJax."""
    keep = set("abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789 .,:;()[]=+-*/'<>")
    s = s.replace("^", "**")
    out = "".join(c if c in keep else " " for c in s)
    out = " ".join(out.split())
    if len(out) > limit:
        out = out[: limit - 3] + "..."
    return out


def _is_rational(v) -> bool:
    sp = _sp()
    if not isinstance(v, sp.Basic):
        return False
    return not v.has(sp.sin, sp.cos, sp.tan, sp.atan, sp.sqrt) and not any(
        isinstance(a, sp.Pow) and not a.exp.is_Integer for a in sp.preorder_traversal(v)
    )


def constant_ratio(side_vals, d_vals, refs):
    """If every failing printed side is a constant multiple of the derived value, return it."""
    sp = _sp()
    ratio = None
    for _i, vals, ref in refs:
        for p, d in zip(vals, ref):
            try:
                if _sym.is_zero(d):
                    if not _sym.is_zero(p):
                        return None
                    continue
                r = _sym.rsimp(sp.sympify(p) / sp.sympify(d))
            except (InvalidInputError, ZeroDivisionError):
                return None
            if not r.is_Number:
                return None
            if ratio is None:
                ratio = r
            elif r != ratio:
                return None
    return ratio if ratio is not None and ratio != 1 else None


def short_difference(dv, D) -> str:
    """LaTeX of a difference: factored, and for diagonal inertia if too long."""
    sp = _sp()
    try:
        dv = _sym.rsimp(dv)
        rational = True
    except InvalidInputError:
        dv = sp.simplify(dv)
        rational = False
    cands = [dv]
    if rational and D.inertia == "general" and dv.free_symbols & set(D.inertia_symbols):
        cands.append(None)
    out = None
    for _i, c in enumerate(cands):
        if c is None:
            c = _sym.rsimp(dv.xreplace(_diag_rep(D)))
            suffix = r"\ \text{(for } I=\mathrm{diag}(I_1,I_2,I_3))"
        else:
            suffix = ""
        if _size(c) < 800:
            c = sp.factor(c)
        txt = sp.latex(c) + suffix
        if len(txt) <= 1200:
            return txt
        out = out or txt
    return r"\text{nonzero rational function (" + str(len(sp.Add.make_args(sp.numer(sp.together(dv))))) + " terms)}"


#: names whose canonical-frame values were derived through H (hence with the inertia tensor)
