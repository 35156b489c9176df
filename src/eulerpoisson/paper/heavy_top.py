r"""The heavy top in the paper's Gibbs vector, derived with SymPy from its Lagrangian.

The paper (section 1) writes the free rigid body in the unconstrained rotation
vector :math:`\mathbf n = \mathbf k\tan(\alpha/2)`: :math:`R(\mathbf n)`
(eq. 1.9), :math:`\boldsymbol\Omega = 2A^T\dot{\mathbf n}` (eq. 1.11-1.12),
:math:`L_0 = \tfrac12\dot{\mathbf n}^TG\dot{\mathbf n}` with
:math:`G = 4AIA^T` (eq. 1.13), the momenta :math:`\boldsymbol\pi = G\dot{\mathbf n}`
(eq. 1.14) and :math:`H_0 = \tfrac18(\tilde A\boldsymbol\pi)^TI^{-1}(\tilde A\boldsymbol\pi)`
(eq. 1.15). Here the body is heavy: a fixed point at the body origin, the
centre of mass :math:`\mathbf c` (body frame), the mass :math:`\mu` and the
gravitational acceleration :math:`\mathbf g` (space frame), all symbols, with
a general symmetric inertia tensor about the fixed point:

.. math::
    U(\mathbf n) = -\mu\,\mathbf g\cdot R(\mathbf n)\mathbf c, \qquad
    L = \tfrac12\dot{\mathbf n}^TG(\mathbf n)\dot{\mathbf n} - U(\mathbf n).

Everything is derived, not transcribed: :math:`R`, :math:`A`, :math:`\tilde A`,
:math:`L_0` come from :func:`eulerpoisson.paper.symbolic.derive` (the
axis-angle construction and eq. 1.10); the momenta, the metric, the velocity
:math:`\dot{\mathbf n}(\mathbf n, \boldsymbol\pi)` and the full Legendre
transform :math:`H = \boldsymbol\pi\cdot\dot{\mathbf n} - L` (the potential
does not depend on the velocity, so :math:`\boldsymbol\pi = G\dot{\mathbf n}`
is unchanged) are computed here, and Hamilton's equations
:math:`\dot z = \{z, H\}` follow from the canonical bracket. The results,
checked exactly by :meth:`HeavyTopDerivation.identities` (rational functions
reduced to polynomial numerators, :mod:`eulerpoisson.paper.symbolic`):

.. math::
    H = H_0 + U, \qquad
    \dot{\mathbf n} = \frac{\partial H_0}{\partial\boldsymbol\pi}, \qquad
    \dot{\boldsymbol\pi} = -\frac{\partial H_0}{\partial\mathbf n} - \frac{\partial U}{\partial\mathbf n},
    \qquad \frac{\partial U}{\partial\mathbf n} = -2A(\mathbf n)\boldsymbol\tau,
    \quad \boldsymbol\tau = \mathbf c\times\mu R^T\mathbf g,

and, in closed form, with :math:`\boldsymbol\Omega = \tfrac12I^{-1}\tilde A\boldsymbol\pi`,

.. math::
    \dot{\boldsymbol\pi} = -\tfrac12\left[(\mathbf n\cdot\boldsymbol\pi)\boldsymbol\Omega
    + (\mathbf n\cdot\boldsymbol\Omega)\boldsymbol\pi + \boldsymbol\Omega\times\boldsymbol\pi\right]
    + 2A\boldsymbol\tau

(the paper's eq. 1.16 with :math:`\epsilon_{ijk}\pi_k` for the printed
:math:`\epsilon_{ijk}n_k`, plus the torque). These are the Euler-Poisson
equations: :math:`\mathbf M = I\boldsymbol\Omega` obeys
:math:`\dot{\mathbf M} = \mathbf M\times\boldsymbol\Omega + \boldsymbol\tau`,
the Poisson vector :math:`\boldsymbol\gamma = R^T\mathbf g` obeys
:math:`\dot{\boldsymbol\gamma} = \boldsymbol\gamma\times\boldsymbol\Omega`, and
:math:`\mathbf m\cdot\mathbf g` is conserved. The numeric counterpart is
``eulerpoisson.formulation("canonical", body, torque=Gravity(...))``;
:func:`check_heavy_top` compares the two at exact rational points.

SymPy is imported on first use only (extra ``symbolic``).

References
----------
A. A. Deriglazov, "Geodesic motion on the symplectic leaf of SO(3) with
distorted e(3) algebra and Liouville integrability of a free rigid body",
eq. 1.9-1.16 (``/work/shared/paper/paper.tex``).
E. Leimanis, *The General Problem of the Motion of Coupled Rigid Bodies about
a Fixed Point*, Springer (1965), ch. I (the Euler-Poisson equations).
"""

