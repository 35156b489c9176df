r"""The formulations in the paper's Gibbs vector :math:`\mathbf n` (part of :mod:`.formulations`).

Four charts share the first block :math:`\mathbf n`: the canonical
variables :math:`(\mathbf n, \boldsymbol\pi)` (:class:`Canonical`), the
noncanonical :math:`(\mathbf n, \mathbf m)` (:class:`Momentum`),
:math:`(\mathbf n, \boldsymbol\Omega)` (:class:`Velocity`) and the
Lagrangian :math:`(\mathbf n, \dot{\mathbf n})` (:class:`Geodesic`), all
valid for :math:`|\mathbf n|\le` :data:`MAX_GIBBS_NORM`. Registered under
their names and re-exported by :mod:`eulerpoisson.model.formulations`.

Examples
--------
>>> [cls.name for cls in (Canonical, Momentum, Velocity, Geodesic)]
['canonical', 'momentum', 'velocity', 'geodesic']
"""

from __future__ import annotations

import numpy as np

from ..attitude.core import (
    conversion_matrix,
    gibbs_from_quaternion,
    inverse_conversion_matrix,
    inverse_metric,
    matrix_from_gibbs,
    metric,
    quaternion_from_gibbs,
    skew,
)
from ..errors import SingularChartError
from ..util.validate import as_float_array
from .formulation_base import Formulation
from .formulation_base import add_block as _add_block
from .formulation_base import antisymmetric as _antisym
from .formulation_base import component_first as _cf
from .formulation_base import matvec as _mvec
from .formulation_base import stack_last as _stack
from .formulation_base import transpose as _T
from .formulation_kernels import a_transpose_v as _a_t_v
from .formulation_kernels import (
    canonical_hamiltonian,
    canonical_rhs,
    geodesic_energy,
    geodesic_rhs,
    kinetic_energy,
    momentum_hamiltonian,
    momentum_rhs,
    velocity_rhs,
)
from .formulation_registry import register
from .gibbs_lagrangian import christoffel_of as _christoffel
from .gibbs_lagrangian import metric_derivative_of as _metric_derivative

__all__ = ["Canonical", "Momentum", "Velocity", "Geodesic", "MAX_GIBBS_NORM"]

#: largest |n| at which the Gibbs formulations evaluate their formulas (powers up to
#: n^6 appear: 1e50 keeps them, and their differences, far from overflow and underflow)
MAX_GIBBS_NORM = 1e50


def _check_gibbs_norm(n, name: str) -> None:
    """SingularChartError where |n| > MAX_GIBBS_NORM (a rotation within ~2e-50 rad of a half turn)."""
    big = np.max(np.abs(n), axis=-1) if n.size else np.zeros(0)
    if np.any(big > MAX_GIBBS_NORM / 2.0):
        nrm = np.sqrt(np.sum((n / MAX_GIBBS_NORM) ** 2, axis=-1)) * MAX_GIBBS_NORM
        worst = float(np.max(nrm))
        if worst > MAX_GIBBS_NORM:
            raise SingularChartError(
                f"{name}: |n| = {worst:.3g} exceeds {MAX_GIBBS_NORM:.0e}: the rotation is within "
                f"{2.0 / worst:.1e} rad of a half turn, the singularity of the Gibbs chart, where the "
                f"formulas overflow; re-centre the chart (eulerpoisson.attitude.gibbs_chart) or use the "
                f"'euler_poisson' formulation"
            )


