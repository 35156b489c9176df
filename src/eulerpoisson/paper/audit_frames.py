r"""The frames in which the paper audit evaluates the transcriptions (part of :mod:`.audit`).

A :class:`Session` builds, once per audit, the namespace of every frame
(``plain``, ``velocity``, ``canonical``, the non-canonical charts...; see
:mod:`eulerpoisson.paper.audit`) from the derivation of
:mod:`eulerpoisson.paper.symbolic`; :func:`derived_value` computes the
quantity a check compares with, and :func:`integrability_summary` the
brackets of the integrals.

Examples
--------
>>> Session  # doctest: +ELLIPSIS
<class 'eulerpoisson.paper.audit_frames.Session'>
"""

from __future__ import annotations

import random
from typing import Any

from ..errors import InvalidInputError
from . import symbolic as _sym
from .audit_compare import N_POINTS
from .audit_compare import latex_of as _latex
from .audit_compare import random_point as _random_point
from .audit_language import flatten as _flatten
from .audit_language import resolve as _resolve
from .audit_lie import check_lie_exact as _lie_exact_check
from .audit_lie import check_lie_numeric as _lie_numeric_check
from .audit_lie import check_lie_symbolic as _lie_symbolic_check
from .symbolic import sympy_module as _sp

__all__ = [
    "Session",
    "derived_value",
    "integrability_summary",
]

# ---------------------------------------------------------------------------
# frames
# ---------------------------------------------------------------------------


def _unit_vector(a, b):
    sp = _sp()
    d = 1 + a**2 + b**2
    return sp.Matrix([2 * a / d, 2 * b / d, (1 - a**2 - b**2) / d])


def _crossmat(v):
    """[v]_x, with [v]_x w = v x w."""
    return -_sym.hat(v)


