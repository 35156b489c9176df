r"""Axis-angle, the rotation vector alpha k (scipy's ``rotvec``) and modified Rodrigues parameters.

Representations: ``axis_angle`` (``(k, alpha)`` with shapes (..., 3) and (...)),
``rotvec`` (scipy's :math:`\alpha\mathbf k`, (..., 3)) and ``mrp`` (modified
Rodrigues parameters :math:`\mathbf k\tan(\alpha/4)`, (..., 3)), converted to
and from unit quaternions and the paper's Gibbs vector, all batched over
leading axes.

Numerical notes
---------------
* Near :math:`\alpha = \pi` the conversion into the Gibbs vector has relative
  condition number about :math:`1/(\pi-\alpha)` (see :mod:`.gibbs`). Rotation
  vectors and MRPs are converted with a double-double sum of squares, so for
  them the result is accurate to a few ulps of the exact value for the given
  floating-point input.
* Near the identity all conversions keep full *relative* accuracy of small
  vectors (no ``1 - cos`` cancellation).

References
----------
M. D. Shuster, "A survey of attitude representations", J. Astronaut. Sci. 41
(1993) 439-517.
T. J. Dekker, "A floating-point technique for extending the available
precision", Numer. Math. 18 (1971) 224-242.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..errors import InvalidInputError
from ..numerics.doubledouble import sum_of_squares as _sumsq_dd
from ..numerics.doubledouble import two_prod as _two_prod
from ..util.validate import as_float_array
from .common import first_index, norm, pow2_below, scaled_norm
from .gibbs import gibbs_from_unit_quaternion, quaternion_from_gibbs
from .quaternion import as_quaternion, canonical_unit_quaternion

__all__ = [
    "quaternion_from_axis_angle",
    "axis_angle_from_quaternion",
    "quaternion_from_rotvec",
    "rotvec_from_quaternion",
    "quaternion_from_mrp",
    "mrp_from_quaternion",
    "gibbs_from_axis_angle",
    "axis_angle_from_gibbs",
    "gibbs_from_rotvec",
    "rotvec_from_gibbs",
    "gibbs_from_mrp",
    "mrp_from_gibbs",
]


# ---------------------------------------------------------------------------
# axis-angle, rotation vector, MRP <-> quaternion
# ---------------------------------------------------------------------------
def _unit_axis(axis, name="axis"):
    k = as_float_array(axis, name, (3,))
    m = np.max(np.abs(k), axis=-1)
    if np.any(m == 0):
        raise InvalidInputError(f"{name} contains a zero vector{first_index(m == 0)}; a rotation axis must be nonzero")
    k = k / pow2_below(m)[..., None]
    return k / norm(k)[..., None]


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
    q = canonical_unit_quaternion(as_quaternion(q))
    v = q[..., 1:]
    s = scaled_norm(v)  # (angles below 1e-146: the plain norm's squares are subnormal)
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
            th = np.where(big, norm(r / np.where(big, m, 1.0)[..., None]) * m, th)
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
    q = canonical_unit_quaternion(as_quaternion(q))
    s = norm(q[..., 1:])
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
    q = canonical_unit_quaternion(as_quaternion(q))
    return q[..., 1:] / (1.0 + q[..., :1])


# ---------------------------------------------------------------------------
# axis-angle, rotation vector, MRP <-> Gibbs vector
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
    return gibbs_from_unit_quaternion(quaternion_from_axis_angle(axis, angle))


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
    return gibbs_from_unit_quaternion(as_quaternion(quaternion_from_rotvec(rotvec)), "rotvec")


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
    return gibbs_from_unit_quaternion(as_quaternion(quaternion_from_mrp(p)), "p")


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