from __future__ import annotations

import functools
from dataclasses import dataclass, field
from fractions import Fraction
from functools import cached_property
from typing import Any

import numpy as np

from ..errors import InvalidInputError
from . import symbolic as _S

__all__ = ["HeavyTopDerivation", "derive_heavy_top", "HeavyTopCheck", "check_heavy_top"]


def _cross(u, v):
    return [
        (u[1] * v[2] - u[2] * v[1]).normalize(),
        (u[2] * v[0] - u[0] * v[2]).normalize(),
        (u[0] * v[1] - u[1] * v[0]).normalize(),
    ]


def _rdot(ctx, u, v):
    return _S.rsum((u[i] * v[i] for i in range(3)), ctx).normalize()


def _scale(ctx, c, u):
    c = ctx.from_expr(c) if not isinstance(c, _S.Rat) else c
    return [(c * x).normalize() for x in u]


def _sub(u, v):
    return [(a - b).normalize() for a, b in zip(u, v)]


class HeavyTopDerivation:
    r"""The heavy top's Hamiltonian equations in :math:`(\mathbf n, \boldsymbol\pi)`, derived from its Lagrangian.

    Obtain instances with :func:`derive_heavy_top` (cached). Every public
    attribute is a lazily computed, cached SymPy object (a scalar or a
    ``(3, 1)`` / ``(3, 3)`` / ``(6, 1)`` matrix) whose denominators are powers
    of :math:`1+\mathbf n^2` and :math:`\det I`.

    Attributes
    ----------
    n, ndot, pi : the Gibbs vector, its velocity and the canonical momenta
        (shared with :func:`eulerpoisson.paper.symbolic.derive`).
    mass, c, g : :math:`\mu` (symbol ``mu``), the centre of mass
        ``c1, c2, c3`` (body frame) and the gravity ``g1, g2, g3`` (space frame).
    I, inertia_symbols : the inertia tensor (general symmetric ``I11 ... I33``
        or ``diag(I1, I2, I3)``) about the fixed point.

    Derived quantities: ``R``, ``A``, ``Atilde``, ``U``, ``L``, ``momenta``,
    ``G``, ``velocity_of_momenta``, ``H``, ``H0``, ``ndot``, ``pidot``,
    ``dU_dn``, ``torque``, ``Omega``, ``pidot_closed_form``, ``vector_field``;
    :meth:`identities` checks them exactly.
    """

    def __init__(self, inertia: str = "general"):
        sp = _S.sympy_module()
        base = _S.derive(inertia)
        self.base = base
        self.inertia = inertia
        self.n, self.ndot, self.pi = base.n, base.ndot, base.pi
        self.I, self.inertia_symbols = base.I, base.inertia_symbols
        self.mass = sp.Symbol("mu", positive=True)
        self.c = sp.Matrix(sp.symbols("c1:4", real=True))
        self.g = sp.Matrix(sp.symbols("g1:4", real=True))
        gens = list(base.ctx.symbols) + [self.mass] + list(self.c) + list(self.g)
        known = [1 + base.nsq] + ([base.detI] if inertia == "general" else list(base.inertia_symbols))
        self.ctx = C = _S.Ctx(gens, known)
        self._fn, self._fnd, self._fpi = C.vec(self.n), C.vec(self.ndot), C.vec(self.pi)
        self._fc, self._fg = C.vec(self.c), C.vec(self.g)
        self._fmass = C.from_expr(self.mass)
        self._fI = C.mat(self.I)
        self._fIinv = C.mat(base.Iinv)

    def __repr__(self) -> str:
        return f"HeavyTopDerivation(inertia={self.inertia!r})"

    def _m(self, X):
        return self.ctx.to_matrix(X)

    # -- kinematics, from the free derivation --------------------------------
    @cached_property
    def _fR(self):
        return self.ctx.mat(self.base.R)

    @cached_property
    def R(self):
        r""":math:`R(\mathbf n)` (eq. 1.9, derived from the axis-angle construction)."""
        return self._m(self._fR)

    @cached_property
    def _fA(self):
        return self.ctx.mat(self.base.A)

    @cached_property
    def A(self):
        r""":math:`A(\mathbf n)`, :math:`\boldsymbol\Omega = 2A^T\dot{\mathbf n}` (eq. 1.11-1.12)."""
        return self._m(self._fA)

    @cached_property
    def _fAtilde(self):
        return self.ctx.mat(self.base.Atilde)

    @cached_property
    def Atilde(self):
        r""":math:`\tilde A = A^{-1}` (eq. 1.12, corrected)."""
        return self._m(self._fAtilde)

    # -- Lagrangian ------------------------------------------------------------
    @cached_property
    def _fU(self):
        Rc = _S.rmm(self._fR, self._fc)
        return (-(self._fmass * _rdot(self.ctx, self._fg, Rc))).normalize()

    @cached_property
    def U(self):
        r"""Potential :math:`U(\mathbf n) = -\mu\,\mathbf g\cdot R(\mathbf n)\mathbf c`."""
        return self._fU.expr()

    @cached_property
    def _fL(self):
        return (self.ctx.from_expr(self.base.L) - self._fU).normalize()

    @cached_property
    def L(self):
        r"""Lagrangian :math:`L = \tfrac12 I_{ij}\Omega_i\Omega_j - U` (eq. 1.10, 1.13 with the potential)."""
        return self._fL.expr()

    @cached_property
    def _fmomenta(self):
        return [self._fL.diff(x) for x in self.ndot]

    @cached_property
    def momenta(self):
        r""":math:`\pi_i = \partial L/\partial\dot n_i` (eq. 1.14; the potential does not contribute)."""
        return self._m(self._fmomenta)

    @cached_property
    def _fG(self):
        return [[self._fmomenta[i].diff(self.ndot[j]) for j in range(3)] for i in range(3)]

    @cached_property
    def G(self):
        r"""Metric :math:`G_{ij} = \partial^2L/\partial\dot n_i\partial\dot n_j` (eq. 1.13)."""
        return self._m(self._fG)

    @cached_property
    def _fvelocity(self):
        return _S.rmm(_S.rinv3(self._fG), self._fpi)

    @cached_property
    def velocity_of_momenta(self):
        r""":math:`\dot{\mathbf n}(\mathbf n, \boldsymbol\pi) = G^{-1}\boldsymbol\pi`, the solution of :math:`\boldsymbol\pi = \partial L/\partial\dot{\mathbf n}`."""
        return self._m(self._fvelocity)

    # -- Hamiltonian -------------------------------------------------------------
    @cached_property
    def _fH(self):
        # the full Legendre transform H = pi.v - L(n, v), v = ndot(n, pi) substituted into L
        C = self.ctx
        v = self._fvelocity
        Lv = C.subs(self._fL, dict(zip(self.ndot, v)))
        return (_rdot(C, self._fpi, v) - Lv).normalize()

    @cached_property
    def H(self):
        r"""Hamiltonian :math:`H = \pi_i\dot n_i - L` at :math:`\dot{\mathbf n}(\mathbf n, \boldsymbol\pi)` (Legendre transform)."""
        return self._fH.expr()

    @cached_property
    def _fH0(self):
        C = self.ctx
        u = _S.rmm(self._fAtilde, self._fpi)
        return (C.const(_S.sympy_module().Rational(1, 8)) * _rdot(C, u, _S.rmm(self._fIinv, u))).normalize()

    @cached_property
    def H0(self):
        r"""The paper's free Hamiltonian :math:`H_0 = \tfrac18 I^{-1}_{ij}(\tilde A\boldsymbol\pi)_i(\tilde A\boldsymbol\pi)_j` (eq. 1.15)."""
        return self._fH0.expr()

    def _fbracket(self, f, g):
        return self.ctx.bracket(f, g, self.n, self.pi)

    @cached_property
    def _fndot(self):
        return [self._fbracket(x, self._fH) for x in self._fn]

    @cached_property
    def ndot_hamilton(self):
        r"""Hamilton's equation :math:`\dot n_i = \{n_i, H\} = \partial H/\partial\pi_i`."""
        return self._m(self._fndot)

    @cached_property
    def _fpidot(self):
        return [self._fbracket(x, self._fH) for x in self._fpi]

    @cached_property
    def pidot(self):
        r"""Hamilton's equation :math:`\dot\pi_i = \{\pi_i, H\} = -\partial H/\partial n_i`."""
        return self._m(self._fpidot)

    @cached_property
    def _fdU(self):
        return [self._fU.diff(x) for x in self.n]

    @cached_property
    def dU_dn(self):
        r""":math:`\partial U/\partial\mathbf n`, differentiated directly."""
        return self._m(self._fdU)

    @cached_property
    def _ftorque(self):
        C = self.ctx
        gamma = _S.rmm(_S.rtr(self._fR), self._fg)  # R^T g
        return _cross(self._fc, _scale(C, self._fmass, gamma))

    @cached_property
    def torque(self):
        r"""Body-frame torque :math:`\boldsymbol\tau = \mathbf c\times(\mu R^T\mathbf g)` (as :class:`~eulerpoisson.torques.Gravity`)."""
        return self._m(self._ftorque)

    @cached_property
    def _fOmega(self):
        C = self.ctx
        return _scale(C, _S.sympy_module().Rational(1, 2), _S.rmm(self._fIinv, _S.rmm(self._fAtilde, self._fpi)))

    @cached_property
    def Omega(self):
        r""":math:`\boldsymbol\Omega = \tfrac12 I^{-1}\tilde A\boldsymbol\pi`."""
        return self._m(self._fOmega)

    @cached_property
    def _fpidot_closed(self):
        C = self.ctx
        sp = _S.sympy_module()
        n, p, W = self._fn, self._fpi, self._fOmega
        npi, nw = _rdot(C, n, p), _rdot(C, n, W)
        c = _cross(W, p)
        half = C.const(sp.Rational(-1, 2))
        free = [(half * (npi * W[i] + nw * p[i] + c[i])).normalize() for i in range(3)]
        tq = _scale(C, 2, _S.rmm(self._fA, self._ftorque))
        return [(a + b).normalize() for a, b in zip(free, tq)]

    @cached_property
    def pidot_closed_form(self):
        r""":math:`-\tfrac12[(\mathbf n\cdot\boldsymbol\pi)\boldsymbol\Omega + (\mathbf n\cdot\boldsymbol\Omega)\boldsymbol\pi + \boldsymbol\Omega\times\boldsymbol\pi] + 2A\boldsymbol\tau` (eq. 1.16 corrected, plus the torque)."""
        return self._m(self._fpidot_closed)

    @cached_property
    def vector_field(self):
        r"""The heavy top's canonical vector field :math:`(\dot{\mathbf n}, \dot{\boldsymbol\pi})`, a (6, 1) matrix."""
        sp = _S.sympy_module()
        return sp.Matrix(list(self.ndot_hamilton) + list(self.pidot))

    # -- exact checks ------------------------------------------------------------
    def _zero(self, xs):
        return all(x.normalize().is_zero() for x in xs)

    def _identity(self, name):
        C, b = self.ctx, self.base
        if name == "momenta_are_G_ndot":
            return self._zero(_sub(self._fmomenta, _S.rmm(C.mat(b.G), self._fnd)))
        if name == "metric_is_4AIAt":
            AIAt = _S.rmm(_S.rmm(self._fA, self._fI), _S.rtr(self._fA))
            return self._zero([g - 4 * x for rg, ra in zip(self._fG, AIAt) for g, x in zip(rg, ra)])
        if name == "H_is_H0_plus_U":
            return self._zero([self._fH - self._fH0 - self._fU])
        if name == "ndot_is_dH0_dpi":
            return self._zero(_sub(self._fndot, [self._fH0.diff(p) for p in self.pi]))
        if name == "pidot_is_minus_dH0_dn_minus_dU_dn":
            return self._zero([self._fpidot[i] + self._fH0.diff(self.n[i]) + self._fdU[i] for i in range(3)])
        if name == "dU_dn_is_minus_2A_tau":
            tq = _S.rmm(self._fA, self._ftorque)
            return self._zero([self._fdU[i] + 2 * tq[i] for i in range(3)])
        if name == "pidot_closed_form":
            return self._zero(_sub(self._fpidot, self._fpidot_closed))
        if name == "euler_equations":
            # M = I Omega(n, pi) from eq. 1.10, Mdot = {M, H} = M x Omega + tau
            Om = C.vec(b.Omega_canonical)
            M = _S.rmm(self._fI, Om)
            Md = [self._fbracket(x, self._fH) for x in M]
            rhs = [a + t for a, t in zip(_cross(M, Om), self._ftorque)]
            return self._zero(_sub(Md, rhs))
        if name == "poisson_equation":
            # gamma = R^T g, gammadot = {gamma, H} = gamma x Omega
            gamma = _S.rmm(_S.rtr(self._fR), self._fg)
            gd = [self._fbracket(x, self._fH) for x in gamma]
            return self._zero(_sub(gd, _cross(gamma, self._fOmega)))
        if name == "vertical_momentum_conserved":
            m = C.vec(b.m_canonical)
            return self._zero([self._fbracket(_rdot(C, m, self._fg), self._fH)])
        raise InvalidInputError(f"identity name must be one of {self.IDENTITIES}, got {name!r}")

    #: names accepted by :meth:`identities`
    IDENTITIES = (
        "momenta_are_G_ndot",
        "metric_is_4AIAt",
        "H_is_H0_plus_U",
        "ndot_is_dH0_dpi",
        "pidot_is_minus_dH0_dn_minus_dU_dn",
        "dU_dn_is_minus_2A_tau",
        "pidot_closed_form",
        "euler_equations",
        "poisson_equation",
        "vertical_momentum_conserved",
    )

    @functools.cache  # noqa: B019 - one instance per inertia case, kept for the process by derive_heavy_top()'s cache
    def identity(self, name: str) -> bool:
        r"""Exact check of one identity (True when it holds identically).

        Parameters
        ----------
        name : str
            One of :attr:`IDENTITIES`:

            - ``"momenta_are_G_ndot"``: :math:`\partial L/\partial\dot{\mathbf n} = G\dot{\mathbf n}`
              with the free metric (eq. 1.14);
            - ``"metric_is_4AIAt"``: :math:`G = 4AIA^T` (eq. 1.13);
            - ``"H_is_H0_plus_U"``: the Legendre transform is :math:`H_0 + U`, :math:`H_0` of eq. 1.15;
            - ``"ndot_is_dH0_dpi"``: :math:`\dot{\mathbf n} = \partial H_0/\partial\boldsymbol\pi` (eq. 1.16);
            - ``"pidot_is_minus_dH0_dn_minus_dU_dn"``: :math:`\dot{\boldsymbol\pi} = -\partial_{\mathbf n}H_0 - \partial_{\mathbf n}U`;
            - ``"dU_dn_is_minus_2A_tau"``: :math:`\partial U/\partial\mathbf n = -2A\boldsymbol\tau`;
            - ``"pidot_closed_form"``: :math:`\dot{\boldsymbol\pi}` equals :attr:`pidot_closed_form`;
            - ``"euler_equations"``: :math:`\{\mathbf M, H\} = \mathbf M\times\boldsymbol\Omega + \boldsymbol\tau`;
            - ``"poisson_equation"``: :math:`\{R^T\mathbf g, H\} = (R^T\mathbf g)\times\boldsymbol\Omega`;
            - ``"vertical_momentum_conserved"``: :math:`\{\mathbf m\cdot\mathbf g, H\} = 0`.

        Returns
        -------
        bool

        Raises
        ------
        InvalidInputError
            Unknown ``name``.
        """
        if not isinstance(name, str) or name not in self.IDENTITIES:
            raise InvalidInputError(f"identity name must be one of {self.IDENTITIES}, got {name!r}")
        return bool(self._identity(name))

    def identities(self) -> dict:
        """All of :attr:`IDENTITIES` checked exactly: ``{name: bool}``."""
        return {k: self.identity(k) for k in self.IDENTITIES}

    # -- exact evaluation ----------------------------------------------------------
    def _values(self, n, pi, inertia, mass, center_of_mass, g):
        sp = _S.sympy_module()
        vals: dict[Any, Any] = {}
        vals.update(zip(self.n, _exact_vector(n, "n")))
        vals.update(zip(self.pi, _exact_vector(pi, "pi")))
        vals.update(zip(self.c, _exact_vector(center_of_mass, "center_of_mass")))
        vals.update(zip(self.g, _exact_vector(g, "g")))
        m = _exact_scalar(mass, "mass")
        if m <= 0:
            raise InvalidInputError(f"mass must be > 0, got {mass!r}")
        vals[self.mass] = m
        I = _exact_inertia(inertia, self.inertia)
        if self.inertia == "general":
            idx = ((0, 0), (0, 1), (0, 2), (1, 1), (1, 2), (2, 2))
            vals.update({s: I[i][j] for s, (i, j) in zip(self.inertia_symbols, idx)})
        else:
            vals.update({s: I[i][i] for i, s in enumerate(self.inertia_symbols)})
        for s in self.ctx.symbols:
            vals.setdefault(s, Fraction(0))
        return {s: sp.QQ(v.numerator, v.denominator) for s, v in vals.items()}

    def _eval(self, f, vals):
        C = self.ctx
        point = [vals[s] for s in C.symbols]
        num = f.num(*point) if C.symbols else f.num
        den = C.ring.domain.one
        for k, e in f.den.items():
            den = den * C.factors[k](*point) ** e
        if den == 0:
            raise InvalidInputError("the point is singular (a denominator vanishes: det I = 0?)")
        q = num / den
        return Fraction(int(q.numerator), int(q.denominator))

    def evaluate(self, n, pi, inertia, mass, center_of_mass, g, *, exact: bool = False):
        r"""The derived vector field :math:`(\dot{\mathbf n}, \dot{\boldsymbol\pi})` at a point, in exact arithmetic.

        Every input is converted to an exact rational (floats exactly, by
        :class:`fractions.Fraction`), the rational functions are evaluated
        over :math:`\mathbb Q`, and the result is rounded once.

        Parameters
        ----------
        n, pi : sequence of 3 numbers
            Gibbs vector and canonical momentum.
        inertia : array_like, shape (3, 3) (or (3,) for ``inertia="diagonal"``)
            Inertia tensor about the fixed point (symmetric).
        mass : number
            > 0.
        center_of_mass, g : sequence of 3 numbers
            Body frame and space frame.
        exact : bool
            Return :class:`fractions.Fraction` values instead of floats.

        Returns
        -------
        ndarray, shape (6,)
            Floats (or an object array of Fractions when ``exact``).

        Raises
        ------
        InvalidInputError
            Wrong lengths, non-finite values, a non-positive mass, an
            asymmetric inertia.
        TypeError
            Non-numeric inputs.
        """
        vals = self._values(n, pi, inertia, mass, center_of_mass, g)
        out = [self._eval(f, vals) for f in list(self._fndot) + list(self._fpidot)]
        if exact:
            return np.array(out, dtype=object)
        return np.array([float(x) for x in out])


