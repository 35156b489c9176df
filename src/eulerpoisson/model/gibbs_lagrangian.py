r"""The Lagrangian side of the Gibbs chart, batched in NumPy (part of :mod:`.formulations`).

The metric :math:`G = 4AIA^T` of the paper's Lagrangian in the Gibbs vector
(eq. 1.11, 1.13), its derivatives, the Christoffel symbols, the Lagrangian,
the canonical momentum and the geodesic acceleration, for any symmetric
positive-definite inertia tensor; re-exported by
:mod:`eulerpoisson.model.formulations`.

Examples
--------
>>> import numpy as np
>>> float(lagrangian(np.zeros(3), [1.0, 0.0, 0.0], [1.0, 2.0, 3.0]))  # 1/2 ndot^T G(0) ndot, G(0) = 4 I
2.0
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..attitude.core import (
    conversion_matrix,
    inverse_conversion_matrix,
    inverse_metric,
    metric,
)
from ..util.validate import as_float_array
from .formulation_base import GENERATORS as _GEN
from .formulation_base import as_body as _as_body
from .formulation_base import component_first as _cf
from .formulation_base import component_first_matrix as _cf2
from .formulation_base import matvec as _mvec
from .formulation_base import stack_last as _stack
from .formulation_base import transpose as _T
from .formulation_kernels import geodesic_energy, geodesic_rhs

__all__ = [
    "metric_derivative",
    "christoffel",
    "christoffel_from_metric",
    "lagrangian",
    "canonical_momentum",
    "geodesic_acceleration",
    "metric_derivative_of",
    "christoffel_of",
]


# ---------------------------------------------------------------------------
# Lagrangian side (batched numpy)
# ---------------------------------------------------------------------------
def metric_derivative(n: ArrayLike, inertia: ArrayLike) -> NDArray[np.float64]:
    r"""Derivatives :math:`\partial_k G_{ij}` of the metric :math:`G = 4AIA^T`.

    With :math:`\partial_k A = [\mathbf e_k]_\times/s - 2n_kA/s` (:math:`s = 1+\mathbf n^2`),

    .. math::
        \partial_k G = \frac4s\left(X_k + X_k^T\right) - \frac{4n_k}{s}G,
        \qquad X_k = [\mathbf e_k]_\times I A^T .

    Parameters
    ----------
    n : array_like, shape (..., 3)
    inertia : RigidBody or array_like, shape (..., 3) or (..., 3, 3)

    Returns
    -------
    ndarray, shape (..., 3, 3, 3)
        ``dG[..., k, i, j]`` :math:`= \partial G_{ij}/\partial n_k`.

    Raises
    ------
    InvalidInputError
        Wrong shape or non-finite ``n``.
    InvalidInertiaError
        Not a physical inertia tensor.

    References
    ----------
    Paper eq. 1.12-1.13.
    """
    n = as_float_array(n, "n", (3,))
    body = _as_body(inertia)
    return metric_derivative_of(n, body.inertia)


def metric_derivative_of(n, I):
    """:func:`metric_derivative` of the arrays ``n`` (..., 3) and ``I`` (..., 3, 3) (no checks)."""
    s = 1.0 + np.sum(n * n, -1)
    A = conversion_matrix(n)
    IAt = I @ _T(A)
    X = np.einsum("kab,...bc->...kac", _GEN, IAt)
    G = 4.0 * A @ IAt
    s4 = (4.0 / s)[..., None, None, None]
    return s4 * (X + _T(X)) - s4 * n[..., :, None, None] * G[..., None, :, :]


def christoffel(n: ArrayLike, inertia: ArrayLike) -> NDArray[np.float64]:
    r"""Christoffel symbols :math:`\Gamma^i_{jk}(\mathbf n)` of :math:`G = 4AIA^T`, closed form.

    .. math::
        \Gamma^i_{jk} = -\frac{n_j\delta_{ik} + n_k\delta_{ij}}{1+\mathbf n^2}
        - \left[\tilde A^T I^{-1}\left((I\mathbf a_j)\times\mathbf a_k
        + (I\mathbf a_k)\times\mathbf a_j\right)\right]_i

    where :math:`\mathbf a_j = A^T\mathbf e_j` is column :math:`j` of :math:`A^T`
    (:math:`\boldsymbol\Omega = 2\sum_j\mathbf a_j\dot n_j`). Derivation: the
    Euler-Lagrange equations of :math:`L = \tfrac12 G_{ij}\dot n_i\dot n_j`
    are Euler's equations; differentiating
    :math:`\dot{\mathbf n} = \tfrac12\tilde A^T\boldsymbol\Omega` gives
    :math:`\ddot{\mathbf n} = 2(\mathbf n\cdot\dot{\mathbf n})\dot{\mathbf n}/s
    + \tfrac12\tilde A^T\dot{\boldsymbol\Omega}` (the kinematic terms collapse
    because :math:`\mathbf n\cdot\boldsymbol\Omega = 2\mathbf n\cdot\dot{\mathbf n}/s`,
    :math:`\dot{\mathbf n}\cdot\boldsymbol\Omega = 2\dot{\mathbf n}^2/s`), and
    :math:`\Gamma` is the symmetrized coefficient of
    :math:`-\ddot{\mathbf n}`. Equals the Levi-Civita formula
    :func:`christoffel_from_metric`.

    Parameters
    ----------
    n : array_like, shape (..., 3)
    inertia : RigidBody or array_like, shape (..., 3) or (..., 3, 3)

    Returns
    -------
    ndarray, shape (..., 3, 3, 3)
        ``Gamma[..., i, j, k]`` :math:`= \Gamma^i_{jk}`, symmetric in ``j, k``.

    Raises
    ------
    InvalidInputError, InvalidInertiaError

    References
    ----------
    Paper eq. 1.11-1.14.
    """
    n = as_float_array(n, "n", (3,))
    body = _as_body(inertia)
    return christoffel_of(n, body.inertia, body.inertia_inv)


def christoffel_of(n, I, Iinv):
    """:func:`christoffel` of the arrays ``n``, ``I`` and its inverse ``Iinv`` (no checks)."""
    s = 1.0 + np.sum(n * n, -1)
    A = conversion_matrix(n)  # rows of A are the columns a_j of A^T
    IA_cols = A @ I  # row j: (I a_j)^T  (I symmetric)
    X = np.cross(IA_cols[..., :, None, :], A[..., None, :, :])  # (..., j, k, 3)
    K = _T(inverse_conversion_matrix(n)) @ Iinv  # Ã^T I^-1
    B = np.einsum("...ia,...jka->...ijk", K, X)
    d = np.eye(3)
    kin = (n[..., None, :, None] * d[:, None, :] + n[..., None, None, :] * d[:, :, None]) / s[..., None, None, None]
    return -(B + np.swapaxes(B, -1, -2)) - kin


def christoffel_from_metric(n: ArrayLike, inertia: ArrayLike, dG: ArrayLike | None = None) -> NDArray[np.float64]:
    r"""Christoffel symbols by the Levi-Civita formula (reference for :func:`christoffel`).

    .. math:: \Gamma^i_{jk} = \tfrac12 G^{il}\left(\partial_j G_{lk} + \partial_k G_{lj} - \partial_l G_{jk}\right)

    Parameters
    ----------
    n : array_like, shape (..., 3)
    inertia : RigidBody or array_like
    dG : array_like, shape (..., 3, 3, 3), optional
        Metric derivatives ``dG[..., k, i, j]``; default :func:`metric_derivative`.
        Pass finite differences to check the closed form independently.

    Returns
    -------
    ndarray, shape (..., 3, 3, 3)

    Raises
    ------
    InvalidInputError, InvalidInertiaError
    """
    n = as_float_array(n, "n", (3,))
    body = _as_body(inertia)
    dG = metric_derivative_of(n, body.inertia) if dG is None else as_float_array(dG, "dG", (3, 3, 3))
    first = 0.5 * (np.einsum("...jlk->...ljk", dG) + np.einsum("...klj->...ljk", dG) - dG)  # Γ_{l jk}
    Ginv = inverse_metric(n, body.inertia)
    return np.einsum("...il,...ljk->...ijk", Ginv, first)


def lagrangian(n: ArrayLike, ndot: ArrayLike, inertia: ArrayLike) -> NDArray[np.float64]:
    r"""The paper's Lagrangian :math:`L = \tfrac12 G_{ij}\dot n_i\dot n_j` (eq. 1.13).

    .. math:: L = \frac{2}{(1+\mathbf n^2)^2}\,(\dot{\mathbf n}-\mathbf n\times\dot{\mathbf n})^T I
              (\dot{\mathbf n}-\mathbf n\times\dot{\mathbf n})
              = \tfrac12\boldsymbol\Omega^T I\boldsymbol\Omega

    Parameters
    ----------
    n, ndot : array_like, shape (..., 3)
    inertia : RigidBody or array_like

    Returns
    -------
    ndarray, shape (...)

    Raises
    ------
    InvalidInputError, InvalidInertiaError
    """
    n = as_float_array(n, "n", (3,))
    v = as_float_array(ndot, "ndot", (3,))
    body = _as_body(inertia)
    return np.asarray(geodesic_energy(_cf(n), _cf(v), _cf2(body.inertia)))


def canonical_momentum(n: ArrayLike, ndot: ArrayLike, inertia: ArrayLike) -> NDArray[np.float64]:
    r"""Canonical momentum :math:`\boldsymbol\pi = G\dot{\mathbf n} = 2AI\boldsymbol\Omega` (eq. 1.14, 1.26).

    Parameters
    ----------
    n, ndot : array_like, shape (..., 3)
    inertia : RigidBody or array_like

    Returns
    -------
    ndarray, shape (..., 3)

    Raises
    ------
    InvalidInputError, InvalidInertiaError
    """
    n = as_float_array(n, "n", (3,))
    v = as_float_array(ndot, "ndot", (3,))
    body = _as_body(inertia)
    return _mvec(metric(n, body.inertia), v)


def geodesic_acceleration(n: ArrayLike, ndot: ArrayLike, inertia: ArrayLike) -> NDArray[np.float64]:
    r""":math:`\ddot{\mathbf n} = -\Gamma(\dot{\mathbf n}, \dot{\mathbf n})` (see :func:`geodesic_rhs`).

    Parameters
    ----------
    n, ndot : array_like, shape (..., 3)
    inertia : RigidBody or array_like

    Returns
    -------
    ndarray, shape (..., 3)

    Raises
    ------
    InvalidInputError, InvalidInertiaError
    """
    n = as_float_array(n, "n", (3,))
    v = as_float_array(ndot, "ndot", (3,))
    body = _as_body(inertia)
    _, a = geodesic_rhs(_cf(n), _cf(v), _cf2(body.inertia), _cf2(body.inertia_inv))
    return _stack(a)
