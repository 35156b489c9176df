r"""Attitude sets centred on the paper's rotation vector.

The paper parametrizes a rotation by the *Gibbs vector* (paper eq. 1.8)

.. math:: \mathbf n = \mathbf k \tan(\alpha/2), \qquad 0 \le \alpha < \pi,

which is the vector part of a unit quaternion divided by its scalar part,
:math:`\mathbf n = \mathbf q/q_0` (footnote to eq. 1.9). This module converts
between the Gibbs vector and the usual attitude sets, all batched over leading
axes, and provides the paper's matrices :math:`A(\mathbf n)`,
:math:`\tilde A(\mathbf n)` (eq. 1.12), the kinematic maps of eq. 1.11 and
eq. 1.30, and the metric :math:`G(\mathbf n)` (eq. 1.13-1.14).

Conventions
-----------
* ``x_space = R @ x_body`` and :math:`\dot R = R[\Omega]_\times` with
  :math:`\Omega` the body angular velocity (paper eq. 1.4).
* Quaternions are scalar first ``(w, x, y, z)`` with the Hamilton product; the
  rotation matrix of ``q`` is the active rotation
  :math:`R = (w^2-\mathbf v^2)\mathbf 1 + 2\mathbf v\mathbf v^T + 2w[\mathbf v]_\times`.
* Functions are named ``<to>_from_<from>``. Representations: ``quaternion``
  (..., 4), ``matrix`` (..., 3, 3), ``gibbs`` (..., 3), ``axis_angle``
  (``(k, alpha)`` with shapes (..., 3) and (...)), ``rotvec`` (scipy's
  :math:`\alpha\mathbf k`, (..., 3)), ``mrp`` (modified Rodrigues parameters
  :math:`\mathbf k\tan(\alpha/4)`, (..., 3)), ``euler`` (..., 3) with a
  sequence string as in scipy (``"xyz"`` extrinsic, ``"XYZ"`` intrinsic) and
  ``scipy`` (:class:`scipy.spatial.transform.Rotation`).

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
  ``pi - alpha = 1e-7``). Rotation vectors and MRPs are converted with a
  double-double sum of squares, so for them the result is accurate to a few
  ulps of the exact value for the given floating-point input.
* Near the identity all conversions keep full *relative* accuracy of small
  vectors (no ``1 - cos`` cancellation).

References
----------
A. A. Deriglazov, *Geodesic motion on the symplectic leaf of SO(3) with
distorted e(3) algebra and Liouville integrability of a free rigid body*
(the paper), eqs. 1.7-1.14, 1.30.
M. D. Shuster, "A survey of attitude representations", J. Astronaut. Sci. 41
(1993) 439-517.
S. W. Shepperd, "Quaternion from rotation matrix", J. Guidance Control 1 (1978) 223-224.
E. Bernardes and S. Viollet, "Quaternion to Euler angles conversion: a direct,
general and computationally efficient method", PLoS ONE 17 (2022) e0276302.
T. J. Dekker, "A floating-point technique for extending the available
precision", Numer. Math. 18 (1971) 224-242.
"""

from __future__ import annotations

import operator
from collections.abc import Iterator
from typing import TYPE_CHECKING, Any, TypeAlias

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..errors import InvalidInputError, SingularChartError
from ..numerics.doubledouble import sum_of_squares as _sumsq_dd
from ..numerics.doubledouble import two_prod as _two_prod
from ..numerics.quaternion import qmul
from ..util.validate import as_bool, as_float_array, as_scalar, as_shape, check_broadcast

if TYPE_CHECKING:
    from scipy.spatial.transform import Rotation

#: an attitude as the API takes it: an :class:`Attitude`, a scipy ``Rotation`` or unit quaternions (w, x, y, z)
AttitudeLike: TypeAlias = "Attitude | Rotation | ArrayLike"

__all__ = [
    "Attitude",
    "UNIT_QUATERNION_TOLERANCE",
    "skew",
    "unskew",
    "quaternion_multiply",
    "quaternion_conjugate",
    "quaternion_normalize",
    "quaternion_canonical",
    "quaternion_make_continuous",
    "quaternion_from_gibbs",
    "gibbs_from_quaternion",
    "matrix_from_quaternion",
    "quaternion_from_matrix",
    "matrix_from_gibbs",
    "gibbs_from_matrix",
    "quaternion_from_axis_angle",
    "axis_angle_from_quaternion",
    "quaternion_from_rotvec",
    "rotvec_from_quaternion",
    "quaternion_from_mrp",
    "mrp_from_quaternion",
    "quaternion_from_euler",
    "euler_from_quaternion",
    "quaternion_from_scipy",
    "scipy_from_quaternion",
    "gibbs_from_axis_angle",
    "axis_angle_from_gibbs",
    "gibbs_from_rotvec",
    "rotvec_from_gibbs",
    "gibbs_from_mrp",
    "mrp_from_gibbs",
    "gibbs_from_euler",
    "euler_from_gibbs",
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
    "EULER_GIMBAL_TOL",
]

_EPS = np.finfo(float).eps
_CONJ = np.array([1.0, -1.0, -1.0, -1.0])

#: Gimbal lock is declared in :func:`euler_from_quaternion` when the sine (or
#: cosine) of the half middle angle is below this fraction of the other; the
#: rotation error introduced by zeroing the third angle is at most about
#: twice this value.
#: largest ``| |q| - 1 |`` accepted where a unit quaternion is required (a float32-rounded unit quaternion is
#: off by about 3e-8); inputs within it are renormalized, inputs beyond it are refused
UNIT_QUATERNION_TOLERANCE = 1e-6

EULER_GIMBAL_TOL = 1e-14


# ---------------------------------------------------------------------------
# small helpers
# ---------------------------------------------------------------------------
def skew(v: ArrayLike) -> NDArray[np.float64]:
    r"""Cross-product matrix :math:`[\mathbf v]_\times`, with :math:`[\mathbf v]_\times \mathbf w = \mathbf v\times\mathbf w`.

    In the paper's index notation :math:`([\mathbf v]_\times)_{ij} = -\epsilon_{ijk} v_k`
    (the matrix :math:`-\hat v` of eq. 1.21).

    Parameters
    ----------
    v : array_like, shape (..., 3)

    Returns
    -------
    ndarray, shape (..., 3, 3)

    Raises
    ------
    InvalidInputError
        Wrong trailing shape or non-finite values.

    Examples
    --------
    >>> import numpy as np
    >>> from eulerpoisson.attitude import skew
    >>> S = skew([1.0, 2.0, 3.0])
    >>> print(S)
    [[ 0. -3.  2.]
     [ 3.  0. -1.]
     [-2.  1.  0.]]
    >>> print(S @ [0.0, 0.0, 1.0], np.cross([1.0, 2.0, 3.0], [0.0, 0.0, 1.0]))
    [ 2. -1.  0.] [ 2. -1.  0.]
    """
    v = as_float_array(v, "v", (3,))
    return _skew(v)


def _skew(v: np.ndarray) -> np.ndarray:
    x, y, z = v[..., 0], v[..., 1], v[..., 2]
    o = np.zeros_like(x)
    return np.stack([np.stack([o, -z, y], -1), np.stack([z, o, -x], -1), np.stack([-y, x, o], -1)], -2)


def unskew(S: ArrayLike) -> NDArray[np.float64]:
    r"""Vector of the antisymmetric part of ``S``: the inverse of :func:`skew`.

    .. math:: v_k = -\tfrac12\epsilon_{kij}S_{ij}

    (the map :math:`R^T\dot R\mapsto\boldsymbol\Omega` of eq. 1.10).

    Parameters
    ----------
    S : array_like, shape (..., 3, 3)

    Returns
    -------
    ndarray, shape (..., 3)

    Raises
    ------
    InvalidInputError
        Wrong trailing shape or non-finite values.

    Examples
    --------
    >>> from eulerpoisson.attitude import skew, unskew
    >>> print(unskew(skew([1.0, 2.0, 3.0])))
    [1. 2. 3.]
    """
    S = as_float_array(S, "S", (3, 3))
    return 0.5 * np.stack([S[..., 2, 1] - S[..., 1, 2], S[..., 0, 2] - S[..., 2, 0], S[..., 1, 0] - S[..., 0, 1]], -1)


def _outer(a, b):
    return a[..., :, None] * b[..., None, :]


def _norm(v):
    return np.sqrt(np.sum(v * v, axis=-1))