class _GibbsFormulation(Formulation):
    r"""Common parts of the formulations whose first block is n.

    The formulas are evaluated for :math:`|\mathbf n|\le 10^{50}` only
    (:data:`MAX_GIBBS_NORM`); beyond, a
    :class:`~eulerpoisson.errors.SingularChartError`. The attitude
    conversions (:meth:`gibbs`, :meth:`quaternion`, :meth:`matrix`) take any
    finite n. Near the half turn the chart is ill-conditioned: a state
    :math:`\delta` rad from it has :math:`|\mathbf n|\approx 2/\delta`, and
    quantities computed from :math:`(\mathbf n, \boldsymbol\pi)` or
    :math:`(\mathbf n, \mathbf m)` carry relative errors up to about
    :math:`\varepsilon|\mathbf n|` (measured :math:`\varepsilon|\mathbf n|/10`
    for the energy; :math:`(\mathbf n, \boldsymbol\Omega)` keeps full
    accuracy); re-centre the chart where that matters.
    """

    def _check(self, state, what="state"):
        x = super()._check(state, what)
        _check_gibbs_norm(x[..., 0:3], f"{what} of the {self.name!r} formulation")
        return x

    def gibbs(self, state) -> np.ndarray:
        return Formulation._check(self, state)[..., 0:3].copy()

    def quaternion(self, state) -> np.ndarray:
        return quaternion_from_gibbs(Formulation._check(self, state)[..., 0:3])

    def matrix(self, state) -> np.ndarray:
        return matrix_from_gibbs(Formulation._check(self, state)[..., 0:3])

    def to_common(self, state):
        x = self._check(state)
        return quaternion_from_gibbs(x[..., 0:3]), self.omega(x)

    def _split(self, state):
        x = self._check(state)
        return x, _cf(x[..., 0:3]), _cf(x[..., 3:6])

    def _tau_n(self, x, t):
        """Body-frame torque at R(n) of the states x, (..., 3)."""
        return self._torque_at(self._time(t), matrix_from_gibbs(x[..., 0:3]))

    def potential_gradient(self, state, t=0.0) -> np.ndarray:
        r"""Closed-form :math:`\partial U/\partial\mathbf n = -2A(\mathbf n)\boldsymbol\tau`, shape (..., 3).

        See :func:`gibbs_potential_gradient`; zero for the free body.

        Raises
        ------
        InvalidInputError
            Wrong trailing shape or non-finite values of ``state`` or ``t``.
        """
        x = self._check(state)
        shape = np.broadcast_shapes(self._batch(x), self._time(t).shape) + (3,)
        if not self.torques:
            return np.zeros(shape)
        g = -2.0 * _mvec(conversion_matrix(x[..., 0:3]), self._tau_n(x, t))
        return np.broadcast_to(g, shape).copy()

    def _common_in(self, q, omega):
        n = gibbs_from_quaternion(q)
        _check_gibbs_norm(n, f"q for the {self.name!r} formulation")
        w = as_float_array(omega, "omega", (3,))
        n, w = np.broadcast_arrays(n, w)
        return n, w