class Session:
    """Caches frames and derived quantities for one audit run (private)."""

    def __init__(self, seed: int = 20240607, points: int = N_POINTS):
        self.seed = seed
        self.points = points
        self._ns: dict = {}
        self.integrability: dict = {}
        self.log: list = []

    def derivation(self, inertia):
        return _sym.derive(inertia)

    # -- namespace -------------------------------------------------------
    def namespace(self, frame: str, inertia: str) -> dict:
        key = (frame, inertia)
        if key not in self._ns:
            self._ns[key] = self._build(frame, inertia)
        ns = dict(self._ns[key])
        self.log = []
        ns["_log"] = self.log
        return ns

    def _build(self, frame, inertia):
        sp = _sp()
        D = self.derivation(inertia)
        n = D.n
        ns: dict[str, Any] = {
            "Integer": sp.Integer,
            "Rational": sp.Rational,
            "Float": sp.Float,
            "Matrix": sp.Matrix,
            "sum": sum,
            "range": range,
            "R3": range(3),
            "delta": lambda i, j: 1 if int(i) == int(j) else 0,
            "eps": lambda i, j, k: _sym.levi_civita(int(i), int(j), int(k)),
            "dot": _sym.dot,
            "cross": _sym.cross,
            "hat": _sym.hat,
            "nhat": lambda i, j: sum(_sym.levi_civita(int(i), int(j), p) * n[p] for p in range(3)),
            "one": sp.eye(3),
            "sin": sp.sin,
            "cos": sp.cos,
            "tan": sp.tan,
            "limit": sp.limit,
            "oo": sp.oo,
            "PI": sp.pi,
            "Rquat": _sym.rotation_from_quaternion,
            "det": _det3,
            "n": n,
            "I": D.I,
            "Iinv": D.Iinv,
            "A": D.A,
            "At": D.Atilde,
            "R": D.R,
            "G": D.G,
            "Ginv": D.Ginv,
            "__builtins__": {"True": True, "False": False, "int": int, "abs": abs, "len": len},
        }
        ns["at_origin"] = lambda e: e.xreplace({x: 0 for x in n}) if hasattr(e, "xreplace") else e
        self._claim_helpers(ns, D, frame)
        if frame == "plain":
            pass
        elif frame == "particles":
            ys = {N: sp.Matrix(sp.symbols(f"y{N}_1:4", real=True)) for N in range(1, 5)}
            ns["y"] = lambda N: ys[int(N)]
            ns["lam"] = lambda A_, N: sp.Symbol(f"lambda_{int(A_)}{int(N)}", real=True)
            ns["a"] = lambda A_, N: sp.Symbol(f"a_{int(A_)}{int(N)}", real=True)
            ns["total_force"] = lambda e: sp.Matrix([sum(sp.diff(e, ys[N][c]) for N in ys) for c in range(3)])
        elif frame == "rigid":
            ns["C0"] = sp.Matrix(sp.symbols("C0_1:4", real=True))
            ns["V0"] = sp.Matrix(sp.symbols("V0_1:4", real=True))
            ns["t"] = sp.Symbol("t", real=True)
            xs = {N: sp.Matrix(sp.symbols(f"x{N}_1:4", real=True)) for N in range(1, 4)}
            ns["x"] = lambda N: xs[int(N)]
            ns["mass"] = lambda N: sp.Symbol(f"m_{int(N)}", positive=True)
            ns["g"] = _sym_matrix("g")
            ns["Omega"] = D.Omega_sym
            ns["Rdot"] = D.R * _crossmat(D.Omega_sym)
        elif frame == "kinematic":
            ns["Omega"] = D.Omega_sym
        elif frame == "velocity":
            ns["ndot"] = D.ndot
            ns["nddot"] = D.nddot
            ns["Omega"] = D.Omega_of_velocity
            ns["omega"] = D.omega_of_velocity
            ns["Rdot"] = D.R_dot()
            ns["g"] = _sym_matrix("g")
            ns["EL"] = D.euler_lagrange
            ns["Gamma2"] = lambda l, j, k: D.christoffel_second[int(l)][int(j)][int(k)]

            def ddt(e):
                return sum(sp.diff(e, D.n[j]) * D.ndot[j] + sp.diff(e, D.ndot[j]) * D.nddot[j] for j in range(3))

            def on_shell(e):
                G2 = D.christoffel_second
                rep = {
                    D.nddot[i]: -sum(G2[i][j][k] * D.ndot[j] * D.ndot[k] for j in range(3) for k in range(3))
                    for i in range(3)
                }
                return e.xreplace(rep)

            ns["ddt"] = ddt
            ns["on_shell"] = on_shell
        elif frame in ("canonical", "nm", "nOmega", "nM"):
            chart = frame
            own = {"nm": "m", "nOmega": "Omega", "nM": "M"}.get(chart)
            for name in ("H", "ndot", "Omega", "m", "M", "omega", "Omegadot", "mdot", "Mdot", "pi"):
                if name != own:
                    ns[name] = D.quantity(name, chart)
            if chart == "canonical":
                ns["pi"] = D.pi
                ns["PB"] = lambda f, g: _sym.poisson_bracket(f, g, D.n, D.pi)
                ns["ndot_of_pi"] = D.velocity_of_momenta
                ns["L_of_pi"] = D.L.xreplace(dict(zip(D.ndot, D.velocity_of_momenta)))
            else:
                assert own is not None  # chart is "nm", "nOmega" or "nM" here
                ns[own] = {"nm": D.m_sym, "nOmega": D.Omega_sym, "nM": D.M_sym}[chart]
                ns["PBnX"], ns["PBXX"] = D.brackets(chart)
                ns["P"] = D.poisson_tensor(chart)
        elif frame == "phase-velocity":
            ns["pi"] = D.pi
            ns["ndot"] = D.ndot
            pidot = sp.Matrix(sp.symbols("pidot1:4", real=True))
            ns["pidot"] = pidot
            ns["H"] = D.H

            def el_n(LH):
                # d/dt dLH/dndot_i - dLH/dn_i ; dLH/dndot_i depends on (n, pi) only
                out = []
                for i in range(3):
                    p_i = sp.diff(LH, D.ndot[i])
                    dt = sum(sp.diff(p_i, D.n[j]) * D.ndot[j] + sp.diff(p_i, D.pi[j]) * pidot[j] for j in range(3))
                    out.append(dt - sp.diff(LH, D.n[i]))
                return sp.Matrix(out)

            def el_pi(LH):
                out = []
                for i in range(3):
                    p_i = sp.diff(LH, pidot[i])
                    dt = sum(sp.diff(p_i, D.n[j]) * D.ndot[j] + sp.diff(p_i, D.pi[j]) * pidot[j] for j in range(3))
                    out.append(dt - sp.diff(LH, D.pi[i]))
                return sp.Matrix(out)

            ns["el_n"] = el_n
            ns["el_pi"] = el_pi
        elif frame in ("axis-angle", "angle", "asymptotic"):
            a, b = sp.symbols("a b", real=True)
            ns["alpha"] = sp.Symbol("alpha", real=True)
            if frame == "axis-angle":
                k = _unit_vector(a, b)
                ns["k"] = k
                ns["x"] = sp.Matrix(sp.symbols("x_1:4", real=True))
                ns["q0"] = sp.cos(ns["alpha"] / 2)
                ns["q"] = k * sp.sin(ns["alpha"] / 2)
            if frame == "asymptotic":
                ns["r"] = sp.Symbol("r", positive=True)
                ns["e"] = _unit_vector(a, b)
        else:
            raise InvalidInputError(f"unknown frame {frame!r}")
        return ns

    # -- claim helpers ---------------------------------------------------
    def _claim_helpers(self, ns, D, frame):
        sp = _sp()
        session = self

        def log(text, latex=None):
            session.log.append((text, latex))

        def jac(F, vars_):
            F = sp.Matrix(_resolve(F))
            return F.jacobian(sp.Matrix(_resolve(vars_)))

        def generic_rank(M):
            M = sp.Matrix(_resolve(M))
            syms = sorted(M.free_symbols, key=lambda s: s.name)
            rng = random.Random(f"{session.seed}/rank/{frame}")
            best = 0
            for _ in range(3):
                pt = _random_point(syms, rng, lambda p: M.xreplace(p))
                best = max(best, M.xreplace(pt).rank())
            session.log.append((f"rank {best} (maximum over 3 random rational points)", None))
            return best

        def nonzero(e):
            e = _resolve(e)
            s = _sym.rsimp(e)
            session.log.append(("closed form", sp.factor(s)))
            return not _sym.is_zero(s)

        def nonzero_matrix(M):
            M = sp.Matrix(_resolve(M))
            M = M.applyfunc(_sym.rsimp)
            session.log.append(("difference", M))
            return any(not _sym.is_zero(x) for x in M)

        def independent_of_inertia(X):
            X = _flatten(_resolve(X))
            bad = [s for x in X for s in D.inertia_symbols if not _sym.is_zero(sp.diff(x, s))]
            session.log.append(
                (
                    f"derivatives with respect to {', '.join(map(str, D.inertia_symbols))} vanish"
                    if not bad
                    else f"depends on {sorted(set(map(str, bad)))}",
                    None,
                )
            )
            return not bad

        def pfaffian(M):
            M = sp.Matrix(_resolve(M))
            pf = _pfaffian(M)
            return pf

        def e3_difference(chart):
            return session.e3_comparison(D, chart)["difference"]

        def lie_symbolic_check(order):
            ok, text = _lie_symbolic_check(D, int(order))
            log(text)
            return ok

        def lie_exact_check(order, npoints):
            ok, text = _lie_exact_check(D, int(order), int(npoints), session.seed)
            log(text)
            return ok

        def lie_numeric_check(orders):
            ok, text = _lie_numeric_check([int(o) for o in orders])
            log(text)
            return ok

        ns.update(
            jac=jac,
            generic_rank=generic_rank,
            nonzero=nonzero,
            nonzero_matrix=nonzero_matrix,
            independent_of_inertia=independent_of_inertia,
            pfaffian=pfaffian,
            e3_difference=e3_difference,
            lie_symbolic_check=lie_symbolic_check,
            lie_exact_check=lie_exact_check,
            lie_numeric_check=lie_numeric_check,
        )

    # -- e(3) ------------------------------------------------------------
    def e3_comparison(self, D, chart):
        key = ("e3", D.inertia, chart)
        if key in self.integrability:
            return self.integrability[key]
        sp = _sp()
        X = {"nm": D.m_sym, "nOmega": D.Omega_sym, "nM": D.M_sym}[chart]
        S = {"nm": sp.eye(3), "nM": -sp.eye(3), "nOmega": -D.I}[chart]
        P = D.poisson_tensor(chart)
        vars_ = list(D.n) + list(X)
        zero = {v: 0 for v in vars_}

        def lin(e):
            e0 = e.xreplace(zero)
            return _sym.rsimp(e0 + sum(sp.diff(e, v).xreplace(zero) * v for v in vars_))

        L = P.applyfunc(lin)
        Sinv = S.inv() if chart != "nOmega" else D.Iinv * -1
        J = S * X
        E = sp.zeros(6, 6)
        for i in range(3):
            for j in range(3):
                E[i, 3 + j] = sum(Sinv[j, l] * _sym.levi_civita(i, l, k) * D.n[k] for l in range(3) for k in range(3))
                E[3 + j, i] = -E[i, 3 + j]
                E[3 + i, 3 + j] = sum(
                    Sinv[i, a] * Sinv[j, b] * _sym.levi_civita(a, b, c) * J[c]
                    for a in range(3)
                    for b in range(3)
                    for c in range(3)
                )
        E = E.applyfunc(_sym.rsimp)
        Dm = (L - E).applyfunc(_sym.rsimp)
        res = {
            "chart": chart,
            "identification": {"nm": "J = m, P = n", "nM": "J = -M, P = n", "nOmega": "J = -I Omega, P = n"}[chart],
            "linearised": L,
            "e3": E,
            "difference": Dm,
            "linearised_latex": _latex(L),
            "e3_latex": _latex(E),
            "difference_latex": _latex(Dm),
        }
        self.integrability[key] = res
        return res