def _pow2_below(m):
    """Largest power of two <= m (m > 0 finite); division by it is exact."""
    _, e = np.frexp(m)
    return np.ldexp(1.0, e - 1)


def _first_index(mask) -> str:
    """' at batch index (i, j)' for the first True of a boolean batch mask, or ''."""
    mask = np.asarray(mask)
    if mask.ndim == 0:
        return ""
    idx = np.unravel_index(int(np.argmax(mask)), mask.shape)
    return f" at batch index {tuple(int(i) for i in idx)}"


# ---------------------------------------------------------------------------
# quaternions
# ---------------------------------------------------------------------------
def finite_result(x, what: str, **inputs) -> np.ndarray:
    """``x`` when it is finite; an :class:`~eulerpoisson.errors.InvalidInputError` naming ``what`` and its
    largest input when float64 overflowed (never a silent inf)."""
    if np.all(np.isfinite(x)):
        return x
    desc = ", ".join(f"max |{k}| = {float(np.max(np.abs(v))):.3g}" for k, v in inputs.items())
    raise InvalidInputError(f"{what} overflows float64 for these inputs ({desc}); rescale them")


def as_quaternion(q, name="q") -> np.ndarray:
    """Validate and normalize quaternions (power-of-two prescaling: no overflow/underflow)."""
    q = as_float_array(q, name, (4,))
    m = np.max(np.abs(q), axis=-1)
    if np.any(m == 0):
        raise InvalidInputError(f"{name} contains a zero quaternion{_first_index(m == 0)}, which is not a rotation")
    qs = q / _pow2_below(m)[..., None]
    return qs / _norm(qs)[..., None]


def quaternion_multiply(p: ArrayLike, q: ArrayLike) -> NDArray[np.float64]:
    r"""Hamilton product :math:`p\otimes q` of scalar-first quaternions.

    .. math:: (p_0, \mathbf p)\otimes(q_0, \mathbf q) =
              (p_0q_0 - \mathbf p\cdot\mathbf q,\;
               p_0\mathbf q + q_0\mathbf p + \mathbf p\times\mathbf q)

    The rotation of :math:`p\otimes q` is :math:`R(p)R(q)`. The inputs are
    not normalized.

    Parameters
    ----------
    p, q : array_like, shape (..., 4)
        Broadcast against each other.

    Returns
    -------
    ndarray, shape (..., 4)

    Raises
    ------
    InvalidInputError
        Wrong trailing shape or non-finite values.

    Examples
    --------
    >>> import numpy as np
    >>> from eulerpoisson.attitude import quaternion_multiply
    >>> qz = [np.cos(np.pi / 4), 0.0, 0.0, np.sin(np.pi / 4)]     # 90 degrees about z
    >>> print(np.round(quaternion_multiply(qz, qz), 12))          # 180 degrees about z
    [0. 0. 0. 1.]
    """
    p = as_float_array(p, "p", (4,))
    q = as_float_array(q, "q", (4,))
    check_broadcast(p=p, q=q)
    with np.errstate(over="ignore", invalid="ignore"):
        out = qmul(p, q)
    return finite_result(out, "quaternion_multiply", p=p, q=q)


def quaternion_conjugate(q: ArrayLike) -> NDArray[np.float64]:
    """Conjugate ``(w, -x, -y, -z)``: the inverse rotation of a unit quaternion.

    Parameters
    ----------
    q : array_like, shape (..., 4)
        Not normalized.

    Returns
    -------
    ndarray, shape (..., 4)

    Raises
    ------
    InvalidInputError
        Wrong trailing shape or non-finite values.

    Examples
    --------
    >>> from eulerpoisson.attitude import quaternion_conjugate, quaternion_multiply
    >>> q = [0.5, 0.5, 0.5, 0.5]
    >>> print(quaternion_conjugate(q))
    [ 0.5 -0.5 -0.5 -0.5]
    >>> print(quaternion_multiply(q, quaternion_conjugate(q)))    # the identity
    [1. 0. 0. 0.]
    """
    q = as_float_array(q, "q", (4,))
    return q * _CONJ


def quaternion_normalize(q: ArrayLike) -> NDArray[np.float64]:
    """Scale quaternions to unit norm (without overflow or underflow).

    Parameters
    ----------
    q : array_like, shape (..., 4)

    Returns
    -------
    ndarray, shape (..., 4)

    Raises
    ------
    InvalidInputError
        Zero quaternion, wrong shape or non-finite values.

    Examples
    --------
    >>> from eulerpoisson.attitude import quaternion_normalize
    >>> print(quaternion_normalize([3.0, 0.0, 4.0, 0.0]))
    [0.6 0.  0.8 0. ]
    >>> print(quaternion_normalize([3e300, 0.0, 4e300, 0.0]))     # no overflow
    [0.6 0.  0.8 0. ]
    """
    return as_quaternion(q)


def quaternion_canonical(q: ArrayLike) -> NDArray[np.float64]:
    """Unit quaternion with the sign chosen so that ``w >= 0``.

    For ``w = 0`` the first nonzero vector component is made positive, so the
    result is unique for every rotation.

    Parameters
    ----------
    q : array_like, shape (..., 4)

    Returns
    -------
    ndarray, shape (..., 4)

    Raises
    ------
    InvalidInputError
        Zero quaternion, wrong shape or non-finite values.

    Examples
    --------
    >>> from eulerpoisson.attitude import quaternion_canonical
    >>> print(quaternion_canonical([-0.5, -0.5, 0.5, -0.5]))     # the same rotation, w >= 0
    [ 0.5  0.5 -0.5  0.5]
    """
    return _canonical(as_quaternion(q))


def _canonical(q: np.ndarray) -> np.ndarray:
    first = np.argmax(q != 0, axis=-1)
    lead = np.take_along_axis(q, first[..., None], axis=-1)
    return np.where(lead < 0, -q, q)


def quaternion_make_continuous(q: ArrayLike, axis: int = 0) -> NDArray[np.float64]:
    """Flip signs along ``axis`` so that consecutive quaternions have a nonnegative dot product.

    Both ``q`` and ``-q`` are the same rotation; a time series of attitudes
    reads (and interpolates) best when the sign does not jump. The first
    sample keeps its sign; magnitudes are not changed.

    Parameters
    ----------
    q : array_like, shape (..., 4)
        A series of quaternions along ``axis``.
    axis : int
        The series axis; any axis but the last (the quaternion axis).

    Returns
    -------
    ndarray, same shape as ``q``

    Raises
    ------
    InvalidInputError
        Wrong shape, non-finite values, or ``axis`` out of range or equal to
        the quaternion axis.
    TypeError
        If ``axis`` is not an integer.

    Examples
    --------
    >>> from eulerpoisson.attitude import quaternion_make_continuous
    >>> q = [[1.0, 0.0, 0.0, 0.0], [-0.8, -0.6, 0.0, 0.0], [0.6, 0.8, 0.0, 0.0]]
    >>> print(quaternion_make_continuous(q)[:, :2])               # (w, x): the second sample flipped
    [[1.  0. ]
     [0.8 0.6]
     [0.6 0.8]]
    """
    q = as_float_array(q, "q", (4,))
    try:
        axis = operator.index(axis)
    except TypeError:
        raise TypeError(f"axis must be an integer, got {type(axis).__name__} {axis!r}") from None
    if not -q.ndim <= axis < q.ndim:
        raise InvalidInputError(f"axis {axis} is out of range for q of shape {q.shape}")
    ax = axis % q.ndim
    if ax == q.ndim - 1:
        raise InvalidInputError(f"axis={axis} is the quaternion axis of q (shape {q.shape}); give the series axis")
    qm = np.moveaxis(q, ax, 0)
    if qm.shape[0] < 2:
        return q.copy()
    dots = np.sum(qm[1:] * qm[:-1], axis=-1)
    flips = np.concatenate([np.zeros((1,) + dots.shape[1:], dtype=int), np.cumsum(dots < 0, axis=0)])
    sign = np.where(flips % 2 == 1, -1.0, 1.0)
    return np.moveaxis(qm * sign[..., None], 0, ax)