class Canonical(_GibbsFormulation):
    r"""Canonical variables :math:`(\mathbf n, \boldsymbol\pi)` (paper eq. 1.14-1.19).

    .. math::
        H = \tfrac18(\tilde A\boldsymbol\pi)^T I^{-1}(\tilde A\boldsymbol\pi), \qquad
        P = \begin{pmatrix}0 & \mathbf 1\\ -\mathbf 1 & 0\end{pmatrix}, \qquad
        \mathbf m = \tfrac12\tilde A^T\boldsymbol\pi, \quad
        \boldsymbol\Omega = \tfrac12 I^{-1}\tilde A\boldsymbol\pi

    The vector field is the polynomial of :func:`canonical_rhs`
    (paper eq. 1.16 with :math:`\epsilon_{ijk}\pi_k` in place of the printed
    :math:`\epsilon_{ijk}n_k`). With a potential :math:`U(t, R)` (``torque=``),
    :math:`H = H_0 + U(t, R(\mathbf n))` and

    .. math:: \dot{\boldsymbol\pi} = -\frac{\partial H_0}{\partial\mathbf n}
              - \frac{\partial U}{\partial\mathbf n}, \qquad
              \frac{\partial U}{\partial\mathbf n} = -2A(\mathbf n)\boldsymbol\tau

    (:meth:`potential_gradient`), with the canonical Poisson tensor.
    """

    name = "canonical"
    title = "canonical (n, pi)"
    variables = ("n1", "n2", "n3", "pi1", "pi2", "pi3")
    layout = {"n": slice(0, 3), "pi": slice(3, 6)}
    block_shapes = {"n": (3,), "pi": (3,)}
    dimension = 6
    rank = 6
    equations = {
        "vector_field": "1.16 (corrected: eps_ijk pi_k)",
        "hamiltonian": "1.15",
        "poisson_tensor": "1.15.1",
        "integrals": "1.15, 1.17, 1.19, 1.23",
        "momenta": "1.14",
        "potential_gradient": "1.11-1.12 (dU/dn = -2 A tau)",
    }

    def vector_field(self, state, t=0.0) -> np.ndarray:
        x, n, p = self._split(state)
        nd, pd = canonical_rhs(n, p, self._Iinvcf)
        out = _stack(nd + pd)
        if self.torques:
            # pi-dot gains -dU/dn = 2 A tau
            out = _add_block(out, slice(3, 6), 2.0 * _mvec(conversion_matrix(x[..., 0:3]), self._tau_n(x, t)))
        return out

    def hamiltonian(self, state, t=0.0) -> np.ndarray:
        x, n, p = self._split(state)
        H = self._with_potential(canonical_hamiltonian(n, p, self._Iinvcf), x, t)
        return np.broadcast_to(H, np.broadcast_shapes(self._batch(x), np.shape(H))).copy()

    def poisson_tensor(self, state) -> np.ndarray:
        x = self._check(state)
        P = np.zeros((6, 6))
        P[:3, 3:] = np.eye(3)
        P[3:, :3] = -np.eye(3)
        return np.broadcast_to(P, self._batch(x) + (6, 6)).copy()

    def poisson_determinant(self, state) -> np.ndarray:
        x = self._check(state)
        return np.ones(self._batch(x))

    def omega(self, state) -> np.ndarray:
        x = self._check(state)
        u = _mvec(inverse_conversion_matrix(x[..., :3]), x[..., 3:6])
        return 0.5 * _mvec(self._Iinv, u)

    def spatial_momentum(self, state) -> np.ndarray:
        r""":math:`\mathbf m = \tfrac12\tilde A^T\boldsymbol\pi` (eq. 1.17), (..., 3)."""
        x = self._check(state)
        m = 0.5 * _mvec(_T(inverse_conversion_matrix(x[..., :3])), x[..., 3:6])
        return np.broadcast_to(m, self._batch(x) + (3,)).copy()

    def from_common(self, q, omega) -> np.ndarray:
        n, w = self._common_in(q, omega)
        p = 2.0 * _mvec(conversion_matrix(n), _mvec(self._I, w))
        n = np.broadcast_to(n, p.shape)
        return np.concatenate([n, p], -1)