def _sym_matrix(name):
    sp = _sp()
    s = {(i, j): sp.Symbol(f"{name}{min(i, j) + 1}{max(i, j) + 1}", real=True) for i in range(3) for j in range(3)}
    return sp.Matrix(3, 3, lambda i, j: s[(i, j)])


def _det3(M):
    """Determinant of a 3x3 matrix by the cofactor formula (no simplification)."""
    return (
        M[0, 0] * (M[1, 1] * M[2, 2] - M[1, 2] * M[2, 1])
        - M[0, 1] * (M[1, 0] * M[2, 2] - M[1, 2] * M[2, 0])
        + M[0, 2] * (M[1, 0] * M[2, 1] - M[1, 1] * M[2, 0])
    )


def _pfaffian(M):
    n = M.shape[0]
    if n == 0:
        return 1
    if n % 2:
        return 0
    total = 0
    for j in range(1, n):
        if M[0, j] == 0:
            continue
        rest = [k for k in range(n) if k not in (0, j)]
        sub = M.extract(rest, rest)
        total += (-1) ** (j + 1) * M[0, j] * _pfaffian(sub)
    return total


# ---------------------------------------------------------------------------
# derived quantities
# ---------------------------------------------------------------------------


def _limit_at_infinity(expr, r):
    sp = _sp()
    e = _sym.rsimp(expr)
    num, den = sp.fraction(sp.together(e))
    pn = sp.Poly(sp.expand(num), r)
    pd = sp.Poly(sp.expand(den), r)
    if pn.is_zero:
        return sp.Integer(0)
    if pn.degree() < pd.degree():
        return sp.Integer(0)
    if pn.degree() == pd.degree():
        return _sym.rsimp(pn.LC() / pd.LC())
    return sp.oo