def _exact_scalar(x, name):
    if isinstance(x, Fraction):
        return x
    if isinstance(x, (bool, np.bool_)) or isinstance(x, (str, bytes)):
        raise TypeError(f"{name} must be a real number, got {x!r}")
    try:
        sp = _S.sympy_module()
        if isinstance(x, sp.Rational):
            return Fraction(int(x.p), int(x.q))
    except Exception:  # pragma: no cover - sympy always importable here
        pass
    if isinstance(x, (int, np.integer)):
        return Fraction(int(x))
    try:
        f = float(x)
    except (TypeError, ValueError):
        raise TypeError(f"{name} must be a real number, got {x!r}") from None
    if not np.isfinite(f):
        raise InvalidInputError(f"{name} must be finite, got {x!r}")
    return Fraction(f)


def _exact_vector(v, name):
    if isinstance(v, (str, bytes)):
        raise TypeError(f"{name} must be a sequence of 3 numbers, got {v!r}")
    try:
        items = list(v)
    except TypeError:
        raise TypeError(f"{name} must be a sequence of 3 numbers, got {v!r}") from None
    if len(items) != 3:
        raise InvalidInputError(f"{name} must have 3 components, got {len(items)}")
    return [_exact_scalar(x, f"{name}[{i}]") for i, x in enumerate(items)]