class Momentum(_GibbsFormulation):
    r"""Noncanonical variables :math:`(\mathbf n, \mathbf m)` (paper eq. 1.20-1.23).

    .. math::
        \dot{\mathbf n} = \tfrac12\tilde A^T I^{-1}R^T\mathbf m,\quad \dot{\mathbf m} = 0,\quad
        H = \tfrac12\mathbf m^T RI^{-1}R^T\mathbf m

    .. math::
        \{n_i, n_j\} = 0,\quad \{n_i, m_j\} = \tfrac12\tilde A_{ij},\quad
        \{m_i, m_j\} = \epsilon_{ijk}m_k, \qquad
        \det P = \frac{(1+\mathbf n^2)^4}{64}

    The paper's :math:`\{m_i,m_j\}` of eq. 1.21 equals :math:`\epsilon_{ijk}m_k`
    because :math:`\hat n_{ij}n_k + \mathrm{cycle} = \mathbf n^2\epsilon_{ijk}`.
    """

    name = "momentum"
    title = "noncanonical (n, m)"
    variables = ("n1", "n2", "n3", "m1", "m2", "m3")
    layout = {"n": slice(0, 3), "m": slice(3, 6)}
    block_shapes = {"n": (3,), "m": (3,)}
    dimension = 6
    rank = 6
    equations = {
        "vector_field": "1.20",
        "hamiltonian": "footnote to 1.20, 1.25",
        "poisson_tensor": "1.21 (simplified with 1.22)",
        "integrals": "1.17, 1.19, 1.23",
    }

    def vector_field(self, state, t=0.0) -> np.ndarray:
        x, n, m = self._split(state)
        nd, md = momentum_rhs(n, m, self._Iinvcf)
        out = _stack(nd + md)
        if self.torques:
            # m-dot gains the space-frame torque R tau = -1/2 Atilde^T dU/dn
            R = matrix_from_gibbs(x[..., 0:3])
            out = _add_block(out, slice(3, 6), _mvec(R, self._torque_at(self._time(t), R)))
        return out

    def hamiltonian(self, state, t=0.0) -> np.ndarray:
        x, n, m = self._split(state)
        H = self._with_potential(momentum_hamiltonian(n, m, self._Iinvcf), x, t)
        return np.broadcast_to(H, np.broadcast_shapes(self._batch(x), np.shape(H))).copy()

    def poisson_tensor(self, state) -> np.ndarray:
        x = self._check(state)
        At = inverse_conversion_matrix(x[..., :3])
        P = np.zeros(self._batch(x) + (6, 6))
        P[..., :3, 3:] = 0.5 * At
        P[..., 3:, :3] = -0.5 * _T(At)
        P[..., 3:, 3:] = -skew(x[..., 3:6])
        return P

    def poisson_determinant(self, state) -> np.ndarray:
        x = self._check(state)
        s = 1.0 + np.sum(x[..., :3] ** 2, -1)
        return np.broadcast_to(s**4 / 64.0, self._batch(x)).copy()

    def omega(self, state) -> np.ndarray:
        x = self._check(state)
        R = matrix_from_gibbs(x[..., :3])
        return _mvec(self._Iinv, _mvec(_T(R), x[..., 3:6]))

    def spatial_momentum(self, state) -> np.ndarray:
        x = self._check(state)
        return np.broadcast_to(x[..., 3:6], self._batch(x) + (3,)).copy()

    def from_common(self, q, omega) -> np.ndarray:
        n, w = self._common_in(q, omega)
        m = _mvec(matrix_from_gibbs(n), _mvec(self._I, w))
        n = np.broadcast_to(n, m.shape)
        return np.concatenate([n, m], -1)


