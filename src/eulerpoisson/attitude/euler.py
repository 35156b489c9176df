r"""Euler angles in all 12 sequences, to and from unit quaternions and the Gibbs vector.

A sequence string is as in scipy: lower case (``"xyz"``) extrinsic, upper case
(``"XYZ"``) intrinsic; Tait-Bryan (``"xyz"``) and proper Euler (``"zxz"``)
sequences are both accepted. Angles are (..., 3), batched over leading axes.

References
----------
E. Bernardes and S. Viollet, "Quaternion to Euler angles conversion: a direct,
general and computationally efficient method", PLoS ONE 17 (2022) e0276302.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..errors import InvalidInputError
from ..numerics.quaternion import qmul
from ..util.validate import as_bool, as_float_array
from .gibbs import gibbs_from_unit_quaternion, quaternion_from_gibbs
from .quaternion import as_quaternion

__all__ = [
    "quaternion_from_euler",
    "euler_from_quaternion",
    "gibbs_from_euler",
    "euler_from_gibbs",
    "EULER_GIMBAL_TOL",
]

#: Gimbal lock is declared in :func:`euler_from_quaternion` when the sine (or
#: cosine) of the half middle angle is below this fraction of the other; the
#: rotation error introduced by zeroing the third angle is at most about
#: twice this value.
EULER_GIMBAL_TOL = 1e-14

_AXES = {"x": 0, "y": 1, "z": 2}


def parse_seq(seq):
    """``([i, j, k], intrinsic)`` of a validated sequence string (axis indices 0, 1, 2)."""
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
# Euler angles <-> Gibbs vector
# ---------------------------------------------------------------------------
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
    return gibbs_from_unit_quaternion(as_quaternion(quaternion_from_euler(seq, angles, degrees=degrees)))


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