def matrix_from_quaternion(q: ArrayLike) -> NDArray[np.float64]:
    r"""Rotation matrix of a quaternion.

    .. math:: R = (w^2-\mathbf v^2)\mathbf 1 + 2\mathbf v\mathbf v^T + 2w[\mathbf v]_\times

    The quaternion is normalized first; ``q`` and ``-q`` give the same matrix.

    Parameters
    ----------
    q : array_like, shape (..., 4)

    Returns
    -------
    ndarray, shape (..., 3, 3)

    Raises
    ------
    InvalidInputError
        Zero quaternion, wrong shape or non-finite values.

    References
    ----------
    Paper, footnote to eq. 1.9 (with :math:`\mathbf n = \mathbf q/q_0` this is eq. 1.9).

    Examples
    --------
    >>> import numpy as np
    >>> from eulerpoisson.attitude import matrix_from_quaternion
    >>> R = matrix_from_quaternion([np.cos(np.pi / 4), 0.0, 0.0, np.sin(np.pi / 4)])   # 90 degrees about z
    >>> print(np.round(R @ [1.0, 0.0, 0.0], 12) + 0.0)            # x_space = R x_body
    [0. 1. 0.]
    """
    return matrix_from_unit_quaternion(as_quaternion(q))


def matrix_from_unit_quaternion(q):
    w = q[..., 0]
    v = q[..., 1:]
    R = (w * w - np.sum(v * v, -1))[..., None, None] * np.eye(3)
    return R + 2.0 * _outer(v, v) + 2.0 * w[..., None, None] * _skew(v)


def quaternion_from_matrix(R: ArrayLike, *, atol: float = 1e-6) -> NDArray[np.float64]:
    r"""Unit quaternion (``w >= 0``) of a rotation matrix, by Shepperd's method.

    The largest of :math:`4w^2 = 1+\mathrm{tr}R` and
    :math:`4x_i^2 = 1 + 2R_{ii} - \mathrm{tr}R` is the pivot; the other
    components come from the off-diagonal sums and differences divided by it,
    so no square root of a small number is taken. Near the identity the
    vector part keeps full relative accuracy; near :math:`\alpha=\pi` the
    scalar part :math:`w` has an absolute error of a few ``eps`` (the matrix
    holds no more information than that).

    Parameters
    ----------
    R : array_like, shape (..., 3, 3)
        Rotation matrices.
    atol : float, keyword-only
        Tolerance for the checks :math:`\max|R^TR-\mathbf 1|\le` ``atol`` and
        :math:`|\det R - 1|\le` ``atol``. Matrices within the tolerance are
        used as they are (the result is the quaternion of a nearby rotation).

    Returns
    -------
    ndarray, shape (..., 4)

    Raises
    ------
    InvalidInputError
        Wrong shape, non-finite values, a negative or non-finite ``atol``,
        or a matrix that is not a rotation (not orthogonal, or a reflection
        with :math:`\det R = -1`).

    References
    ----------
    Shepperd (1978).

    Examples
    --------
    >>> import numpy as np
    >>> from eulerpoisson.attitude import quaternion_from_matrix
    >>> R = [[0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]]  # 90 degrees about z
    >>> print(np.round(quaternion_from_matrix(R), 12))
    [0.70710678 0.         0.         0.70710678]
    """
    R = as_float_array(R, "R", (3, 3))
    atol = as_scalar(atol, "atol", nonnegative=True)
    RtR = np.swapaxes(R, -1, -2) @ R
    orth = np.max(np.abs(RtR - np.eye(3)), axis=(-1, -2))
    det = np.linalg.det(R)
    bad = (orth > atol) | (np.abs(det - 1.0) > atol)
    if np.any(bad):
        i = np.argmax(bad.ravel())
        raise InvalidInputError(
            "R is not a rotation matrix: expected R^T R = 1 and det R = +1 within "
            f"atol={atol:g}; got max|R^T R - 1| = {orth.ravel()[i]:.3g} and det R = "
            f"{det.ravel()[i]:.6g}{_first_index(bad)}"
        )
    return quaternion_from_rotation_matrix(R)


def quaternion_from_rotation_matrix(R):
    r00, r11, r22 = R[..., 0, 0], R[..., 1, 1], R[..., 2, 2]
    tr = r00 + r11 + r22
    k = np.argmax(np.stack([tr, r00, r11, r22], -1), axis=-1)
    d21 = R[..., 2, 1] - R[..., 1, 2]
    d02 = R[..., 0, 2] - R[..., 2, 0]
    d10 = R[..., 1, 0] - R[..., 0, 1]
    s01 = R[..., 0, 1] + R[..., 1, 0]
    s02 = R[..., 0, 2] + R[..., 2, 0]
    s12 = R[..., 1, 2] + R[..., 2, 1]
    # row p is 4 q_p q, accurate where q_p is the largest component
    Q = np.stack(
        [
            np.stack([1 + tr, d21, d02, d10], -1),
            np.stack([d21, 1 + 2 * r00 - tr, s01, s02], -1),
            np.stack([d02, s01, 1 + 2 * r11 - tr, s12], -1),
            np.stack([d10, s02, s12, 1 + 2 * r22 - tr], -1),
        ],
        -2,
    )
    q = np.take_along_axis(Q, k[..., None, None], axis=-2)[..., 0, :]
    q = q / _norm(q)[..., None]
    return np.where(q[..., :1] < 0, -q, q)


# ---------------------------------------------------------------------------
# Gibbs vector (the paper's n)
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
    scale = np.where(big > 1.0, _pow2_below(np.where(big > 1.0, big, 1.0)), 1.0)
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


def _gibbs_from_unit_quaternion(q, what="the attitude"):
    w = q[..., 0]
    with np.errstate(divide="ignore", over="ignore", invalid="ignore"):
        n = q[..., 1:] / w[..., None]
    bad = (w == 0) | ~np.all(np.isfinite(n), axis=-1)
    if np.any(bad):
        raise SingularChartError(_singular_message(what, _first_index(bad)))
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
    return _gibbs_from_unit_quaternion(as_quaternion(q))


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
    return _gibbs_from_unit_quaternion(quaternion_from_matrix(R, atol=atol), "R")


# ---------------------------------------------------------------------------
# axis-angle, rotation vector, MRP
# ---------------------------------------------------------------------------
def _unit_axis(axis, name="axis"):
    k = as_float_array(axis, name, (3,))
    m = np.max(np.abs(k), axis=-1)
    if np.any(m == 0):
        raise InvalidInputError(f"{name} contains a zero vector{_first_index(m == 0)}; a rotation axis must be nonzero")
    k = k / _pow2_below(m)[..., None]
    return k / _norm(k)[..., None]


def quaternion_from_axis_angle(axis: ArrayLike, angle: ArrayLike) -> NDArray[np.float64]:
    r"""Quaternion :math:`(\cos\frac\alpha2, \mathbf k\sin\frac\alpha2)` of a rotation by ``angle`` about ``axis``.

    Parameters
    ----------
    axis : array_like, shape (..., 3)
        Rotation axis; normalized here (must be nonzero).
    angle : array_like, shape (...)
        Angle in radians, counterclockwise seen from the tip of the axis
        (paper eq. 1.7); broadcast against the batch shape of ``axis``.

    Returns
    -------
    ndarray, shape (..., 4)

    Raises
    ------
    InvalidInputError
        Zero axis, shapes that do not broadcast, or non-finite values.

    References
    ----------
    Paper eq. 1.7; Shuster (1993), section 5.

    Examples
    --------
    >>> import numpy as np
    >>> from eulerpoisson.attitude import quaternion_from_axis_angle
    >>> print(np.round(quaternion_from_axis_angle([0.0, 0.0, 2.0], np.pi / 2), 12))   # the axis is normalized
    [0.70710678 0.         0.         0.70710678]
    """
    k = _unit_axis(axis)
    a = as_float_array(angle, "angle")
    try:
        shape = np.broadcast_shapes(k.shape[:-1], a.shape)
    except ValueError:
        raise InvalidInputError(
            f"axis (shape {k.shape}) and angle (shape {a.shape}) do not broadcast: angle must have "
            "the batch shape of axis, i.e. axis.shape[:-1]"
        ) from None
    k = np.broadcast_to(k, shape + (3,))
    a = np.broadcast_to(a, shape)
    return np.concatenate([np.cos(a / 2)[..., None], k * np.sin(a / 2)[..., None]], -1)