class Velocity(_GibbsFormulation):
    r"""Variables :math:`(\mathbf n, \boldsymbol\Omega)` (paper eq. 1.26-1.30).

    .. math::
        \dot{\mathbf n} = \tfrac12\tilde A^T\boldsymbol\Omega,\quad
        I\dot{\boldsymbol\Omega} = (I\boldsymbol\Omega)\times\boldsymbol\Omega,\quad
        H = \tfrac12\boldsymbol\Omega^T I\boldsymbol\Omega

    .. math::
        \{n_i, \Omega_j\} = \tfrac12(\tilde A^T I^{-1})_{ij},\quad
        \{\Omega_i, \Omega_j\} = -I^{-1}_{ia}I^{-1}_{jb}\epsilon_{abc}M_c
        = (I^{-1}[\mathbf M]_\times I^{-1})_{ij},\qquad
        \det P = \frac{(1+\mathbf n^2)^4}{64(\det I)^2}
    """

    name = "velocity"
    title = "(n, Omega)"
    variables = ("n1", "n2", "n3", "Omega1", "Omega2", "Omega3")
    layout = {"n": slice(0, 3), "Omega": slice(3, 6)}
    block_shapes = {"n": (3,), "Omega": (3,)}
    dimension = 6
    rank = 6
    equations = {
        "vector_field": "1.30",
        "hamiltonian": "1.27",
        "poisson_tensor": "1.28 (simplified with 1.29)",
        "integrals": "1.24-1.25",
        "momenta": "1.26",
    }

    def vector_field(self, state, t=0.0) -> np.ndarray:
        x, n, W = self._split(state)
        nd, Wd = velocity_rhs(n, W, self._Icf, self._Iinvcf)
        out = _stack(nd + Wd)
        if self.torques:
            out = _add_block(out, slice(3, 6), _mvec(self._Iinv, self._tau_n(x, t)))
        return out

    def hamiltonian(self, state, t=0.0) -> np.ndarray:
        x, n, W = self._split(state)
        H = self._with_potential(kinetic_energy(W, self._Icf), x, t)
        return np.broadcast_to(H, np.broadcast_shapes(self._batch(x), np.shape(H))).copy()

    def poisson_tensor(self, state) -> np.ndarray:
        x = self._check(state)
        K = 0.5 * _T(inverse_conversion_matrix(x[..., :3])) @ self._Iinv
        M = _mvec(self._I, x[..., 3:6])
        P = np.zeros(self._batch(x) + (6, 6))
        P[..., :3, 3:] = K
        P[..., 3:, :3] = -_T(K)
        P[..., 3:, 3:] = _antisym(self._Iinv @ skew(M) @ self._Iinv)
        return P

    def poisson_determinant(self, state) -> np.ndarray:
        x = self._check(state)
        s = 1.0 + np.sum(x[..., :3] ** 2, -1)
        return np.broadcast_to(s**4 / (64.0 * np.linalg.det(self._I) ** 2), self._batch(x)).copy()

    def omega(self, state) -> np.ndarray:
        x = self._check(state)
        return x[..., 3:6].copy()

    def from_common(self, q, omega) -> np.ndarray:
        n, w = self._common_in(q, omega)
        return np.concatenate([n, w], -1)


