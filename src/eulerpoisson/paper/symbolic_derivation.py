r"""The paper's quantities derived from its Lagrangian (part of :mod:`.symbolic`).

:func:`derive` builds (once per inertia kind, then cached) a
:class:`Derivation`: the rotation matrix of the Gibbs vector, the angular
velocity, the conversion matrices, the metric and its Christoffel symbols,
the momenta, the Hamiltonian and the brackets of the non-canonical charts
(paper eq. 1.7-1.28), each attribute computed on first use. Re-exported by
:mod:`eulerpoisson.paper.symbolic`, whose docstring lists what is derived.

Examples
--------
>>> INERTIA_KINDS
('general', 'diagonal')
"""

from __future__ import annotations

import functools
from functools import cached_property
from typing import Any

from ..errors import InvalidInputError
from .symbolic_rational import Ctx, rinv3, rmm, rsum, rtr
from .symbolic_tensors import dot, levi_civita, poisson_bracket, rotation_from_axis_angle, sympy_module

__all__ = [
    "INERTIA_KINDS",
    "Derivation",
    "derive",
]

#: Accepted values of the ``inertia`` argument of :func:`derive`.
INERTIA_KINDS = ("general", "diagonal")


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
