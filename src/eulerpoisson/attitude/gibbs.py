r"""The paper's rotation vector: the Gibbs vector n = k tan(alpha/2), its charts and matrices.

The paper parametrizes a rotation by the *Gibbs vector* (paper eq. 1.8)

.. math:: \mathbf n = \mathbf k \tan(\alpha/2), \qquad 0 \le \alpha < \pi,

which is the vector part of a unit quaternion divided by its scalar part,
:math:`\mathbf n = \mathbf q/q_0` (footnote to eq. 1.9). This module converts
between the Gibbs vector, unit quaternions and rotation matrices, all batched
over leading axes, composes and inverts Gibbs vectors, and provides the
paper's matrices :math:`A(\mathbf n)`, :math:`\tilde A(\mathbf n)` (eq. 1.12),
the kinematic maps of eq. 1.11 and eq. 1.30, and the metric
:math:`G(\mathbf n)` (eq. 1.13-1.14). The conversions between the Gibbs vector
and axis-angle, rotation vectors and MRPs are in :mod:`.rotvec`, those with
Euler angles in :mod:`.euler`.

The global Gibbs vector is infinite at :math:`\alpha=\pi` (``w = 0``):
converting such an attitude raises :class:`~eulerpoisson.errors.SingularChartError`.
A *chart* (:func:`gibbs_chart`, :func:`quaternion_from_chart`) writes
:math:`R = R_0 R(\mathbf n)` around a reference attitude :math:`R_0` so a
trajectory can continue through :math:`\alpha=\pi`.

Numerical notes
---------------
* Gibbs vector <-> quaternion is well conditioned at every angle and is
  computed to a few ulps, also for :math:`|\mathbf n|` up to ``1e300``
  (power-of-two scaling, no overflow).
* Near :math:`\alpha = \pi` every conversion *into* the Gibbs vector from a
  representation whose components are :math:`O(1)` (matrix, rotation vector,
  Euler angles, MRP) has relative condition number about
  :math:`1/(\pi-\alpha)`: a rounding error ``eps`` in a matrix entry becomes a
  relative error ``eps/(pi - alpha)`` in ``n`` (about ``2e-9`` at
  ``pi - alpha = 1e-7``).
* Near the identity all conversions keep full *relative* accuracy of small
  vectors (no ``1 - cos`` cancellation).

References
----------
A. A. Deriglazov, *Geodesic motion on the symplectic leaf of SO(3) with
distorted e(3) algebra and Liouville integrability of a free rigid body*
(the paper), eqs. 1.7-1.14, 1.30.
M. D. Shuster, "A survey of attitude representations", J. Astronaut. Sci. 41
(1993) 439-517.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..errors import InvalidInputError, SingularChartError
from ..numerics.quaternion import qmul
from ..util.validate import as_float_array, check_broadcast
from .common import finite_result, first_index, outer, pow2_below, skew_unchecked
from .quaternion import CONJUGATE_SIGNS, as_quaternion, matrix_from_unit_quaternion, quaternion_from_matrix

if TYPE_CHECKING:  # for the annotations only: .attitude imports this module, never the reverse at run time
    from .attitude import Attitude

__all__ = [
    "quaternion_from_gibbs",
    "gibbs_from_quaternion",
    "matrix_from_gibbs",
    "gibbs_from_matrix",
    "gibbs_compose",
    "gibbs_inverse",
    "gibbs_chart",
    "quaternion_from_chart",
    "conversion_matrix",
    "inverse_conversion_matrix",
    "matrix_from_conversion",
    "omega_from_gibbs_rate",
    "gibbs_rate_from_omega",
    "metric",
    "inverse_metric",
]


# ---------------------------------------------------------------------------
# Gibbs vector (the paper's n) <-> quaternion and matrix
# ---------------------------------------------------------------------------
def quaternion_from_gibbs(n: ArrayLike) -> NDArray[np.float64]:
    r"""Unit quaternion (``w > 0``) of a Gibbs vector.

    .. math:: q = \frac{(1, \mathbf n)}{\sqrt{1+\mathbf n^2}}

    computed with a power-of-two prescaling so that very large
    :math:`|\mathbf n|` (angles close to :math:`\pi`, up to ``1e308``) neither
    overflow nor lose accuracy.

    Parameters
    ----------
    n : array_like, shape (..., 3)
        Gibbs vector :math:`\mathbf k\tan(\alpha/2)`.

    Returns
    -------
    ndarray, shape (..., 4)

    Raises
    ------
    InvalidInputError
        Wrong shape or non-finite values (an infinite ``n`` is the singular
        set of the chart: use a quaternion there).

    References
    ----------
    Paper eq. 1.8 and the footnote to eq. 1.9.

    Examples
    --------
    >>> import numpy as np
    >>> from eulerpoisson.attitude import quaternion_from_gibbs
    >>> print(np.round(quaternion_from_gibbs([0.0, 0.0, 1.0]), 12))   # tan(45 deg): 90 degrees about z
    [0.70710678 0.         0.         0.70710678]
    """
    n = as_float_array(n, "n", (3,))
    return _quaternion_from_gibbs(n)


def _quaternion_from_gibbs(n):
    big = np.max(np.abs(n), axis=-1)
    scale = np.where(big > 1.0, pow2_below(np.where(big > 1.0, big, 1.0)), 1.0)
    inv = 1.0 / scale  # exact; may underflow to 0 for |n| > 1e154, harmlessly
    ns = n / scale[..., None]
    with np.errstate(under="ignore"):
        nrm = np.sqrt(np.sum(ns * ns, -1) + inv * inv)
    return np.concatenate([(inv / nrm)[..., None], ns / nrm[..., None]], -1)


def _singular_message(what: str, where: str = "") -> str:
    return (
        f"{what}{where} has rotation angle alpha = pi (quaternion w = 0), where the global Gibbs "
        "vector n = k tan(alpha/2) is infinite; keep the quaternion (Attitude.as_quaternion) or "
        "use a local chart R = R0 R(n): gibbs_chart(q, reference) / Attitude.as_chart(reference)"
    )


def gibbs_from_unit_quaternion(q, what="the attitude"):
    """Gibbs vectors of already normalized quaternions; a SingularChartError naming ``what`` at w = 0."""
    w = q[..., 0]
    with np.errstate(divide="ignore", over="ignore", invalid="ignore"):
        n = q[..., 1:] / w[..., None]
    bad = (w == 0) | ~np.all(np.isfinite(n), axis=-1)
    if np.any(bad):
        raise SingularChartError(_singular_message(what, first_index(bad)))
    return n


def gibbs_from_quaternion(q: ArrayLike) -> NDArray[np.float64]:
    r"""Gibbs vector :math:`\mathbf n = (x, y, z)/w` of a quaternion.

    The result does not depend on the sign or the norm of ``q``; it has a
    relative accuracy of a few ulps at every angle.

    Parameters
    ----------
    q : array_like, shape (..., 4)

    Returns
    -------
    ndarray, shape (..., 3)

    Raises
    ------
    SingularChartError
        If ``w = 0`` (rotation angle :math:`\pi`) or ``|n|`` would overflow:
        keep the quaternion, or use :func:`gibbs_chart` with a reference.
    InvalidInputError
        Wrong shape, non-finite values or a zero quaternion.

    References
    ----------
    Paper, footnote to eq. 1.9, and eq. 1.8.

    Examples
    --------
    >>> import numpy as np
    >>> from eulerpoisson.attitude import gibbs_from_quaternion
    >>> print(gibbs_from_quaternion([0.5, 0.5, 0.0, 0.0]))        # n = (x, y, z) / w
    [1. 0. 0.]
    >>> gibbs_from_quaternion([0.0, 1.0, 0.0, 0.0])               # 180 degrees: n is infinite
    Traceback (most recent call last):
        ...
    eulerpoisson.errors.SingularChartError: the attitude has rotation angle alpha = pi (quaternion w = 0), ...
    """
    return gibbs_from_unit_quaternion(as_quaternion(q))


def matrix_from_gibbs(n: ArrayLike) -> NDArray[np.float64]:
    r"""The paper's rotation matrix :math:`R(\mathbf n)` (eq. 1.9).

    .. math::
        R_{ij}(\mathbf n) = \frac{(1-\mathbf n^2)\delta_{ij} + 2 n_i n_j - 2\epsilon_{ijk}n_k}{1+\mathbf n^2}

    Evaluated through the unit quaternion of ``n`` (same formula, divided by
    :math:`1+\mathbf n^2` first), which is exact in the limit
    :math:`|\mathbf n|\to\infty` and does not overflow (``n = 1e200`` gives
    the rotation by :math:`\pi`).

    Parameters
    ----------
    n : array_like, shape (..., 3)

    Returns
    -------
    ndarray, shape (..., 3, 3)

    Raises
    ------
    InvalidInputError
        Wrong shape or non-finite values.

    References
    ----------
    Paper eq. 1.9 (equivalently eq. 1.7 with eq. 1.8).

    Examples
    --------
    >>> import numpy as np
    >>> from eulerpoisson.attitude import matrix_from_gibbs
    >>> print(np.round(matrix_from_gibbs([0.0, 0.0, 1.0]), 12) + 0.0)   # 90 degrees about z
    [[ 0. -1.  0.]
     [ 1.  0.  0.]
     [ 0.  0.  1.]]
    """
    n = as_float_array(n, "n", (3,))
    return matrix_from_unit_quaternion(_quaternion_from_gibbs(n))


def gibbs_from_matrix(R: ArrayLike, *, atol: float = 1e-6) -> NDArray[np.float64]:
    r"""Gibbs vector of a rotation matrix (through Shepperd's quaternion).

    Near :math:`\alpha=\pi` the relative accuracy of :math:`\mathbf n` is
    about ``eps/(pi - alpha)`` (about ``2e-9`` at ``pi - alpha = 1e-7``):
    the conversion is that ill-conditioned.

    Parameters
    ----------
    R : array_like, shape (..., 3, 3)
    atol : float, keyword-only
        See :func:`quaternion_from_matrix`.

    Returns
    -------
    ndarray, shape (..., 3)

    Raises
    ------
    SingularChartError
        If the rotation angle is :math:`\pi`.
    InvalidInputError
        If ``R`` is not a rotation matrix, has the wrong shape or non-finite values.

    References
    ----------
    Paper eq. 1.9 inverted; Shepperd (1978).

    Examples
    --------
    >>> import numpy as np
    >>> from eulerpoisson.attitude import gibbs_from_matrix
    >>> R = [[1.0, 0.0, 0.0], [0.0, 0.0, -1.0], [0.0, 1.0, 0.0]]  # 90 degrees about x
    >>> print(np.round(gibbs_from_matrix(R), 12) + 0.0)
    [1. 0. 0.]
    """
    return gibbs_from_unit_quaternion(quaternion_from_matrix(R, atol=atol), "R")


# ---------------------------------------------------------------------------
# composition and inverse
# ---------------------------------------------------------------------------
def gibbs_compose(n1: ArrayLike, n2: ArrayLike) -> NDArray[np.float64]:
    r"""Gibbs vector of the product :math:`R(\mathbf n_1)R(\mathbf n_2)`, in closed form.

    .. math:: \mathbf n_{12} = \frac{\mathbf n_1 + \mathbf n_2 + \mathbf n_1\times\mathbf n_2}{1 - \mathbf n_1\cdot\mathbf n_2}

    (the Hamilton product of :math:`(1,\mathbf n_1)` and :math:`(1,\mathbf n_2)`
    divided by its scalar part). Numerator and denominator are divided by
    powers of two first, so large arguments do not overflow.

    Parameters
    ----------
    n1, n2 : array_like, shape (..., 3)
        Broadcast against each other.

    Returns
    -------
    ndarray, shape (..., 3)

    Raises
    ------
    SingularChartError
        If :math:`\mathbf n_1\cdot\mathbf n_2 = 1`: the product is a rotation by :math:`\pi`.
    InvalidInputError
        Wrong shapes or non-finite values.

    References
    ----------
    Paper eq. 1.9 (the product of two such matrices); Shuster (1993), eq. 256.

    Examples
    --------
    >>> import numpy as np
    >>> from eulerpoisson.attitude import gibbs_compose, matrix_from_gibbs
    >>> n1, n2 = np.array([0.1, 0.0, 0.0]), np.array([0.0, 0.2, 0.0])
    >>> n = gibbs_compose(n1, n2)                                  # (n1 + n2 + n1 x n2) / (1 - n1.n2)
    >>> print(np.round(n, 12))
    [0.1  0.2  0.02]
    >>> bool(np.allclose(matrix_from_gibbs(n), matrix_from_gibbs(n1) @ matrix_from_gibbs(n2)))
    True
    """
    n1 = as_float_array(n1, "n1", (3,))
    n2 = as_float_array(n2, "n2", (3,))
    check_broadcast(n1=n1, n2=n2)
    m1 = np.max(np.abs(n1), -1)
    m2 = np.max(np.abs(n2), -1)
    s1 = np.where(m1 > 1.0, pow2_below(np.maximum(m1, 1.0)), 1.0)
    s2 = np.where(m2 > 1.0, pow2_below(np.maximum(m2, 1.0)), 1.0)
    u1 = n1 / s1[..., None]
    u2 = n2 / s2[..., None]
    with np.errstate(under="ignore"):
        r1 = 1.0 / s1
        r2 = 1.0 / s2
        num = u1 * r2[..., None] + u2 * r1[..., None] + np.cross(u1, u2)
        den = r1 * r2 - np.sum(u1 * u2, -1)
    with np.errstate(divide="ignore", over="ignore", invalid="ignore"):
        out = num / den[..., None]
    bad = (den == 0) | ~np.all(np.isfinite(out), -1)
    if np.any(bad):
        raise SingularChartError(
            f"gibbs_compose: n1 . n2 = 1{first_index(bad)}: the product is a rotation by pi where "
            "the global Gibbs vector is infinite; compose quaternions (Attitude * Attitude) or use a chart"
        )
    return out


def gibbs_inverse(n: ArrayLike) -> NDArray[np.float64]:
    r"""Gibbs vector of :math:`R(\mathbf n)^{-1} = R(\mathbf n)^T`, which is :math:`-\mathbf n`.

    Parameters
    ----------
    n : array_like, shape (..., 3)

    Returns
    -------
    ndarray, shape (..., 3)

    Raises
    ------
    InvalidInputError
        Wrong shape or non-finite values.

    References
    ----------
    Paper eq. 1.9: :math:`R_{ij}(-\mathbf n) = R_{ji}(\mathbf n)`.

    Examples
    --------
    >>> from eulerpoisson.attitude import gibbs_compose, gibbs_inverse
    >>> n = [0.1, -0.2, 0.3]
    >>> print(gibbs_inverse(n), gibbs_compose(n, gibbs_inverse(n)))
    [-0.1  0.2 -0.3] [0. 0. 0.]
    """
    return -as_float_array(n, "n", (3,))


# ---------------------------------------------------------------------------
# charts
# ---------------------------------------------------------------------------
def gibbs_chart(q: ArrayLike, reference: Attitude | ArrayLike) -> NDArray[np.float64]:
    r"""Local Gibbs vector of ``q`` in the chart centred on ``reference``.

    Returns :math:`\mathbf n` with :math:`R(q) = R(q_0)R(\mathbf n)`, i.e. the
    Gibbs vector of :math:`q_0^{-1}\otimes q`. The free rigid body is
    left-invariant, so its equations in :math:`\mathbf n` (eq. 1.13-1.30) are
    the same in every such chart; re-centring the chart when
    :math:`|\mathbf n|` grows lets a trajectory pass through
    :math:`\alpha=\pi` of the global chart.

    Parameters
    ----------
    q : array_like, shape (..., 4)
        Attitudes.
    reference : array_like, shape (..., 4)
        Chart centres :math:`q_0` (broadcast against ``q``).

    Returns
    -------
    ndarray, shape (..., 3)

    Raises
    ------
    SingularChartError
        If ``q`` is a rotation by :math:`\pi` relative to ``reference``.
    InvalidInputError
        Zero quaternions, wrong shapes or non-finite values.

    Examples
    --------
    >>> import numpy as np
    >>> from eulerpoisson.attitude import gibbs_chart
    >>> ref = [0.0, 1.0, 0.0, 0.0]                                 # 180 degrees about x: no global n
    >>> q = [0.0, np.cos(0.1), np.sin(0.1), 0.0]                    # near it
    >>> print(np.round(gibbs_chart(q, ref), 12) + 0.0)             # small in the chart centred there
    [ 0.          0.         -0.10033467]
    """
    q = as_quaternion(q)
    q0 = as_quaternion(reference, "reference")
    check_broadcast(q=q, reference=q0)
    rel = qmul(q0 * CONJUGATE_SIGNS, q)
    w = rel[..., 0]
    with np.errstate(divide="ignore", over="ignore", invalid="ignore"):
        n = rel[..., 1:] / w[..., None]
    bad = (w == 0) | ~np.all(np.isfinite(n), -1)
    if np.any(bad):
        raise SingularChartError(
            f"the attitude{first_index(bad)} is a rotation by pi relative to the chart reference, where "
            "the local Gibbs vector is infinite; choose another reference (e.g. the attitude itself)"
        )
    return n


def quaternion_from_chart(reference: Attitude | ArrayLike, n: ArrayLike) -> NDArray[np.float64]:
    r"""Attitude :math:`q_0\otimes q(\mathbf n)` of the local Gibbs vector ``n`` in the chart at ``reference``.

    The inverse of :func:`gibbs_chart`: :math:`R = R(q_0)R(\mathbf n)`.

    Parameters
    ----------
    reference : array_like, shape (..., 4)
        Chart centres :math:`q_0`.
    n : array_like, shape (..., 3)
        Local Gibbs vectors (broadcast against ``reference``).

    Returns
    -------
    ndarray, shape (..., 4)
        Unit quaternions (sign not canonical).

    Raises
    ------
    InvalidInputError
        Zero reference, wrong shapes or non-finite values.

    Examples
    --------
    >>> import numpy as np
    >>> from eulerpoisson.attitude import gibbs_chart, quaternion_from_chart
    >>> ref = [0.0, 1.0, 0.0, 0.0]
    >>> q = quaternion_from_chart(ref, [0.0, 0.0, 0.1])
    >>> print(np.round(q, 9) + 0.0)
    [ 0.          0.99503719 -0.09950372  0.        ]
    >>> print(np.round(gibbs_chart(q, ref), 12) + 0.0)             # back to the local n
    [0.  0.  0.1]
    """
    q0 = as_quaternion(reference, "reference")
    n = as_float_array(n, "n", (3,))
    check_broadcast(reference=q0, n=n)
    return qmul(q0, _quaternion_from_gibbs(n))


# ---------------------------------------------------------------------------
# the paper's matrices
# ---------------------------------------------------------------------------
def conversion_matrix(n: ArrayLike) -> NDArray[np.float64]:
    r"""The paper's conversion matrix :math:`A(\mathbf n)` (eq. 1.12).

    .. math:: A_{ij} = \frac{\delta_{ij} - \epsilon_{ijk}n_k}{1+\mathbf n^2}
              = \frac{\mathbf 1 + [\mathbf n]_\times}{1+\mathbf n^2}
              = w\,(w\mathbf 1 + [\mathbf v]_\times)

    evaluated in the last form with the unit quaternion :math:`(w, \mathbf v)`
    of :math:`\mathbf n`, which does not overflow for large :math:`|\mathbf n|`.

    Parameters
    ----------
    n : array_like, shape (..., 3)

    Returns
    -------
    ndarray, shape (..., 3, 3)

    Raises
    ------
    InvalidInputError
        Wrong shape or non-finite values.

    References
    ----------
    Paper eq. 1.11-1.12.

    Examples
    --------
    >>> import numpy as np
    >>> from eulerpoisson.attitude import conversion_matrix
    >>> print(conversion_matrix([0.0, 0.0, 0.0]))                   # A(0) = 1
    [[1. 0. 0.]
     [0. 1. 0.]
     [0. 0. 1.]]
    >>> print(np.round(conversion_matrix([0.0, 0.0, 1.0]), 12) + 0.0)
    [[ 0.5 -0.5  0. ]
     [ 0.5  0.5  0. ]
     [ 0.   0.   0.5]]
    """
    n = as_float_array(n, "n", (3,))
    return _A(n)


def _A(n):
    q = _quaternion_from_gibbs(n)
    w = q[..., 0][..., None, None]
    with np.errstate(under="ignore"):
        return w * (w * np.eye(3) + skew_unchecked(q[..., 1:]))


def inverse_conversion_matrix(n: ArrayLike) -> NDArray[np.float64]:
    r"""The paper's :math:`\tilde A(\mathbf n) = A^{-1}(\mathbf n)` (eq. 1.12, corrected).

    .. math:: \tilde A_{ij} = \delta_{ij} + n_i n_j + \epsilon_{ijk}n_k
              = \mathbf 1 + \mathbf n\mathbf n^T - [\mathbf n]_\times

    The paper prints :math:`n_j n_j` for the middle term; the inverse of
    :math:`A` has :math:`n_i n_j` (checked in the tests: :math:`A\tilde A = \mathbf 1`).

    Parameters
    ----------
    n : array_like, shape (..., 3)

    Returns
    -------
    ndarray, shape (..., 3, 3)

    Raises
    ------
    InvalidInputError
        Wrong shape or non-finite values.

    References
    ----------
    Paper eq. 1.12.

    Examples
    --------
    >>> import numpy as np
    >>> from eulerpoisson.attitude import conversion_matrix, inverse_conversion_matrix
    >>> n = [0.1, 0.2, 0.3]
    >>> print(np.round(inverse_conversion_matrix(n) @ conversion_matrix(n), 12) + 0.0)   # A~ A = 1
    [[1. 0. 0.]
     [0. 1. 0.]
     [0. 0. 1.]]
    """
    n = as_float_array(n, "n", (3,))
    with np.errstate(over="ignore", invalid="ignore"):
        out = _At(n)
    return finite_result(out, "inverse_conversion_matrix", n=n)


def _At(n):
    return np.eye(3) + outer(n, n) - skew_unchecked(n)


def matrix_from_conversion(n: ArrayLike) -> NDArray[np.float64]:
    r"""The rotation matrix as :math:`R = A\tilde A^T` (paper, after eq. 1.12).

    Equals :func:`matrix_from_gibbs` (eq. 1.9); kept as an independent
    evaluation of the paper's identity.

    Parameters
    ----------
    n : array_like, shape (..., 3)

    Returns
    -------
    ndarray, shape (..., 3, 3)

    Raises
    ------
    InvalidInputError
        Wrong shape or non-finite values; a result that overflows float64
        (:math:`|\mathbf n|` beyond about 1e154: :func:`matrix_from_gibbs`
        evaluates those).

    References
    ----------
    Paper eq. 1.12.

    Examples
    --------
    >>> import numpy as np
    >>> from eulerpoisson.attitude import matrix_from_conversion, matrix_from_gibbs
    >>> n = [0.1, 0.2, 0.3]
    >>> float(np.max(np.abs(matrix_from_conversion(n) - matrix_from_gibbs(n)))) < 1e-15
    True
    """
    n = as_float_array(n, "n", (3,))
    with np.errstate(over="ignore", invalid="ignore"):
        out = _A(n) @ np.swapaxes(_At(n), -1, -2)
    return finite_result(out, "matrix_from_conversion", n=n)


def omega_from_gibbs_rate(n: ArrayLike, ndot: ArrayLike) -> NDArray[np.float64]:
    r"""Body angular velocity :math:`\boldsymbol\Omega = 2A^T\dot{\mathbf n}` (eq. 1.11).

    .. math:: \boldsymbol\Omega = \frac{2(\dot{\mathbf n} - \mathbf n\times\dot{\mathbf n})}{1+\mathbf n^2}

    This is :math:`\Omega_k = -\tfrac12\epsilon_{kij}(R^T\dot R)_{ij}` (eq. 1.10)
    for :math:`R = R(\mathbf n(t))`.

    Parameters
    ----------
    n, ndot : array_like, shape (..., 3)
        Gibbs vector and its time derivative; broadcast against each other.

    Returns
    -------
    ndarray, shape (..., 3)

    Raises
    ------
    InvalidInputError
        Wrong shapes or non-finite values.

    References
    ----------
    Paper eq. 1.10-1.11, 1.24.

    Examples
    --------
    >>> from eulerpoisson.attitude import omega_from_gibbs_rate
    >>> print(omega_from_gibbs_rate([0.0, 0.0, 0.0], [0.0, 0.0, 0.5]))   # at n = 0: Omega = 2 ndot
    [0. 0. 1.]
    """
    n = as_float_array(n, "n", (3,))
    nd = as_float_array(ndot, "ndot", (3,))
    check_broadcast(n=n, ndot=nd)
    with np.errstate(over="ignore", invalid="ignore"):
        out = 2.0 * np.einsum("...ji,...j->...i", _A(n), nd)
    return finite_result(out, "omega_from_gibbs_rate", n=n, ndot=nd)


def gibbs_rate_from_omega(n: ArrayLike, omega: ArrayLike) -> NDArray[np.float64]:
    r""":math:`\dot{\mathbf n} = \tfrac12\tilde A^T\boldsymbol\Omega` (eq. 1.30), the inverse of eq. 1.11.

    .. math:: \dot{\mathbf n} = \tfrac12\left(\boldsymbol\Omega + \mathbf n\times\boldsymbol\Omega + (\mathbf n\cdot\boldsymbol\Omega)\mathbf n\right)

    Parameters
    ----------
    n, omega : array_like, shape (..., 3)
        Gibbs vector and body angular velocity; broadcast against each other.

    Returns
    -------
    ndarray, shape (..., 3)

    Raises
    ------
    InvalidInputError
        Wrong shapes or non-finite values.

    References
    ----------
    Paper eq. 1.30 (and 1.20).

    Examples
    --------
    >>> import numpy as np
    >>> from eulerpoisson.attitude import gibbs_rate_from_omega, omega_from_gibbs_rate
    >>> n, w = [0.1, 0.2, 0.3], [1.0, -0.5, 0.25]
    >>> print(np.round(omega_from_gibbs_rate(n, gibbs_rate_from_omega(n, w)), 12))   # the inverse map
    [ 1.   -0.5   0.25]
    """
    n = as_float_array(n, "n", (3,))
    w = as_float_array(omega, "omega", (3,))
    check_broadcast(n=n, omega=w)
    n, w = np.broadcast_arrays(n, w)
    with np.errstate(over="ignore", invalid="ignore"):
        out = 0.5 * (w + np.cross(n, w) + np.sum(n * w, -1)[..., None] * n)
    return finite_result(out, "gibbs_rate_from_omega", n=n, omega=w)


def _inertia_arrays(inertia, inverse: bool = False):
    """Validated inertia tensor (..., 3, 3), or its inverse, from moments, a tensor or a RigidBody.

    Same checks as :class:`~eulerpoisson.model.body.RigidBody` (symmetric, positive
    definite, triangle inequality) without building the principal frame.
    """
    from ..model.body import RigidBody, check_moments, check_tensor

    if isinstance(inertia, RigidBody):
        return inertia.inertia_inv if inverse else inertia.inertia
    a = as_float_array(inertia, "inertia")
    if a.ndim >= 2 and a.shape[-2:] == (3, 3):
        check_tensor(a)
        I = 0.5 * (a + np.swapaxes(a, -1, -2))
        check_moments(np.linalg.eigvalsh(I))
        return np.linalg.inv(I) if inverse else I
    if a.ndim >= 1 and a.shape[-1] == 3:
        check_moments(a)
        return (1.0 / a if inverse else a)[..., :, None] * np.eye(3)
    raise InvalidInputError(
        f"inertia must be three principal moments, shape (..., 3), or a 3x3 tensor, "
        f"shape (..., 3, 3); got shape {a.shape}"
    )


def metric(n: ArrayLike, inertia: ArrayLike) -> NDArray[np.float64]:
    r"""The metric :math:`G(\mathbf n) = 4AIA^T` of the geodesic problem (eq. 1.13).

    The Lagrangian is :math:`L = \tfrac12 G_{ij}\dot n_i\dot n_j =
    \tfrac12\boldsymbol\Omega\cdot I\boldsymbol\Omega`.

    Parameters
    ----------
    n : array_like, shape (..., 3)
    inertia : array_like, shape (..., 3) or (..., 3, 3), or RigidBody
        Principal moments or the full (body-frame) inertia tensor; validated
        as in :class:`~eulerpoisson.model.body.RigidBody` (a (3, 3) array is a tensor).

    Returns
    -------
    ndarray, shape (..., 3, 3)

    Raises
    ------
    InvalidInputError
        Wrong shapes or non-finite values.
    InvalidInertiaError
        An inertia tensor that is not symmetric, not positive definite or
        violates the triangle inequality.

    References
    ----------
    Paper eq. 1.13.

    Examples
    --------
    >>> import numpy as np
    >>> from eulerpoisson.attitude import metric
    >>> print(metric([0.0, 0.0, 0.0], [1.0, 2.0, 3.0]))            # G(0) = 4 A I A^T = 4 I
    [[ 4.  0.  0.]
     [ 0.  8.  0.]
     [ 0.  0. 12.]]
    >>> G = metric([0.1, 0.2, 0.3], [1.0, 2.0, 3.0])
    >>> bool(np.allclose(G, G.T)), bool(np.all(np.linalg.eigvalsh(G) > 0))
    (True, True)
    """
    n = as_float_array(n, "n", (3,))
    I = _inertia_arrays(inertia)
    with np.errstate(over="ignore", invalid="ignore"):
        A = _A(n)
    with np.errstate(over="ignore", invalid="ignore"):
        out = 4.0 * A @ I @ np.swapaxes(A, -1, -2)
    return finite_result(out, "metric", n=n)


def inverse_metric(n: ArrayLike, inertia: ArrayLike) -> NDArray[np.float64]:
    r"""The inverse metric :math:`G^{-1} = \tfrac14\tilde A^T I^{-1}\tilde A` (eq. 1.14).

    Parameters
    ----------
    n : array_like, shape (..., 3)
    inertia : array_like, shape (..., 3) or (..., 3, 3), or RigidBody
        As in :func:`metric`.

    Returns
    -------
    ndarray, shape (..., 3, 3)

    Raises
    ------
    InvalidInputError
        Wrong shapes or non-finite values.
    InvalidInertiaError
        Invalid inertia (see :func:`metric`).

    References
    ----------
    Paper eq. 1.14.

    Examples
    --------
    >>> import numpy as np
    >>> from eulerpoisson.attitude import inverse_metric, metric
    >>> n, inertia = [0.1, 0.2, 0.3], [1.0, 2.0, 3.0]
    >>> print(np.round(inverse_metric(n, inertia) @ metric(n, inertia), 12) + 0.0)
    [[1. 0. 0.]
     [0. 1. 0.]
     [0. 0. 1.]]
    """
    n = as_float_array(n, "n", (3,))
    Iinv = _inertia_arrays(inertia, inverse=True)
    with np.errstate(over="ignore", invalid="ignore"):
        At = _At(n)
    with np.errstate(over="ignore", invalid="ignore"):
        out = 0.25 * np.swapaxes(At, -1, -2) @ Iinv @ At
    return finite_result(out, "inverse_metric", n=n)