def _exact_inertia(inertia, kind):
    if isinstance(inertia, (str, bytes)):
        raise TypeError(f"inertia must be a (3, 3) array of numbers, got {inertia!r}")
    a = np.asarray(inertia, dtype=object)
    if a.shape == (3,):
        M = [[_exact_scalar(a[i], f"inertia[{i}]") if i == j else Fraction(0) for j in range(3)] for i in range(3)]
    elif a.shape == (3, 3):
        M = [[_exact_scalar(a[i, j], f"inertia[{i}, {j}]") for j in range(3)] for i in range(3)]
    else:
        raise InvalidInputError(f"inertia must have shape (3,) or (3, 3), got {a.shape}")
    if any(M[i][j] != M[j][i] for i in range(3) for j in range(3)):
        raise InvalidInputError("inertia must be symmetric")
    if kind == "diagonal" and any(M[i][j] for i in range(3) for j in range(3) if i != j):
        raise InvalidInputError("inertia must be diagonal for a derivation with inertia='diagonal'")
    return M


@functools.cache
def derive_heavy_top(inertia: str = "general") -> HeavyTopDerivation:
    r"""The heavy top's canonical equations in the Gibbs vector, derived from :math:`L = \tfrac12\dot{\mathbf n}^TG\dot{\mathbf n} - U`.

    .. math::
        U = -\mu\,\mathbf g\cdot R(\mathbf n)\mathbf c,\qquad
        H = H_0 + U,\qquad
        \dot{\boldsymbol\pi} = -\frac{\partial H_0}{\partial\mathbf n} - \frac{\partial U}{\partial\mathbf n},
        \qquad \frac{\partial U}{\partial\mathbf n} = -2A(\mathbf n)\,(\mathbf c\times\mu R^T\mathbf g)

    with general symbols :math:`\mu`, :math:`\mathbf c`, :math:`\mathbf g` and
    inertia (see the module docstring).

    Parameters
    ----------
    inertia : {"general", "diagonal"}
        General symmetric inertia tensor (six symbols) or ``diag(I1, I2, I3)``.

    Returns
    -------
    HeavyTopDerivation
        Lazily evaluated and cached: ``H``, ``ndot_hamilton``, ``pidot``,
        ``dU_dn``, ``torque``, ``vector_field``, ... and :meth:`~HeavyTopDerivation.identities`.

    Raises
    ------
    InvalidInputError
        ``inertia`` not one of ``"general"``, ``"diagonal"``.
    MissingDependencyError
        SymPy is not installed (extra ``symbolic``).

    References
    ----------
    Paper eq. 1.9 (:math:`R`), 1.11-1.12 (:math:`A`, :math:`\tilde A`), 1.13
    (:math:`G`), 1.14-1.16 (momenta, :math:`H_0`, Hamilton's equations).

    Examples
    --------
    >>> from eulerpoisson.paper.heavy_top import derive_heavy_top
    >>> d = derive_heavy_top("diagonal")
    >>> d.identity("dU_dn_is_minus_2A_tau")
    True
    """
    if not isinstance(inertia, str) or inertia not in _S.INERTIA_KINDS:
        raise InvalidInputError(f"inertia must be one of {_S.INERTIA_KINDS}, got {inertia!r}")
    return HeavyTopDerivation(inertia)