class Geodesic(_GibbsFormulation):
    r"""Lagrangian (geodesic) variables :math:`(\mathbf n, \dot{\mathbf n})` (paper eq. 1.11-1.14).

    Geodesics of :math:`G = 4AIA^T`: :math:`\ddot n^i + \Gamma^i_{jk}(\mathbf n)\dot n^j\dot n^k = 0`
    (see :func:`christoffel`). Those through :math:`\mathbf n = 0` are the
    body's motions from the identity; by left invariance every geodesic is a
    body motion (from :math:`R(\mathbf n_0)`).

    The "Hamiltonian" is the energy :math:`E = \tfrac12\dot{\mathbf n}^TG\dot{\mathbf n}`
    (equal to :math:`L`), plus :math:`U` with a potential (then
    :math:`L = E - U` and the motion is no longer geodesic: :math:`\ddot{\mathbf n}`
    gains :math:`-G^{-1}\partial U/\partial\mathbf n`). The Poisson tensor is the canonical one pulled
    back by :math:`\boldsymbol\pi = G(\mathbf n)\dot{\mathbf n}`:

    .. math::
        P = \begin{pmatrix}0 & G^{-1}\\ -G^{-1} & G^{-1}(C^T - C)G^{-1}\end{pmatrix},\qquad
        C_{lk} = \partial_k G_{lm}\,\dot n_m,\qquad
        \det P = \left(\frac{(1+\mathbf n^2)^4}{64\det I}\right)^2
    """

    name = "geodesic"
    title = "geodesic (n, ndot)"
    variables = ("n1", "n2", "n3", "ndot1", "ndot2", "ndot3")
    layout = {"n": slice(0, 3), "ndot": slice(3, 6)}
    block_shapes = {"n": (3,), "ndot": (3,)}
    dimension = 6
    rank = 6
    equations = {
        "vector_field": "1.13 (Euler-Lagrange / geodesic equation)",
        "hamiltonian": "1.13",
        "poisson_tensor": "1.14, 1.15.1 (pulled back)",
        "metric": "1.13",
        "integrals": "1.11, 1.24",
    }

    def vector_field(self, state, t=0.0) -> np.ndarray:
        x, n, v = self._split(state)
        nd, a = geodesic_rhs(n, v, self._Icf, self._Iinvcf)
        out = _stack(nd + a)
        if self.torques:
            # Euler-Lagrange with L = E - U: nddot gains -G^{-1} dU/dn = 1/2 Atilde^T I^{-1} tau
            K = _T(inverse_conversion_matrix(x[..., 0:3])) @ self._Iinv
            out = _add_block(out, slice(3, 6), 0.5 * _mvec(K, self._tau_n(x, t)))
        return out

    def hamiltonian(self, state, t=0.0) -> np.ndarray:
        x, n, v = self._split(state)
        H = self._with_potential(geodesic_energy(n, v, self._Icf), x, t)
        return np.broadcast_to(H, np.broadcast_shapes(self._batch(x), np.shape(H))).copy()

    def lagrangian(self, state, t=0.0) -> np.ndarray:
        r"""Lagrangian :math:`L = \tfrac12\dot{\mathbf n}^TG\dot{\mathbf n} - U(t, R(\mathbf n))` (eq. 1.13 with a potential), shape (...)."""
        x, n, v = self._split(state)
        E = geodesic_energy(n, v, self._Icf)
        L = E - self._potential_at(self._time(t), self.matrix(x)) if self.torques else E
        return np.broadcast_to(L, np.broadcast_shapes(self._batch(x), np.shape(L))).copy()

    def metric(self, state) -> np.ndarray:
        """:math:`G(\\mathbf n) = 4AIA^T`, (..., 3, 3)."""
        x = self._check(state)
        return metric(x[..., :3], self._I)

    def christoffel(self, state) -> np.ndarray:
        """:math:`\\Gamma^i_{jk}(\\mathbf n)`, (..., 3, 3, 3) (see :func:`christoffel`)."""
        x = self._check(state)
        return _christoffel(x[..., :3], self._I, self._Iinv)

    def momenta(self, state) -> np.ndarray:
        """Canonical momenta :math:`\\boldsymbol\\pi = G\\dot{\\mathbf n}`, (..., 3)."""
        x = self._check(state)
        return _mvec(metric(x[..., :3], self._I), x[..., 3:6])

    def poisson_tensor(self, state) -> np.ndarray:
        x = self._check(state)
        n, v = x[..., :3], x[..., 3:6]
        Ginv = inverse_metric(n, self._I)
        dG = _metric_derivative(n, self._I)
        C = np.einsum("...klm,...m->...lk", dG, v)
        Ginv = np.broadcast_to(Ginv, self._batch(x) + (3, 3))
        P = np.zeros(self._batch(x) + (6, 6))
        P[..., :3, 3:] = Ginv
        P[..., 3:, :3] = -_T(Ginv)
        P[..., 3:, 3:] = _antisym(Ginv @ (_T(C) - C) @ Ginv)
        return P

    def poisson_determinant(self, state) -> np.ndarray:
        x = self._check(state)
        s = 1.0 + np.sum(x[..., :3] ** 2, -1)
        return np.broadcast_to((s**4 / (64.0 * np.linalg.det(self._I))) ** 2, self._batch(x)).copy()

    def omega(self, state) -> np.ndarray:
        x = self._check(state)
        v = _stack(_a_t_v(_cf(x[..., :3]), _cf(x[..., 3:6])))
        return 2.0 * v

    def from_common(self, q, omega) -> np.ndarray:
        n, w = self._common_in(q, omega)
        v = 0.5 * _mvec(_T(inverse_conversion_matrix(n)), w)
        return np.concatenate([n, v], -1)


register("canonical", Canonical)
register("momentum", Momentum)
register("velocity", Velocity)
register("geodesic", Geodesic)
