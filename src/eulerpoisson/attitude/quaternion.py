r"""Unit quaternions: the Hamilton product, normalization, sign, rotation matrices and scipy rotations.

Conventions
-----------
* ``x_space = R @ x_body`` and :math:`\dot R = R[\Omega]_\times` with
  :math:`\Omega` the body angular velocity (paper eq. 1.4).
* Quaternions are scalar first ``(w, x, y, z)`` with the Hamilton product; the
  rotation matrix of ``q`` is the active rotation
  :math:`R = (w^2-\mathbf v^2)\mathbf 1 + 2\mathbf v\mathbf v^T + 2w[\mathbf v]_\times`.
* Functions are named ``<to>_from_<from>``. Representations: ``quaternion``
  (..., 4), ``matrix`` (..., 3, 3) and ``scipy``
  (:class:`scipy.spatial.transform.Rotation`); the Gibbs vector is in
  :mod:`.gibbs`, axis-angle, rotation vectors and MRPs in :mod:`.rotvec`,
  Euler angles in :mod:`.euler`.

References
----------
S. W. Shepperd, "Quaternion from rotation matrix", J. Guidance Control 1 (1978) 223-224.
"""

from __future__ import annotations

import operator
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..errors import InvalidInputError
from ..numerics.quaternion import qmul
from ..util.validate import as_float_array, as_scalar, check_broadcast
from .common import finite_result, first_index, norm, outer, pow2_below, skew_unchecked

if TYPE_CHECKING:
    from scipy.spatial.transform import Rotation

__all__ = [
    "UNIT_QUATERNION_TOLERANCE",
    "quaternion_multiply",
    "quaternion_conjugate",
    "quaternion_normalize",
    "quaternion_canonical",
    "quaternion_make_continuous",
    "matrix_from_quaternion",
    "quaternion_from_matrix",
    "quaternion_from_scipy",
    "scipy_from_quaternion",
]

#: largest ``| |q| - 1 |`` accepted where a unit quaternion is required (a float32-rounded unit quaternion is
#: off by about 3e-8); inputs within it are renormalized, inputs beyond it are refused
UNIT_QUATERNION_TOLERANCE = 1e-6

#: multiply a quaternion (..., 4) by this to get its conjugate ``(w, -x, -y, -z)``
CONJUGATE_SIGNS = np.array([1.0, -1.0, -1.0, -1.0])


def as_quaternion(q, name="q") -> np.ndarray:
    """Validate and normalize quaternions (power-of-two prescaling: no overflow/underflow)."""
    q = as_float_array(q, name, (4,))
    m = np.max(np.abs(q), axis=-1)
    if np.any(m == 0):
        raise InvalidInputError(f"{name} contains a zero quaternion{first_index(m == 0)}, which is not a rotation")
    qs = q / pow2_below(m)[..., None]
    return qs / norm(qs)[..., None]


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
    return q * CONJUGATE_SIGNS


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
    return canonical_unit_quaternion(as_quaternion(q))


def canonical_unit_quaternion(q: np.ndarray) -> np.ndarray:
    """:func:`quaternion_canonical` of already normalized quaternions, without the checks."""
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
    a, b = qm[1:], qm[:-1]
    # the dot products summed in order, as np.sum over the last axis does (component arrays: several times faster)
    dots = a[..., 0] * b[..., 0] + a[..., 1] * b[..., 1] + a[..., 2] * b[..., 2] + a[..., 3] * b[..., 3]
    flips = np.empty(qm.shape[:-1], dtype=np.int64)
    flips[0] = 0
    np.cumsum(dots < 0, axis=0, out=flips[1:])
    if not flips[-1].any():
        return q.copy()  # (the count is nondecreasing: no flip anywhere)
    sign = 1.0 - 2.0 * (flips & 1)
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
    return R + 2.0 * outer(v, v) + 2.0 * w[..., None, None] * skew_unchecked(v)


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
            f"{det.ravel()[i]:.6g}{first_index(bad)}"
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
    q = q / norm(q)[..., None]
    return np.where(q[..., :1] < 0, -q, q)


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