def axis_angle_from_quaternion(q: ArrayLike) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    r"""Unit axis :math:`\mathbf k` and angle :math:`\alpha\in[0,\pi]` of a quaternion.

    :math:`\alpha = 2\,\mathrm{atan2}(|\mathbf v|, |w|)`, accurate at every
    angle (no ``arccos``). At :math:`\alpha = 0` the axis is undefined and
    ``(0, 0, 1)`` is returned.

    Parameters
    ----------
    q : array_like, shape (..., 4)

    Returns
    -------
    axis : ndarray, shape (..., 3)
    angle : ndarray, shape (...)

    Raises
    ------
    InvalidInputError
        Zero quaternion, wrong shape or non-finite values.

    Examples
    --------
    >>> import numpy as np
    >>> from eulerpoisson.attitude import axis_angle_from_quaternion
    >>> k, alpha = axis_angle_from_quaternion([0.5, 0.5, 0.5, 0.5])
    >>> print(np.round(k, 6), round(float(np.degrees(alpha)), 9))
    [0.57735 0.57735 0.57735] 120.0
    """
    q = _canonical(as_quaternion(q))
    v = q[..., 1:]
    s = _norm(v)
    angle = 2.0 * np.arctan2(s, q[..., 0])
    safe = np.where(s > 0, s, 1.0)
    axis = np.where((s > 0)[..., None], v / safe[..., None], np.array([0.0, 0.0, 1.0]))
    return axis, angle


def quaternion_from_rotvec(rotvec: ArrayLike) -> NDArray[np.float64]:
    r"""Quaternion of a rotation vector :math:`\boldsymbol\phi = \alpha\mathbf k` (scipy's ``rotvec``).

    .. math:: q = \left(\cos\frac\alpha2,\; \frac{\sin(\alpha/2)}{\alpha}\boldsymbol\phi\right)

    :math:`\sin(\alpha/2)/\alpha` is evaluated with ``numpy.sinc``, exact near
    zero. The angle :math:`\alpha = |\boldsymbol\phi|` is carried in
    double-double precision into :math:`\cos(\alpha/2)`, so ``w`` keeps its
    relative accuracy near :math:`\alpha=\pi` (where it is small).

    Parameters
    ----------
    rotvec : array_like, shape (..., 3)
        Any length; angles beyond :math:`\pi` are allowed.

    Returns
    -------
    ndarray, shape (..., 4)
        Not sign-canonical (``w < 0`` for :math:`\pi<\alpha<3\pi`).

    Raises
    ------
    InvalidInputError
        Wrong shape or non-finite values.

    References
    ----------
    Shuster (1993), section 5.

    Examples
    --------
    >>> import numpy as np
    >>> from eulerpoisson.attitude import quaternion_from_rotvec
    >>> print(np.round(quaternion_from_rotvec([0.0, np.pi, 0.0]), 12) + 0.0)   # 180 degrees about y
    [0. 0. 1. 0.]
    """
    r = as_float_array(rotvec, "rotvec", (3,))
    m = np.max(np.abs(r), axis=-1)
    big = m > 1e100  # angles that large carry no phase information anyway
    rs = np.where(big[..., None], 0.0, r)
    hi, lo = _sumsq_dd(rs)
    th = np.sqrt(hi)
    p, pe = _two_prod(th, th)
    safe = np.where(th > 0, th, 1.0)
    th_lo = np.where(th > 0, ((hi - p) - pe + lo) / (2.0 * safe), 0.0)
    if np.any(big):
        with np.errstate(over="ignore"):
            th = np.where(big, _norm(r / np.where(big, m, 1.0)[..., None]) * m, th)
        if not np.all(np.isfinite(th)):
            raise InvalidInputError("rotvec has a norm that overflows a float; it is not a usable angle")
    w = np.cos(0.5 * th) - np.sin(0.5 * th) * (0.5 * th_lo)
    v = (0.5 * np.sinc(th / (2 * np.pi)))[..., None] * r
    return np.concatenate([w[..., None], v], -1)


def rotvec_from_quaternion(q: ArrayLike) -> NDArray[np.float64]:
    r"""Rotation vector :math:`\alpha\mathbf k`, :math:`\alpha\in[0,\pi]`, of a quaternion.

    .. math:: \boldsymbol\phi = \frac{\alpha}{\sin(\alpha/2)}\mathbf v,
              \quad \alpha = 2\,\mathrm{atan2}(|\mathbf v|, w),\ w\ge0

    Parameters
    ----------
    q : array_like, shape (..., 4)

    Returns
    -------
    ndarray, shape (..., 3)

    Raises
    ------
    InvalidInputError
        Zero quaternion, wrong shape or non-finite values.

    Examples
    --------
    >>> import numpy as np
    >>> from eulerpoisson.attitude import rotvec_from_quaternion
    >>> print(np.round(rotvec_from_quaternion([np.cos(0.25), 0.0, 0.0, np.sin(0.25)]), 12) + 0.0)   # 0.5 rad about z
    [0.  0.  0.5]
    """
    q = _canonical(as_quaternion(q))
    s = _norm(q[..., 1:])
    th = 2.0 * np.arctan2(s, q[..., 0])
    return q[..., 1:] * (2.0 / np.sinc(th / (2 * np.pi)))[..., None]


def quaternion_from_mrp(p: ArrayLike) -> NDArray[np.float64]:
    r"""Quaternion of modified Rodrigues parameters :math:`\mathbf p = \mathbf k\tan(\alpha/4)`.

    .. math:: q = \frac{(1-\mathbf p^2,\; 2\mathbf p)}{1+\mathbf p^2}

    :math:`1-\mathbf p^2` is formed from a double-double
    :math:`\mathbf p^2`, so ``w`` keeps its relative accuracy near
    :math:`|\mathbf p| = 1` (:math:`\alpha = \pi`).

    Parameters
    ----------
    p : array_like, shape (..., 3)
        Any length (the shadow set :math:`|\mathbf p| > 1` is allowed).

    Returns
    -------
    ndarray, shape (..., 4)

    Raises
    ------
    InvalidInputError
        Wrong shape or non-finite values.

    References
    ----------
    Shuster (1993), section 9.

    Examples
    --------
    >>> import numpy as np
    >>> from eulerpoisson.attitude import quaternion_from_mrp
    >>> p = [0.0, 0.0, np.tan(np.pi / 8)]                         # k tan(alpha/4), 90 degrees about z
    >>> print(np.round(quaternion_from_mrp(p), 12))
    [0.70710678 0.         0.         0.70710678]
    """
    p = as_float_array(p, "p", (3,))
    m = np.max(np.abs(p), axis=-1)
    big = m > 1e100
    ps = np.where(big[..., None], 0.0, p)
    hi, lo = _sumsq_dd(ps)
    one_minus = (1.0 - hi) - lo
    one_plus = 1.0 + hi
    w = one_minus / one_plus
    v = 2.0 * ps / one_plus[..., None]
    # |p| huge: q -> (-1, 2p/p^2) ~ (-1, 0); compute it scaled
    if np.any(big):
        u = p / np.where(big, m, 1.0)[..., None]
        u2 = np.sum(u * u, -1)
        inv = 1.0 / np.where(big, m, 1.0)
        with np.errstate(under="ignore"):
            wb = (inv * inv - u2) / (inv * inv + u2)
            vb = 2.0 * u * (inv / (inv * inv + u2))[..., None]
        w = np.where(big, wb, w)
        v = np.where(big[..., None], vb, v)
    return np.concatenate([w[..., None], v], -1)


def mrp_from_quaternion(q: ArrayLike) -> NDArray[np.float64]:
    r"""Modified Rodrigues parameters :math:`\mathbf v/(1+w)` with ``w >= 0`` (so :math:`|\mathbf p|\le 1`).

    Parameters
    ----------
    q : array_like, shape (..., 4)

    Returns
    -------
    ndarray, shape (..., 3)

    Raises
    ------
    InvalidInputError
        Zero quaternion, wrong shape or non-finite values.

    References
    ----------
    Shuster (1993), section 9.

    Examples
    --------
    >>> import numpy as np
    >>> from eulerpoisson.attitude import mrp_from_quaternion
    >>> print(np.round(mrp_from_quaternion([0.0, 1.0, 0.0, 0.0]), 12))   # 180 degrees: |p| = 1
    [1. 0. 0.]
    """
    q = _canonical(as_quaternion(q))
    return q[..., 1:] / (1.0 + q[..., :1])


# ---------------------------------------------------------------------------
# Euler angles, all 12 sequences
# ---------------------------------------------------------------------------
_AXES = {"x": 0, "y": 1, "z": 2}