def derived_value(key: str, ns: dict, D, shape_index: str):
    """The derived quantity ``key`` as a flat list of components of shape ``shape_index``."""
    sp = _sp()
    size = 3 ** len(shape_index)
    if key == "zero":
        return [sp.Integer(0)] * size
    if key == "delta":
        return list(sp.eye(3))
    if key == "one":
        return [sp.Integer(1)]
    simple = {
        "n": lambda: D.n,
        "x": lambda: ns["x"],
        "k": lambda: ns["k"],
        "R": lambda: D.R,
        "A": lambda: D.A,
        "Atilde": lambda: D.Atilde,
        "G": lambda: D.G,
        "Ginv": lambda: D.Ginv,
        "L": lambda: D.L,
        "momenta": lambda: D.momenta,
        "Omega_v": lambda: D.Omega_of_velocity,
        "ndot_c": lambda: D.ndot_canonical,
        "pidot_c": lambda: D.pidot_canonical,
        "Omega_c": lambda: D.Omega_canonical,
        "m_c": lambda: D.m_canonical,
        "H": lambda: _resolve(ns["H"]),
        "pi": lambda: _resolve(ns["pi"]),
        "ndot": lambda: _resolve(ns["ndot"]),
        "mdot": lambda: _resolve(ns["mdot"]),
        "PBnX": lambda: _resolve(ns["PBnX"]),
        "PBXX": lambda: _resolve(ns["PBXX"]),
        "PBnn": lambda: sp.zeros(3, 3),
    }
    if key in simple:
        return _flatten(simple[key]())
    if key == "constraint_at_t0":
        x = ns["x"]
        return [_sym.dot(x(2) - x(1), x(3) - x(1))]
    if key in ("kinetic_from_g", "kinetic_from_g_velocity"):
        g = ns["g"]
        Om = D.Omega_sym if key == "kinetic_from_g" else D.Omega_of_velocity
        Ig = g.trace() * sp.eye(3) - g
        return [(Om.T * Ig * Om)[0] / 2]
    if key == "kinetic_particles":
        Rdot, x, mass = ns["Rdot"], ns["x"], ns["mass"]
        return [sum(mass(N) * _sym.dot(Rdot * x(N), Rdot * x(N)) for N in (1, 2)) / 2]
    if key == "Rdot_of_Omega":
        nd = _sym.inverse3(2 * D.A.T) * D.Omega_sym
        return _flatten(D.R_dot(nd))
    if key == "R_axis_angle":
        al = ns["alpha"]
        return _flatten(_sym.rotation_from_axis_angle(ns["k"], sp.cos(al), sp.sin(al)))
    if key == "ccw_image_of_e1":
        al = ns["alpha"]
        return [sp.cos(al), sp.sin(al), sp.Integer(0)]
    if key == "sin_half_angle":
        return [sp.sin(ns["alpha"]).rewrite(sp.tan)]
    if key == "cos_half_angle":
        return [sp.cos(ns["alpha"]).rewrite(sp.tan)]
    if key == "eps_Omega":
        Om = D.Omega_of_velocity
        return [-sum(_sym.levi_civita(i, j, k) * Om[k] for k in range(3)) for i in range(3) for j in range(3)]
    if key == "G_at_origin":
        return _flatten(D.G.xreplace({x: 0 for x in D.n}))
    if key in ("n2G_at_infinity", "G_at_infinity", "G_radial"):
        r, e = ns["r"], ns["e"]
        Gre = D.G.xreplace({D.n[i]: r * e[i] for i in range(3)})
        if key == "G_radial":
            return [_sym.rsimp((e.T * Gre * e)[0])]
        factor = r**2 if key == "n2G_at_infinity" else 1
        return [_limit_at_infinity(factor * x, r) for x in Gre]
    if key == "hamilton_pi_residual":
        pidot = ns["pidot"]
        return _flatten(pidot - D.pidot_canonical)
    if key == "hamilton_n_residual":
        return _flatten(-(D.ndot - D.ndot_canonical))
    if key == "H_at_origin":
        return [D.H.xreplace({x: 0 for x in D.n})]
    raise InvalidInputError(f"unknown derived quantity {key!r}")


