r"""The Euler-Poisson formulation in :math:`(R, \boldsymbol\Omega)` (part of :mod:`.formulations`).

Paper eq. 1.4-1.5, 1.25: the rotation matrix and the body angular velocity,
12 variables, a Poisson tensor of rank 6. Registered as ``"euler-poisson"``
and re-exported by :mod:`eulerpoisson.model.formulations`.

Examples
--------
>>> EulerPoisson([1.0, 2.0, 3.0]).dimension
12
"""

from __future__ import annotations

import numpy as np

from ..attitude.core import (
    matrix_from_quaternion,
    quaternion_from_matrix,
    skew,
)
from ..util.validate import as_float_array
from .formulation_base import GENERATORS as _GEN
from .formulation_base import Formulation
from .formulation_base import add_block as _add_block
from .formulation_base import antisymmetric as _antisym
from .formulation_base import component_first as _cf
from .formulation_base import component_first_matrix as _cf2
from .formulation_base import matvec as _mvec
from .formulation_base import stack_last as _stack
from .formulation_base import transpose as _T
from .formulation_kernels import euler_poisson_rhs, kinetic_energy
from .formulation_registry import register

__all__ = ["EulerPoisson"]


class EulerPoisson(Formulation):
    r"""Euler-Poisson equations in :math:`(R, \boldsymbol\Omega)` (paper eq. 1.4-1.5).

    State (..., 12): the rotation matrix :math:`R` flattened row-major
    (``R11, R12, ..., R33``) then :math:`\boldsymbol\Omega`.

    .. math:: \dot R = R[\boldsymbol\Omega]_\times,\quad I\dot{\boldsymbol\Omega} = (I\boldsymbol\Omega)\times\boldsymbol\Omega,
              \quad H = \tfrac12\boldsymbol\Omega^T I\boldsymbol\Omega

    Poisson tensor: the natural 12x12 Lie-Poisson tensor (dual of the
    semidirect product :math:`so(3)\ltimes(\mathbb R^3)^3`, the rows of
    :math:`R` being vectors under body rotations), in :math:`(R, \boldsymbol\Omega)`:

    .. math::
        \{R_{ij}, R_{kl}\} = 0,\quad \{R_{ij}, \Omega_l\} = (R[\mathbf e_k]_\times)_{ij}I^{-1}_{kl},
        \quad \{\Omega_i, \Omega_j\} = (I^{-1}[\mathbf M]_\times I^{-1})_{ij}

    with :math:`\mathbf M = I\boldsymbol\Omega`. It satisfies the Jacobi
    identity on all of :math:`\mathbb R^{12}` and has rank 6: the six
    Casimirs :math:`(RR^T)_{ij}` (:meth:`casimirs`) cut out
    :math:`SO(3)\times\mathbb R^3`, the symplectic leaf on which it is the
    canonical structure pushed forward from :math:`(\mathbf n, \boldsymbol\pi)`.
    """

    name = "euler-poisson"
    title = "Euler-Poisson (R, Omega)"
    variables = tuple(f"R{i}{j}" for i in range(1, 4) for j in range(1, 4)) + ("Omega1", "Omega2", "Omega3")
    layout = {"R": slice(0, 9), "Omega": slice(9, 12)}
    block_shapes = {"R": (3, 3), "Omega": (3,)}
    dimension = 12
    rank = 6
    equations = {
        "vector_field": "1.4, 1.5",
        "hamiltonian": "1.25",
        "poisson_tensor": "1.4-1.5 (Lie-Poisson; not printed)",
        "integrals": "1.24-1.25",
    }

    def _split(self, state):
        x = self._check(state)
        R = x[..., :9].reshape(x.shape[:-1] + (3, 3))
        return x, R, x[..., 9:12]

    def vector_field(self, state, t=0.0) -> np.ndarray:
        x, R, W = self._split(state)
        Rd, Wd = euler_poisson_rhs(_cf2(R), _cf(W), self._Icf, self._Iinvcf)
        out = _stack(Rd[0] + Rd[1] + Rd[2] + Wd)
        if self.torques:
            tau = self._torque_at(self._time(t), R)
            out = _add_block(out, slice(9, 12), _mvec(self._Iinv, tau))
        return out

    def hamiltonian(self, state, t=0.0) -> np.ndarray:
        x, R, W = self._split(state)
        H = self._with_potential(kinetic_energy(_cf(W), self._Icf), x, t)
        return np.broadcast_to(H, np.broadcast_shapes(self._batch(x), np.shape(H))).copy()

    def poisson_tensor(self, state) -> np.ndarray:
        x, R, W = self._split(state)
        shape = self._batch(x)
        RE = np.einsum("...ia,kaj->...ijk", R, _GEN)  # (R E_k)_ij
        B = np.einsum("...ijk,...kl->...ijl", RE, self._Iinv)
        B = np.broadcast_to(B, shape + (3, 3, 3)).reshape(shape + (9, 3))
        M = _mvec(self._I, W)
        C = _antisym(self._Iinv @ skew(M) @ self._Iinv)
        P = np.zeros(shape + (12, 12))
        P[..., :9, 9:] = B
        P[..., 9:, :9] = -_T(B)
        P[..., 9:, 9:] = C
        return P

    def poisson_determinant(self, state) -> np.ndarray:
        x = self._check(state)
        return np.zeros(self._batch(x))

    def casimirs(self, state) -> np.ndarray:
        """The six Casimirs :math:`(RR^T)_{ij}`, ``i <= j`` (order 11, 12, 13, 22, 23, 33), (..., 6)."""
        x, R, W = self._split(state)
        RRt = R @ _T(R)
        iu = np.triu_indices(3)
        return np.broadcast_to(RRt[..., iu[0], iu[1]], self._batch(x) + (6,)).copy()

    def to_common(self, state):
        """``(q, Omega)``; ``R`` must be a rotation matrix (within 1e-6)."""
        x, R, W = self._split(state)
        return quaternion_from_matrix(R), W.copy()

    def from_common(self, q, omega) -> np.ndarray:
        R = matrix_from_quaternion(q)
        w = as_float_array(omega, "omega", (3,))
        return self.pack(R=R, Omega=w)

    def matrix(self, state) -> np.ndarray:
        return self._split(state)[1].copy()

    def omega(self, state) -> np.ndarray:
        return self._split(state)[2].copy()


register("euler-poisson", EulerPoisson)