def parse_seq(seq):
    if not isinstance(seq, str) or len(seq) != 3:
        raise InvalidInputError(
            f"seq must be a 3-letter axis sequence such as 'xyz' (extrinsic) or 'ZYX' (intrinsic), got {seq!r}"
        )
    if seq.islower():
        intrinsic = False
    elif seq.isupper():
        intrinsic = True
    else:
        raise InvalidInputError(f"seq {seq!r} mixes lower case (extrinsic) and upper case (intrinsic) letters")
    s = seq.lower()
    if any(c not in _AXES for c in s):
        raise InvalidInputError(f"seq {seq!r} may only contain the axes x, y, z")
    if s[0] == s[1] or s[1] == s[2]:
        raise InvalidInputError(f"seq {seq!r}: consecutive axes must differ (12 valid sequences, e.g. 'xyz', 'zxz')")
    return [_AXES[c] for c in s], intrinsic


def quaternion_from_euler(seq: str, angles: ArrayLike, *, degrees: bool = False) -> NDArray[np.float64]:
    r"""Quaternion from Euler angles in any of the 12 sequences.

    Lower-case ``seq`` (``"xyz"``) is extrinsic: rotations about the fixed
    axes, the first applied first, :math:`R = R_{c}(\gamma)R_{b}(\beta)R_{a}(\alpha)`.
    Upper-case (``"XYZ"``) is intrinsic: about the moving axes,
    :math:`R = R_{a}(\alpha)R_{b}(\beta)R_{c}(\gamma)`. Same as scipy.

    Parameters
    ----------
    seq : str
        Three axes, consecutive ones different (Tait-Bryan such as ``"xyz"``
        or proper Euler such as ``"zxz"``).
    angles : array_like, shape (..., 3)
    degrees : bool, keyword-only
        Angles in degrees.

    Returns
    -------
    ndarray, shape (..., 4)

    Raises
    ------
    InvalidInputError
        Invalid sequence, wrong shape or non-finite angles.

    Examples
    --------
    >>> import numpy as np
    >>> from eulerpoisson.attitude import quaternion_from_euler
    >>> print(np.round(quaternion_from_euler("ZYX", [90.0, 0.0, 0.0], degrees=True), 12))   # yaw 90 degrees
    [0.70710678 0.         0.         0.70710678]
    """
    axes, intrinsic = parse_seq(seq)
    ang = as_float_array(angles, "angles", (3,))
    if as_bool(degrees, "degrees"):
        ang = np.deg2rad(ang)
    qs = []
    for i, ax in enumerate(axes):
        a = ang[..., i]
        e = np.zeros(a.shape + (4,))
        e[..., 0] = np.cos(a / 2)
        e[..., ax + 1] = np.sin(a / 2)
        qs.append(e)
    if intrinsic:
        return qmul(qmul(qs[0], qs[1]), qs[2])
    return qmul(qmul(qs[2], qs[1]), qs[0])


def _wrap_pi(x):
    """Wrap angles in [-2 pi, 2 pi] to (-pi, pi], leaving those inside untouched (no rounding)."""
    return np.where(x > np.pi, x - 2 * np.pi, np.where(x <= -np.pi, x + 2 * np.pi, x))


def euler_from_quaternion(seq: str, q: ArrayLike, *, degrees: bool = False) -> NDArray[np.float64]:
    r"""Euler angles of a quaternion in any of the 12 sequences.

    Direct method of Bernardes & Viollet (2022), with the Tait-Bryan middle
    angle computed as
    :math:`\theta_2 = 2\arctan\frac{2(w v_j - \epsilon v_i v_k)}{1+\rho\sigma}`
    instead of :math:`2\,\mathrm{atan2}(\rho,\sigma)-\pi/2`, which keeps full
    relative accuracy for small angles.

    Ranges: first and third angle in :math:`(-\pi, \pi]`, the second in
    :math:`[0, \pi]` (proper Euler) or :math:`[-\pi/2, \pi/2]` (Tait-Bryan).
    At gimbal lock (second angle :math:`0` or :math:`\pi` for proper Euler,
    :math:`\pm\pi/2` for Tait-Bryan, within :data:`EULER_GIMBAL_TOL`) only the
    sum or the difference of the first and third angles is defined: the
    *third* angle is set to zero and the first carries the rotation (as
    scipy, without a warning). Close to gimbal lock the individual first and
    third angles are ill-conditioned; the rotation they describe is not.

    Parameters
    ----------
    seq : str
        See :func:`quaternion_from_euler`.
    q : array_like, shape (..., 4)
    degrees : bool, keyword-only
        Return degrees.

    Returns
    -------
    ndarray, shape (..., 3)

    Raises
    ------
    InvalidInputError
        Invalid sequence, zero quaternion, wrong shape or non-finite values.

    References
    ----------
    Bernardes and Viollet (2022).

    Examples
    --------
    >>> import numpy as np
    >>> from eulerpoisson.attitude import euler_from_quaternion, quaternion_from_euler
    >>> q = quaternion_from_euler("ZYX", [30.0, 20.0, 10.0], degrees=True)
    >>> print(np.round(euler_from_quaternion("ZYX", q, degrees=True), 9))
    [30. 20. 10.]
    """
    axes, intrinsic = parse_seq(seq)
    q = as_quaternion(q)
    if intrinsic:
        axes = axes[::-1]  # intrinsic abc == extrinsic cba with reversed angles
    i, j, k = axes
    proper = i == k
    if proper:
        k = 3 - i - j
    sgn = float((i - j) * (j - k) * (k - i) / 2)  # permutation sign of (i, j, k)
    w, vi, vj, vk = q[..., 0], q[..., 1 + i], q[..., 1 + j], q[..., 1 + k]
    if proper:
        a, b, c, d = w, vi, vj, sgn * vk
    else:
        a, b, c, d = w - vj, vi + sgn * vk, vj + w, sgn * vk - vi
    sigma = np.hypot(a, b)
    rho = np.hypot(c, d)
    if proper:
        th2 = 2.0 * np.arctan2(rho, sigma)
    else:
        th2 = 2.0 * np.arctan2(2.0 * (w * vj - sgn * vi * vk), 1.0 + rho * sigma)
        th2 = np.clip(th2, -np.pi / 2, np.pi / 2)
    hp = np.arctan2(b, a)
    hm = np.arctan2(d, c)
    lock0 = rho <= EULER_GIMBAL_TOL * sigma  # half middle angle (B&V) ~ 0: only hp defined
    lockpi = sigma <= EULER_GIMBAL_TOL * rho  # ~ pi/2: only hm defined
    lock = lock0 | lockpi
    t1 = hp - hm
    t3 = hp + hm
    if intrinsic:  # user's third angle is the internal first one
        t3 = np.where(lock0, 2 * hp, np.where(lockpi, 2 * hm, t3))
        t1 = np.where(lock, 0.0, t1)
    else:
        t1 = np.where(lock0, 2 * hp, np.where(lockpi, -2 * hm, t1))
        t3 = np.where(lock, 0.0, t3)
    if not proper:
        t3 = sgn * t3
    out = np.stack([_wrap_pi(t1), th2, _wrap_pi(t3)], -1)
    if intrinsic:
        out = out[..., ::-1]
    return np.rad2deg(out) if as_bool(degrees, "degrees") else out


# ---------------------------------------------------------------------------
# scipy
# ---------------------------------------------------------------------------
def quaternion_from_scipy(rotation: Rotation) -> NDArray[np.float64]:
    """Scalar-first unit quaternions of a :class:`scipy.spatial.transform.Rotation`.

    Parameters
    ----------
    rotation : scipy.spatial.transform.Rotation
        Single, 1-D or (scipy >= 1.17) N-D.

    Returns
    -------
    ndarray, shape rotation's shape + (4,)

    Raises
    ------
    TypeError
        If ``rotation`` is not a scipy ``Rotation``.

    Examples
    --------
    >>> import numpy as np
    >>> from scipy.spatial.transform import Rotation
    >>> from eulerpoisson.attitude import quaternion_from_scipy
    >>> print(np.round(quaternion_from_scipy(Rotation.from_rotvec([0.0, 0.0, np.pi / 2])), 12))   # scalar first
    [0.70710678 0.         0.         0.70710678]
    """
    from scipy.spatial.transform import Rotation

    if not isinstance(rotation, Rotation):
        raise TypeError(f"rotation must be a scipy Rotation, got {type(rotation).__name__}")
    return np.roll(np.asarray(rotation.as_quat(), dtype=float), 1, axis=-1)