@dataclass(frozen=True)
class HeavyTopCheck:
    """Result of :func:`check_heavy_top`.

    Attributes
    ----------
    identities : dict of str to bool
        The exact identities of :meth:`HeavyTopDerivation.identities`.
    max_difference : float
        Largest ``|derived - numeric|`` of the vector field over the points,
        relative to ``max(1, |numeric|)``.
    points : int
        Number of random rational points.
    passed : bool
        All identities hold and ``max_difference <= tol``.
    """

    identities: dict = field(default_factory=dict)
    max_difference: float = 0.0
    points: int = 0
    passed: bool = False


def _random_point(rng):
    def q(lo, hi, den=64):
        return Fraction(int(rng.integers(int(lo * den), int(hi * den) + 1)), den)

    n = [q(-1.5, 1.5) for _ in range(3)]
    pi = [q(-3, 3) for _ in range(3)]
    d = [q(2, 3) for _ in range(3)]
    o = [q(-0.2, 0.2) for _ in range(3)]  # |off-diagonal| <= 0.2: positive definite, triangle inequality
    inertia = [[d[0], o[0], o[1]], [o[0], d[1], o[2]], [o[1], o[2], d[2]]]
    mass = q(0.5, 2)
    c = [q(-0.5, 0.5) for _ in range(3)]
    g = [q(-10, 10, 8) for _ in range(3)]
    return n, pi, inertia, mass, c, g