# ---------------------------------------------------------------------------
# integrability summary
# ---------------------------------------------------------------------------


def integrability_summary(session: Session) -> dict:
    """Pairwise brackets of ``(H, m^2, m_3)`` and the rank of their Jacobian."""
    sp = _sp()
    D = session.derivation("general")
    H = D.H
    m = D.m_canonical
    m2 = _sym.dot(m, m)
    funcs = {"H": H, "m^2": m2, "m_3": m[2]}
    names = list(funcs)
    brackets = {}
    for a in range(3):
        for b in range(a + 1, 3):
            v = _sym.rsimp(_sym.poisson_bracket(funcs[names[a]], funcs[names[b]], D.n, D.pi))
            brackets[f"{{{names[a]}, {names[b]}}}"] = str(v)
    J = sp.Matrix([H, m2, m[2]]).jacobian(sp.Matrix.vstack(D.n, D.pi))
    rng = random.Random(f"{session.seed}/integrability")
    syms = sorted(J.free_symbols, key=lambda s: s.name)
    ranks = []
    for _ in range(3):
        pt = _random_point(syms, rng, lambda p: J.xreplace(p))
        ranks.append(J.xreplace(pt).rank())
    out = {
        "inertia": "general",
        "involution": brackets,
        "all_brackets_vanish": all(v == "0" for v in brackets.values()),
        "jacobian_rank": max(ranks),
        "jacobian_ranks_at_random_points": ranks,
    }
    for chart in ("nm", "nOmega", "nM"):
        P = D.poisson_tensor(chart)
        pf = sp.factor(_sym.rsimp(_pfaffian(P)))
        det = sp.factor(_sym.rsimp(pf**2))
        out[f"pfaffian_{chart}"] = str(pf)
        out[f"pfaffian_{chart}_latex"] = sp.latex(pf)
        out[f"det_{chart}"] = str(det)
        out[f"det_{chart}_latex"] = sp.latex(det)
        out[f"nondegenerate_{chart}"] = not _sym.is_zero(pf)
        e3 = session.e3_comparison(D, chart)
        out[f"e3_{chart}"] = {
            "identification": e3["identification"],
            "linearised_latex": e3["linearised_latex"],
            "e3_latex": e3["e3_latex"],
            "difference_latex": e3["difference_latex"],
            "differs": any(not _sym.is_zero(x) for x in e3["difference"]),
        }
    return out