def scipy_from_quaternion(q: ArrayLike) -> Rotation:
    """A :class:`scipy.spatial.transform.Rotation` of scalar-first quaternions.

    Parameters
    ----------
    q : array_like, shape (4,), (N, 4) or (..., 4)
        Batches with more than one axis need scipy >= 1.17 (N-D rotations);
        older scipy raises and the batch has to be flattened explicitly.

    Returns
    -------
    scipy.spatial.transform.Rotation

    Raises
    ------
    InvalidInputError
        Zero quaternion, wrong shape, non-finite values, or a multi-axis batch
        that the installed scipy cannot hold.

    Examples
    --------
    >>> import numpy as np
    >>> from eulerpoisson.attitude import scipy_from_quaternion
    >>> r = scipy_from_quaternion([np.cos(np.pi / 4), 0.0, 0.0, np.sin(np.pi / 4)])
    >>> print(np.round(r.as_quat(), 12))                           # scipy's order is scalar last
    [0.         0.         0.70710678 0.70710678]
    """
    from scipy.spatial.transform import Rotation

    q = as_quaternion(q)
    xyzw = np.roll(q, -1, axis=-1)
    if q.ndim <= 2:
        return Rotation.from_quat(xyzw)
    try:
        return Rotation.from_quat(xyzw)
    except ValueError as exc:  # scipy < 1.17 has no N-D rotations
        raise InvalidInputError(
            f"this scipy cannot hold a batch of shape {q.shape[:-1]} (N-D rotations need scipy >= 1.17); "
            "flatten it first, e.g. attitude.reshape(-1).as_scipy()"
        ) from exc


# ---------------------------------------------------------------------------
# Gibbs <-> everything
# ---------------------------------------------------------------------------
def gibbs_from_axis_angle(axis: ArrayLike, angle: ArrayLike) -> NDArray[np.float64]:
    r"""Gibbs vector :math:`\mathbf k\tan(\alpha/2)` (paper eq. 1.8).

    Parameters
    ----------
    axis : array_like, shape (..., 3)
        Nonzero; normalized here.
    angle : array_like, shape (...)
        Radians. Angles in :math:`(\pi, 2\pi)` give :math:`\tan(\alpha/2)<0`,
        i.e. the same rotation as :math:`-\mathbf k, 2\pi-\alpha`.

    Returns
    -------
    ndarray, shape (..., 3)

    Raises
    ------
    SingularChartError
        If an angle is an odd multiple of :math:`\pi` (to the last bit).
    InvalidInputError
        Zero axis, wrong shapes or non-finite values.

    References
    ----------
    Paper eq. 1.8.

    Examples
    --------
    >>> import numpy as np
    >>> from eulerpoisson.attitude import gibbs_from_axis_angle
    >>> print(np.round(gibbs_from_axis_angle([1.0, 0.0, 0.0], 2 * np.pi / 3), 12))   # tan(60 deg) = sqrt(3)
    [1.73205081 0.         0.        ]
    """
    return _gibbs_from_unit_quaternion(quaternion_from_axis_angle(axis, angle))


def axis_angle_from_gibbs(n: ArrayLike) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    r"""Axis and angle :math:`\alpha = 2\arctan|\mathbf n|\in[0,\pi)` of a Gibbs vector (paper eq. 1.8).

    Parameters
    ----------
    n : array_like, shape (..., 3)

    Returns
    -------
    axis : ndarray, shape (..., 3)
        :math:`\mathbf n/|\mathbf n|`; ``(0, 0, 1)`` for ``n = 0``.
    angle : ndarray, shape (...)

    Raises
    ------
    InvalidInputError
        Wrong shape or non-finite values.

    References
    ----------
    Paper eq. 1.8.

    Examples
    --------
    >>> import numpy as np
    >>> from eulerpoisson.attitude import axis_angle_from_gibbs
    >>> k, alpha = axis_angle_from_gibbs([0.0, 3.0, 4.0])
    >>> print(k, round(float(alpha), 12), round(float(2 * np.arctan(5.0)), 12))
    [0.  0.6 0.8] 2.74680153389 2.74680153389
    """
    return axis_angle_from_quaternion(quaternion_from_gibbs(n))


def gibbs_from_rotvec(rotvec: ArrayLike) -> NDArray[np.float64]:
    r"""Gibbs vector :math:`\mathbf k\tan(\alpha/2)` of a rotation vector :math:`\alpha\mathbf k`.

    Parameters
    ----------
    rotvec : array_like, shape (..., 3)

    Returns
    -------
    ndarray, shape (..., 3)

    Raises
    ------
    SingularChartError
        At angle :math:`\pi` (or an odd multiple).
    InvalidInputError
        Wrong shape or non-finite values.

    References
    ----------
    Paper eq. 1.8.

    Examples
    --------
    >>> import numpy as np
    >>> from eulerpoisson.attitude import gibbs_from_rotvec
    >>> print(np.round(gibbs_from_rotvec([0.0, 0.0, np.pi / 2]), 12))   # tan(45 deg) = 1
    [0. 0. 1.]
    """
    return _gibbs_from_unit_quaternion(as_quaternion(quaternion_from_rotvec(rotvec)), "rotvec")


def rotvec_from_gibbs(n: ArrayLike) -> NDArray[np.float64]:
    r"""Rotation vector :math:`2\arctan(|\mathbf n|)\,\mathbf n/|\mathbf n|` (scipy's :math:`\alpha\mathbf k`).

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
    Paper eq. 1.8.

    Examples
    --------
    >>> import numpy as np
    >>> from eulerpoisson.attitude import rotvec_from_gibbs
    >>> print(np.round(rotvec_from_gibbs([0.0, 0.0, 1.0]) / np.pi, 12))   # pi/2 about z
    [0.  0.  0.5]
    """
    return rotvec_from_quaternion(quaternion_from_gibbs(n))


def gibbs_from_mrp(p: ArrayLike) -> NDArray[np.float64]:
    r"""Gibbs vector :math:`2\mathbf p/(1-\mathbf p^2)` of modified Rodrigues parameters.

    Parameters
    ----------
    p : array_like, shape (..., 3)

    Returns
    -------
    ndarray, shape (..., 3)

    Raises
    ------
    SingularChartError
        At :math:`|\mathbf p| = 1` (angle :math:`\pi`).
    InvalidInputError
        Wrong shape or non-finite values.

    Examples
    --------
    >>> from eulerpoisson.attitude import gibbs_from_mrp
    >>> print(gibbs_from_mrp([0.0, 0.5, 0.0]))                    # 2p / (1 - p^2)
    [0.         1.33333333 0.        ]
    """
    return _gibbs_from_unit_quaternion(as_quaternion(quaternion_from_mrp(p)), "p")


def mrp_from_gibbs(n: ArrayLike) -> NDArray[np.float64]:
    r"""Modified Rodrigues parameters :math:`\mathbf n/(1+\sqrt{1+\mathbf n^2})` of a Gibbs vector.

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

    Examples
    --------
    >>> import numpy as np
    >>> from eulerpoisson.attitude import mrp_from_gibbs
    >>> print(np.round(mrp_from_gibbs([0.0, 4.0 / 3.0, 0.0]), 12))   # n / (1 + sqrt(1 + n^2))
    [0.  0.5 0. ]
    """
    return mrp_from_quaternion(quaternion_from_gibbs(n))


def gibbs_from_euler(seq: str, angles: ArrayLike, *, degrees: bool = False) -> NDArray[np.float64]:
    r"""Gibbs vector from Euler angles (see :func:`quaternion_from_euler`).

    Parameters
    ----------
    seq : str
    angles : array_like, shape (..., 3)
    degrees : bool, keyword-only

    Returns
    -------
    ndarray, shape (..., 3)

    Raises
    ------
    SingularChartError
        If the rotation angle is :math:`\pi`.
    InvalidInputError
        Invalid sequence, wrong shape or non-finite values.

    Examples
    --------
    >>> import numpy as np
    >>> from eulerpoisson.attitude import gibbs_from_euler
    >>> print(np.round(gibbs_from_euler("xyz", [0.0, 0.0, 90.0], degrees=True), 12))   # 90 degrees about z
    [0. 0. 1.]
    """
    return _gibbs_from_unit_quaternion(as_quaternion(quaternion_from_euler(seq, angles, degrees=degrees)))