def check_heavy_top(
    points: int = 3, seed: int = 0, *, inertia: str = "general", tol: float = 1e-12, identities: bool = True
) -> HeavyTopCheck:
    r"""Compare the derived heavy top with the numeric canonical formulation.

    Checks the identities of :meth:`HeavyTopDerivation.identities` exactly
    (when ``identities``) and, at ``points`` random rational points
    :math:`(\mathbf n, \boldsymbol\pi, I, \mu, \mathbf c, \mathbf g)`, the
    exactly evaluated derived vector field against
    ``formulation("canonical", I, torque=Gravity(mu, c, g)).vector_field``.

    Parameters
    ----------
    points : int
        Number of random points (>= 1).
    seed : int
        Seed of :func:`numpy.random.default_rng`.
    inertia : {"general", "diagonal"}
    tol : float
        Tolerance on the relative difference.
    identities : bool
        Also check the exact identities (the slower part, ~10 s for a general inertia).

    Returns
    -------
    HeavyTopCheck

    Raises
    ------
    InvalidInputError
        ``points < 1``, bad ``inertia``.
    TypeError
        Non-integer ``points``.
    """
    if isinstance(points, bool) or not isinstance(points, (int, np.integer)):
        raise TypeError(f"points must be an int, got {points!r}")
    if points < 1:
        raise InvalidInputError(f"points must be >= 1, got {points}")
    from ..model.formulations import formulation
    from ..model.torques import Gravity

    d = derive_heavy_top(inertia)
    rng = np.random.default_rng(seed)
    worst = 0.0
    for _ in range(int(points)):
        n, pi, I, mass, c, g = _random_point(rng)
        if inertia == "diagonal":
            I = [[I[i][j] if i == j else Fraction(0) for j in range(3)] for i in range(3)]
        derived = d.evaluate(n, pi, I, mass, c, g)
        f = formulation(
            "canonical",
            np.array(I, dtype=float),
            torque=Gravity(float(mass), [float(x) for x in c], [float(x) for x in g]),
        )
        numeric = f.vector_field(np.array([float(x) for x in n + pi]))
        worst = max(worst, float(np.max(np.abs(derived - numeric) / np.maximum(1.0, np.abs(numeric)))))
    ids = d.identities() if identities else {}
    return HeavyTopCheck(
        identities=ids, max_difference=worst, points=int(points), passed=all(ids.values()) and worst <= tol
    )