def euler_from_gibbs(seq: str, n: ArrayLike, *, degrees: bool = False) -> NDArray[np.float64]:
    """Euler angles of a Gibbs vector (see :func:`euler_from_quaternion`).

    Parameters
    ----------
    seq : str
    n : array_like, shape (..., 3)
    degrees : bool, keyword-only

    Returns
    -------
    ndarray, shape (..., 3)

    Raises
    ------
    InvalidInputError
        Invalid sequence, wrong shape or non-finite values.

    Examples
    --------
    >>> import numpy as np
    >>> from eulerpoisson.attitude import euler_from_gibbs
    >>> print(np.round(euler_from_gibbs("ZYX", [0.0, 0.0, 1.0], degrees=True), 9) + 0.0)
    [90.  0.  0.]
    """
    return euler_from_quaternion(seq, quaternion_from_gibbs(n), degrees=degrees)


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
    s1 = np.where(m1 > 1.0, _pow2_below(np.maximum(m1, 1.0)), 1.0)
    s2 = np.where(m2 > 1.0, _pow2_below(np.maximum(m2, 1.0)), 1.0)
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
            f"gibbs_compose: n1 . n2 = 1{_first_index(bad)}: the product is a rotation by pi where "
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
    rel = qmul(q0 * _CONJ, q)
    w = rel[..., 0]
    with np.errstate(divide="ignore", over="ignore", invalid="ignore"):
        n = rel[..., 1:] / w[..., None]
    bad = (w == 0) | ~np.all(np.isfinite(n), -1)
    if np.any(bad):
        raise SingularChartError(
            f"the attitude{_first_index(bad)} is a rotation by pi relative to the chart reference, where "
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
        return w * (w * np.eye(3) + _skew(q[..., 1:]))


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
    return np.eye(3) + _outer(n, n) - _skew(n)


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
        Wrong shape or non-finite values.

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
    return _A(n) @ np.swapaxes(_At(n), -1, -2)


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
    return 2.0 * np.einsum("...ji,...j->...i", _A(n), nd)


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
    return 0.5 * (w + np.cross(n, w) + np.sum(n * w, -1)[..., None] * n)


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


# ---------------------------------------------------------------------------
# the Attitude class
# ---------------------------------------------------------------------------
def _check_attitude(other, name="other"):
    if not isinstance(other, Attitude):
        raise TypeError(f"{name} must be an Attitude, got {type(other).__name__}")
    return other


def _ref_quaternion(reference):
    return reference._q if isinstance(reference, Attitude) else reference


class Attitude:
    r"""A batch of attitudes (rotations), stored as unit quaternions.

    A thin object over the ``<to>_from_<from>`` functions of this module, in
    the style of :class:`scipy.spatial.transform.Rotation`. ``a * b`` (or
    ``a @ b``) is the rotation :math:`R_a R_b`; ``a.inv()`` the inverse;
    ``a.apply(v)`` rotates body vectors into space (``x_space = R x_body``).

    Parameters
    ----------
    quaternion : array_like, shape (..., 4), or Attitude
        Scalar-first quaternions, normalized on construction (sign kept).

    Raises
    ------
    InvalidInputError
        Zero quaternion, wrong shape or non-finite values.

    Notes
    -----
    The batch shape is ``quaternion.shape[:-1]``; indexing, ``len`` and
    iteration act on it. Operations broadcast over batch shapes like numpy.

    Examples
    --------
    >>> from eulerpoisson import Attitude
    >>> a = Attitude.from_gibbs([0.0, 0.0, 1.0])   # 90 degrees about z
    >>> a.as_rotvec().round(6)
    array([0.      , 0.      , 1.570796])
    >>> (a * a).as_quaternion(canonical=True).round(12)  # 180 degrees: as_gibbs() would raise
    array([0., 0., 0., 1.])
    """

    __slots__ = ("_q",)
    __array_ufunc__ = None  # keep numpy from broadcasting over Attitude objects
    _q: np.ndarray

    def __init__(self, quaternion: Attitude | ArrayLike) -> None:
        if isinstance(quaternion, Attitude):
            self._q = quaternion._q.copy()
        else:
            self._q = as_quaternion(quaternion, "quaternion")

    # factories ------------------------------------------------------------
    @classmethod
    def identity(cls, shape: int | tuple[int, ...] = ()) -> Attitude:
        """The identity rotation.

        Parameters
        ----------
        shape : int or tuple of int
            Batch shape.

        Returns
        -------
        Attitude
        """
        shape = as_shape(shape)
        q = np.zeros(shape + (4,))
        q[..., 0] = 1.0
        return cls(q)

    @classmethod
    def random(cls, shape: int | tuple[int, ...] = (), rng: int | np.random.Generator | None = None) -> Attitude:
        """Uniformly (Haar) distributed random rotations: normalized Gaussian quaternions.

        Parameters
        ----------
        shape : int or tuple of int
            Batch shape.
        rng : None, int or numpy.random.Generator
            Anything :func:`numpy.random.default_rng` accepts.

        Returns
        -------
        Attitude
        """
        rng = np.random.default_rng(rng)
        shape = as_shape(shape)
        return cls(rng.standard_normal(shape + (4,)))

    @classmethod
    def from_quaternion(cls, q: ArrayLike) -> Attitude:
        """From scalar-first quaternions.

        Parameters
        ----------
        q : array_like, shape (..., 4)
            Normalized here; the sign is kept.

        Returns
        -------
        Attitude

        Raises
        ------
        InvalidInputError
            Zero quaternion, wrong shape or non-finite values.
        """
        return cls(q)

    @classmethod
    def from_gibbs(cls, n: ArrayLike) -> Attitude:
        """From the paper's Gibbs vectors (eq. 1.8-1.9).

        Parameters
        ----------
        n : array_like, shape (..., 3)

        Returns
        -------
        Attitude

        Raises
        ------
        InvalidInputError
            Wrong shape or non-finite values.
        """
        return cls(quaternion_from_gibbs(n))

    @classmethod
    def from_matrix(cls, R: ArrayLike, *, atol: float = 1e-6) -> Attitude:
        """From rotation matrices (see :func:`quaternion_from_matrix`).

        Parameters
        ----------
        R : array_like, shape (..., 3, 3)
        atol : float, keyword-only
            Orthogonality tolerance.

        Returns
        -------
        Attitude

        Raises
        ------
        InvalidInputError
            Not a rotation matrix, wrong shape or non-finite values.
        """
        return cls(quaternion_from_matrix(R, atol=atol))

    @classmethod
    def from_axis_angle(cls, axis: ArrayLike, angle: ArrayLike) -> Attitude:
        """From rotation axes and angles.

        Parameters
        ----------
        axis : array_like, shape (..., 3)
            Nonzero; normalized here.
        angle : array_like, shape (...)
            Radians, counterclockwise about ``axis`` (paper eq. 1.7).

        Returns
        -------
        Attitude

        Raises
        ------
        InvalidInputError
            Zero axis, shapes that do not broadcast, non-finite values.
        """
        return cls(quaternion_from_axis_angle(axis, angle))

    @classmethod
    def from_rotvec(cls, rotvec: ArrayLike) -> Attitude:
        """From rotation vectors :math:`\\alpha\\mathbf k` (scipy's rotvec).

        Parameters
        ----------
        rotvec : array_like, shape (..., 3)

        Returns
        -------
        Attitude

        Raises
        ------
        InvalidInputError
            Wrong shape or non-finite values.
        """
        return cls(quaternion_from_rotvec(rotvec))

    @classmethod
    def from_mrp(cls, p: ArrayLike) -> Attitude:
        """From modified Rodrigues parameters :math:`\\mathbf k\\tan(\\alpha/4)`.

        Parameters
        ----------
        p : array_like, shape (..., 3)

        Returns
        -------
        Attitude

        Raises
        ------
        InvalidInputError
            Wrong shape or non-finite values.
        """
        return cls(quaternion_from_mrp(p))

    @classmethod
    def from_euler(cls, seq: str, angles: ArrayLike, *, degrees: bool = False) -> Attitude:
        """From Euler angles (see :func:`quaternion_from_euler`).

        Parameters
        ----------
        seq : str
            As in scipy: ``'xyz'`` extrinsic, ``'XYZ'`` intrinsic, 12 sequences each.
        angles : array_like, shape (..., 3)
        degrees : bool, keyword-only

        Returns
        -------
        Attitude

        Raises
        ------
        InvalidInputError
            Invalid sequence, wrong shape or non-finite values.
        """
        return cls(quaternion_from_euler(seq, angles, degrees=degrees))

    @classmethod
    def from_scipy(cls, rotation: Rotation) -> Attitude:
        """From a :class:`scipy.spatial.transform.Rotation`, keeping its batch shape.

        Parameters
        ----------
        rotation : scipy.spatial.transform.Rotation

        Returns
        -------
        Attitude

        Raises
        ------
        TypeError
            If ``rotation`` is not a scipy ``Rotation``.
        """
        return cls(quaternion_from_scipy(rotation))

    @classmethod
    def from_chart(cls, reference: Attitude | ArrayLike, n: ArrayLike) -> Attitude:
        """From local Gibbs vectors in the chart at ``reference``: :math:`R = R_0R(\\mathbf n)`.

        Parameters
        ----------
        reference : Attitude or array_like, shape (..., 4)
            Chart centres.
        n : array_like, shape (..., 3)
            Local Gibbs vectors.

        Returns
        -------
        Attitude

        Raises
        ------
        InvalidInputError
            Zero reference, wrong shapes or non-finite values.
        """
        return cls(quaternion_from_chart(_ref_quaternion(reference), n))

    # views ----------------------------------------------------------------
    def as_quaternion(self, canonical: bool = False) -> NDArray[np.float64]:
        """Unit scalar-first quaternions (a copy).

        Parameters
        ----------
        canonical : bool
            Choose the sign with ``w >= 0`` (see :func:`quaternion_canonical`).

        Returns
        -------
        ndarray, shape (..., 4)
        """
        return _canonical(self._q) if as_bool(canonical, "canonical") else self._q.copy()

    def as_gibbs(self) -> NDArray[np.float64]:
        """The paper's Gibbs vectors :math:`\\mathbf n = \\mathbf k\\tan(\\alpha/2)` (eq. 1.8).

        Returns
        -------
        ndarray, shape (..., 3)

        Raises
        ------
        SingularChartError
            At rotation angle :math:`\\pi`; use :meth:`as_quaternion` or :meth:`as_chart`.
        """
        return _gibbs_from_unit_quaternion(self._q)

    def as_chart(self, reference: Attitude | ArrayLike) -> NDArray[np.float64]:
        """Local Gibbs vectors relative to ``reference`` (see :func:`gibbs_chart`).

        Parameters
        ----------
        reference : Attitude or array_like, shape (..., 4)

        Returns
        -------
        ndarray, shape (..., 3)

        Raises
        ------
        SingularChartError
            If an attitude is a rotation by :math:`\\pi` relative to its reference.
        """
        return gibbs_chart(self._q, _ref_quaternion(reference))

    def as_matrix(self) -> NDArray[np.float64]:
        """Rotation matrices (paper eq. 1.9).

        Returns
        -------
        ndarray, shape (..., 3, 3)
        """
        return matrix_from_unit_quaternion(self._q)

    def as_axis_angle(self) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """Unit axes and angles in :math:`[0, \\pi]`.

        Returns
        -------
        axis : ndarray, shape (..., 3)
        angle : ndarray, shape (...)
        """
        return axis_angle_from_quaternion(self._q)

    def as_rotvec(self) -> NDArray[np.float64]:
        """Rotation vectors :math:`\\alpha\\mathbf k` with :math:`\\alpha\\in[0,\\pi]`.

        Returns
        -------
        ndarray, shape (..., 3)
        """
        return rotvec_from_quaternion(self._q)

    def as_mrp(self) -> NDArray[np.float64]:
        """Modified Rodrigues parameters with norm <= 1.

        Returns
        -------
        ndarray, shape (..., 3)
        """
        return mrp_from_quaternion(self._q)

    def as_euler(self, seq: str, *, degrees: bool = False) -> NDArray[np.float64]:
        """Euler angles (see :func:`euler_from_quaternion` for ranges and gimbal lock).

        Parameters
        ----------
        seq : str
        degrees : bool, keyword-only

        Returns
        -------
        ndarray, shape (..., 3)

        Raises
        ------
        InvalidInputError
            Invalid sequence.
        """
        return euler_from_quaternion(seq, self._q, degrees=degrees)

    def as_scipy(self) -> Rotation:
        """A :class:`scipy.spatial.transform.Rotation` with the same batch shape.

        Multi-axis batches are kept as N-D rotations (scipy >= 1.17); they are
        never flattened silently: with an older scipy this raises, and
        ``self.reshape(-1).as_scipy()`` gives the flattened batch.

        Returns
        -------
        scipy.spatial.transform.Rotation

        Raises
        ------
        InvalidInputError
            A multi-axis batch with a scipy older than 1.17.
        """
        return scipy_from_quaternion(self._q)

    # algebra --------------------------------------------------------------
    def __mul__(self, other: Attitude) -> Attitude:
        """``a * b``: the rotation :math:`R_aR_b` (apply ``b`` first); batch shapes broadcast."""
        if not isinstance(other, Attitude):
            return NotImplemented
        check_broadcast(self=self._q, other=other._q)
        return Attitude(qmul(self._q, other._q))

    __matmul__ = __mul__

    def inv(self) -> Attitude:
        """The inverse rotations, :math:`R^T`.

        Returns
        -------
        Attitude
        """
        return Attitude(self._q * _CONJ)

    def apply(self, vectors: ArrayLike, inverse: bool = False) -> NDArray[np.float64]:
        """Rotate vectors: ``R v`` (body to space) or ``R^T v`` with ``inverse=True``.

        Parameters
        ----------
        vectors : array_like, shape (..., 3)
            Broadcast against the batch shape.
        inverse : bool

        Returns
        -------
        ndarray, shape (..., 3)

        Raises
        ------
        InvalidInputError
            Wrong shape or non-finite values.
        """
        v = as_float_array(vectors, "vectors", (3,))
        R = self.as_matrix()
        if as_bool(inverse, "inverse"):
            R = np.swapaxes(R, -1, -2)
        return np.einsum("...ij,...j->...i", R, v)

    def magnitude(self) -> NDArray[np.float64]:
        """Rotation angles in :math:`[0, \\pi]`.

        Returns
        -------
        ndarray, shape (...)
        """
        return self.as_axis_angle()[1]

    def angle_to(self, other: Attitude) -> NDArray[np.float64]:
        """Angle of the rotation taking ``self`` to ``other``: the angle of :math:`R_\\mathrm{self}^TR_\\mathrm{other}`.

        The geodesic (bi-invariant) distance on SO(3), computed with
        ``atan2`` (accurate for tiny and for near-:math:`\\pi` angles).

        Parameters
        ----------
        other : Attitude
            Batch shapes broadcast.

        Returns
        -------
        ndarray, shape (...)
            Radians in :math:`[0, \\pi]`.

        Raises
        ------
        TypeError
            If ``other`` is not an Attitude.
        """
        other = _check_attitude(other)
        check_broadcast(self=self._q, other=other._q)
        rel = qmul(self._q * _CONJ, other._q)
        return 2.0 * np.arctan2(_norm(rel[..., 1:]), np.abs(rel[..., 0]))

    # container ------------------------------------------------------------
    @property
    def shape(self) -> tuple[int, ...]:
        """Batch shape (the quaternion array's shape without the last axis)."""
        return self._q.shape[:-1]

    @property
    def ndim(self) -> int:
        """Number of batch axes."""
        return self._q.ndim - 1

    @property
    def size(self) -> int:
        """Number of attitudes in the batch."""
        return int(np.prod(self.shape, dtype=int))

    def reshape(self, *shape: int | tuple[int, ...]) -> Attitude:
        """The same attitudes with a new batch shape.

        Parameters
        ----------
        *shape : int or tuple of int
            As :meth:`numpy.ndarray.reshape`, on the batch axes only.

        Returns
        -------
        Attitude

        Raises
        ------
        ValueError
            If the sizes do not match.
        """
        if len(shape) == 1 and not isinstance(shape[0], (int, np.integer)):
            shape = tuple(shape[0])
        return Attitude(self._q.reshape(tuple(shape) + (4,)))

    def __len__(self) -> int:
        if not self.shape:
            raise TypeError("a single Attitude has no len()")
        return self.shape[0]

    def __getitem__(self, idx: Any) -> Attitude:
        """Attitudes of the batch; indexes the batch axes only, never the quaternion axis."""
        if not self.shape:
            raise TypeError("a single Attitude cannot be indexed")
        pos = np.arange(self.size).reshape(self.shape)[idx]
        return Attitude(self._q.reshape(-1, 4)[pos])

    def __iter__(self) -> Iterator[Attitude]:
        if not self.shape:
            raise TypeError("a single Attitude is not iterable")
        for i in range(self.shape[0]):
            yield self[i]

    def __repr__(self) -> str:
        if self.shape == ():
            w, x, y, z = self._q
            return f"Attitude(quaternion=[{w:.6g}, {x:.6g}, {y:.6g}, {z:.6g}])"
        return f"Attitude(shape={self.shape})"
