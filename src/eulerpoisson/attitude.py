r"""Attitude sets centred on the paper's rotation vector.

The paper parametrizes a rotation by the *Gibbs vector* (paper eq. 1.8)

.. math:: \mathbf n = \mathbf k \tan(\alpha/2), \qquad 0 \le \alpha < \pi,

which is the vector part of a unit quaternion divided by its scalar part,
:math:`\mathbf n = \mathbf q/q_0` (footnote to eq. 1.9). This module converts
between the Gibbs vector and the usual attitude sets, all batched over leading
axes, and provides the paper's matrices :math:`A(\mathbf n)`,
:math:`\tilde A(\mathbf n)` (eq. 1.12) and the metric :math:`G(\mathbf n)`
(eq. 1.13-1.14).

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
  :math:`\mathbf k\tan(\alpha/4)`, (..., 3)) and ``euler`` (..., 3) with a
  sequence string as in scipy (``"xyz"`` extrinsic, ``"XYZ"`` intrinsic).

The global Gibbs vector is infinite at :math:`\alpha=\pi` (``w = 0``):
converting such an attitude raises :class:`~eulerpoisson.errors.SingularChartError`.
A *chart* (:func:`gibbs_chart`, :func:`quaternion_from_chart`) writes
:math:`R = R_0 R(\mathbf n)` around a reference attitude :math:`R_0` so a
trajectory can continue through :math:`\alpha=\pi`.

References
----------
A. A. Deriglazov, *Geodesic motion on the symplectic leaf of SO(3) with
distorted e(3) algebra and Liouville integrability of a free rigid body*
(the paper), eqs. 1.7-1.14.
M. D. Shuster, "A survey of attitude representations", J. Astronaut. Sci. 41
(1993) 439-517.
E. Bernardes and S. Viollet, "Quaternion to Euler angles conversion: a direct,
general and computationally efficient method", PLoS ONE 17 (2022) e0276302.
"""

from __future__ import annotations

import numpy as np

from ._validate import as_float_array
from .errors import InvalidInputError, SingularChartError

__all__ = [
    "Attitude",
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
]

_EPS = np.finfo(float).eps


# ---------------------------------------------------------------------------
# small helpers
# ---------------------------------------------------------------------------
def skew(v) -> np.ndarray:
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
    """
    v = as_float_array(v, "v", (3,))
    return _skew(v)


def _skew(v: np.ndarray) -> np.ndarray:
    x, y, z = v[..., 0], v[..., 1], v[..., 2]
    o = np.zeros_like(x)
    return np.stack(
        [np.stack([o, -z, y], -1), np.stack([z, o, -x], -1), np.stack([-y, x, o], -1)], -2
    )


def unskew(S) -> np.ndarray:
    r"""Vector of the antisymmetric part of ``S``: the inverse of :func:`skew`.

    Parameters
    ----------
    S : array_like, shape (..., 3, 3)

    Returns
    -------
    ndarray, shape (..., 3)
        :math:`v_k = -\tfrac12\epsilon_{kij}S_{ij}`, as in eq. 1.10.
    """
    S = as_float_array(S, "S", (3, 3))
    return 0.5 * np.stack(
        [S[..., 2, 1] - S[..., 1, 2], S[..., 0, 2] - S[..., 2, 0], S[..., 1, 0] - S[..., 0, 1]], -1
    )


def _outer(a, b):
    return a[..., :, None] * b[..., None, :]


def _norm(v):
    return np.sqrt(np.sum(v * v, axis=-1))


def _eye_like(x):
    return np.broadcast_to(np.eye(3), x.shape[:-1] + (3, 3))


# ---------------------------------------------------------------------------
# quaternions
# ---------------------------------------------------------------------------
def _as_quaternion(q, name="q", normalize=True) -> np.ndarray:
    q = as_float_array(q, name, (4,))
    nrm = _norm(q)
    if np.any(nrm == 0):
        raise InvalidInputError(f"{name} contains a zero quaternion, which is not a rotation")
    return q / nrm[..., None] if normalize else q


def quaternion_multiply(p, q) -> np.ndarray:
    r"""Hamilton product :math:`p\otimes q` of scalar-first quaternions.

    The rotation of :math:`p\otimes q` is :math:`R(p)R(q)`.

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
    """
    p = as_float_array(p, "p", (4,))
    q = as_float_array(q, "q", (4,))
    return _qmul(p, q)


def _qmul(p, q):
    pw, px, py, pz = np.moveaxis(p, -1, 0)
    qw, qx, qy, qz = np.moveaxis(q, -1, 0)
    return np.stack(
        [
            pw * qw - px * qx - py * qy - pz * qz,
            pw * qx + px * qw + py * qz - pz * qy,
            pw * qy - px * qz + py * qw + pz * qx,
            pw * qz + px * qy - py * qx + pz * qw,
        ],
        -1,
    )


def quaternion_conjugate(q) -> np.ndarray:
    """Conjugate ``(w, -x, -y, -z)``: the inverse rotation of a unit quaternion.

    Parameters
    ----------
    q : array_like, shape (..., 4)

    Returns
    -------
    ndarray, shape (..., 4)
    """
    q = as_float_array(q, "q", (4,))
    return q * np.array([1.0, -1.0, -1.0, -1.0])


def quaternion_normalize(q) -> np.ndarray:
    """Scale quaternions to unit norm.

    Raises
    ------
    InvalidInputError
        Zero quaternion, wrong shape or non-finite values.
    """
    return _as_quaternion(q)


def quaternion_canonical(q) -> np.ndarray:
    """Unit quaternion with the sign chosen so that ``w >= 0``.

    For ``w = 0`` the first nonzero vector component is made positive, so the
    result is unique for every rotation.

    Parameters
    ----------
    q : array_like, shape (..., 4)

    Returns
    -------
    ndarray, shape (..., 4)
    """
    q = _as_quaternion(q)
    return _canonical(q)


def _canonical(q):
    # sign of the first nonzero component
    nz = q != 0
    first = np.argmax(nz, axis=-1)
    lead = np.take_along_axis(q, first[..., None], axis=-1)
    return np.where(lead < 0, -q, q)


def quaternion_make_continuous(q, axis: int = 0) -> np.ndarray:
    """Flip signs along ``axis`` so that consecutive quaternions have a positive dot product.

    Both ``q`` and ``-q`` are the same rotation; a time series of attitudes
    reads best when the sign does not jump. The first sample keeps its sign.

    Parameters
    ----------
    q : array_like, shape (..., 4)
        A series of quaternions along ``axis`` (not the last axis).
    axis : int
        The series axis.

    Returns
    -------
    ndarray, same shape as ``q``
    """
    q = as_float_array(q, "q", (4,))
    ax = axis % q.ndim
    if ax == q.ndim - 1:
        raise InvalidInputError("axis must not be the quaternion axis (the last one)")
    qm = np.moveaxis(q, ax, 0)
    if qm.shape[0] < 2:
        return q.copy()
    dots = np.sum(qm[1:] * qm[:-1], axis=-1)
    flips = np.concatenate([np.zeros((1,) + dots.shape[1:], dtype=int), np.cumsum(dots < 0, axis=0)])
    sign = np.where(flips % 2 == 1, -1.0, 1.0)
    return np.moveaxis(qm * sign[..., None], 0, ax)


def matrix_from_quaternion(q) -> np.ndarray:
    r"""Rotation matrix of a quaternion.

    .. math:: R = (w^2-\mathbf v^2)\mathbf 1 + 2\mathbf v\mathbf v^T + 2w[\mathbf v]_\times

    The quaternion is normalized first.

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
    """
    q = _as_quaternion(q)
    return _matrix_from_unit_quaternion(q)


def _matrix_from_unit_quaternion(q):
    w = q[..., 0]
    v = q[..., 1:]
    R = (w * w - np.sum(v * v, -1))[..., None, None] * np.eye(3)
    R = R + 2.0 * _outer(v, v) + 2.0 * w[..., None, None] * _skew(v)
    return R


def quaternion_from_matrix(R, *, atol: float = 1e-6) -> np.ndarray:
    """Unit quaternion (``w >= 0``) of a rotation matrix, by Shepperd's method.

    The largest of ``w, |x|, |y|, |z|`` is computed from the diagonal and the
    others from off-diagonal sums, which keeps full accuracy at every angle,
    including near ``alpha = pi``.

    Parameters
    ----------
    R : array_like, shape (..., 3, 3)
        Rotation matrices.
    atol : float
        Tolerance for the check ``R^T R = 1`` and ``det R = 1``.

    Returns
    -------
    ndarray, shape (..., 4)

    Raises
    ------
    InvalidInputError
        Wrong shape, non-finite values, or a matrix that is not a rotation.

    References
    ----------
    S. W. Shepperd, "Quaternion from rotation matrix", J. Guidance Control 1 (1978) 223.
    """
    R = as_float_array(R, "R", (3, 3))
    RtR = np.swapaxes(R, -1, -2) @ R
    if np.any(np.abs(RtR - np.eye(3)) > atol) or np.any(np.abs(np.linalg.det(R) - 1.0) > atol):
        raise InvalidInputError(
            "R is not a rotation matrix: expected R^T R = 1 and det R = +1 "
            f"(within atol={atol}); max |R^T R - 1| = {np.max(np.abs(RtR - np.eye(3))):.3g}"
        )
    return _quaternion_from_rotation_matrix(R)


def _quaternion_from_rotation_matrix(R):
    r00, r11, r22 = R[..., 0, 0], R[..., 1, 1], R[..., 2, 2]
    tr = r00 + r11 + r22
    cand = np.stack([tr, r00, r11, r22], -1)
    k = np.argmax(cand, axis=-1)
    # four candidate formulas, each accurate where its pivot is largest
    d21 = R[..., 2, 1] - R[..., 1, 2]
    d02 = R[..., 0, 2] - R[..., 2, 0]
    d10 = R[..., 1, 0] - R[..., 0, 1]
    s01 = R[..., 0, 1] + R[..., 1, 0]
    s02 = R[..., 0, 2] + R[..., 2, 0]
    s12 = R[..., 1, 2] + R[..., 2, 1]
    with np.errstate(invalid="ignore", divide="ignore"):
        q0 = np.stack([1 + tr, d21, d02, d10], -1)
        q1 = np.stack([d21, 1 + 2 * r00 - tr, s01, s02], -1)
        q2 = np.stack([d02, s01, 1 + 2 * r11 - tr, s12], -1)
        q3 = np.stack([d10, s02, s12, 1 + 2 * r22 - tr], -1)
    Q = np.stack([q0, q1, q2, q3], -2)
    q = np.take_along_axis(Q, k[..., None, None], axis=-2)[..., 0, :]
    q = q / _norm(q)[..., None]
    return np.where(q[..., :1] < 0, -q, q)


# ---------------------------------------------------------------------------
# Gibbs vector (the paper's n)
# ---------------------------------------------------------------------------
def quaternion_from_gibbs(n) -> np.ndarray:
    r"""Unit quaternion (``w > 0``) of a Gibbs vector.

    .. math:: q = \frac{(1, \mathbf n)}{\sqrt{1+\mathbf n^2}}

    computed with ``hypot`` so that very large :math:`|\mathbf n|` (angles
    close to :math:`\pi`) do not overflow.

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
    """
    n = as_float_array(n, "n", (3,))
    return _quaternion_from_gibbs(n)


def _quaternion_from_gibbs(n):
    # w = 1/sqrt(1+|n|^2) without overflow
    big = np.max(np.abs(n), axis=-1)
    scale = np.where(big > 1.0, big, 1.0)
    ns = n / scale[..., None]
    nrm = np.sqrt(np.sum(ns * ns, -1) + (1.0 / scale) ** 2)
    w = (1.0 / scale) / nrm
    return np.concatenate([w[..., None], ns / nrm[..., None]], -1)


def gibbs_from_quaternion(q) -> np.ndarray:
    r"""Gibbs vector :math:`\mathbf n = (x, y, z)/w` of a quaternion.

    The result does not depend on the sign or the norm of ``q``.

    Parameters
    ----------
    q : array_like, shape (..., 4)

    Returns
    -------
    ndarray, shape (..., 3)

    Raises
    ------
    SingularChartError
        If ``w = 0`` (rotation angle :math:`\pi`), where ``n`` is infinite:
        keep the quaternion, or use :func:`gibbs_chart` with another reference.
    InvalidInputError
        Wrong shape, non-finite values or a zero quaternion.

    References
    ----------
    Paper, footnote to eq. 1.9.
    """
    q = _as_quaternion(q)
    w = q[..., 0]
    if np.any(w == 0):
        raise SingularChartError(
            "the attitude has rotation angle alpha = pi (quaternion w = 0), where the Gibbs vector "
            "n = k tan(alpha/2) is infinite; keep the quaternion or use gibbs_chart(q, reference)"
        )
    return q[..., 1:] / w[..., None]


def matrix_from_gibbs(n) -> np.ndarray:
    r"""The paper's rotation matrix :math:`R(\mathbf n)` (eq. 1.9).

    .. math::
        R_{ij}(\mathbf n) = \frac{(1-\mathbf n^2)\delta_{ij} + 2 n_i n_j - 2\epsilon_{ijk}n_k}{1+\mathbf n^2}

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
    """
    n = as_float_array(n, "n", (3,))
    return _matrix_from_unit_quaternion(_quaternion_from_gibbs(n))


def gibbs_from_matrix(R) -> np.ndarray:
    """Gibbs vector of a rotation matrix (through Shepperd's quaternion).

    Parameters
    ----------
    R : array_like, shape (..., 3, 3)

    Returns
    -------
    ndarray, shape (..., 3)

    Raises
    ------
    SingularChartError
        If the rotation angle is exactly pi.
    InvalidInputError
        If ``R`` is not a rotation matrix.
    """
    return gibbs_from_quaternion(quaternion_from_matrix(R))


# ---------------------------------------------------------------------------
# axis-angle, rotation vector, MRP
# ---------------------------------------------------------------------------
def quaternion_from_axis_angle(axis, angle) -> np.ndarray:
    r"""Quaternion :math:`(\cos\frac\alpha2, \mathbf k\sin\frac\alpha2)` of a rotation by ``angle`` about ``axis``.

    Parameters
    ----------
    axis : array_like, shape (..., 3)
        Rotation axis; normalized here (must be nonzero).
    angle : array_like, shape (...)
        Angle in radians, counterclockwise seen from the tip of the axis (paper eq. 1.7).

    Returns
    -------
    ndarray, shape (..., 4)

    Raises
    ------
    InvalidInputError
        Zero axis, wrong shapes or non-finite values.
    """
    k = as_float_array(axis, "axis", (3,))
    a = as_float_array(angle, "angle")
    nk = _norm(k)
    if np.any(nk == 0):
        raise InvalidInputError("axis contains a zero vector; a rotation axis must be nonzero")
    k = k / nk[..., None]
    k, a = np.broadcast_arrays(k, a[..., None])
    a = a[..., 0]
    return np.concatenate([np.cos(a / 2)[..., None], k * np.sin(a / 2)[..., None]], -1)


def axis_angle_from_quaternion(q) -> tuple[np.ndarray, np.ndarray]:
    r"""Unit axis :math:`\mathbf k` and angle :math:`\alpha\in[0,\pi]` of a quaternion.

    :math:`\alpha = 2\,\mathrm{atan2}(|\mathbf v|, |w|)`, accurate at every angle.
    At :math:`\alpha = 0` the axis is undefined and ``(0, 0, 1)`` is returned.

    Parameters
    ----------
    q : array_like, shape (..., 4)

    Returns
    -------
    axis : ndarray, shape (..., 3)
    angle : ndarray, shape (...)
    """
    q = _canonical(_as_quaternion(q))
    v = q[..., 1:]
    s = _norm(v)
    angle = 2.0 * np.arctan2(s, q[..., 0])
    safe = np.where(s > 0, s, 1.0)
    axis = np.where((s > 0)[..., None], v / safe[..., None], np.array([0.0, 0.0, 1.0]))
    return axis, angle


def quaternion_from_rotvec(rotvec) -> np.ndarray:
    r"""Quaternion of a rotation vector :math:`\boldsymbol\phi = \alpha\mathbf k` (scipy's ``rotvec``).

    Uses :math:`\sin(\alpha/2)/\alpha` through ``numpy.sinc``, exact near zero.

    Parameters
    ----------
    rotvec : array_like, shape (..., 3)

    Returns
    -------
    ndarray, shape (..., 4)
    """
    r = as_float_array(rotvec, "rotvec", (3,))
    th = _norm(r)
    return np.concatenate([np.cos(th / 2)[..., None], 0.5 * np.sinc(th / (2 * np.pi))[..., None] * r], -1)


def rotvec_from_quaternion(q) -> np.ndarray:
    r"""Rotation vector :math:`\alpha\mathbf k`, :math:`\alpha\in[0,\pi]`, of a quaternion.

    Parameters
    ----------
    q : array_like, shape (..., 4)

    Returns
    -------
    ndarray, shape (..., 3)
    """
    q = _canonical(_as_quaternion(q))
    s = _norm(q[..., 1:])
    th = 2.0 * np.arctan2(s, q[..., 0])
    return q[..., 1:] * (2.0 / np.sinc(th / (2 * np.pi)))[..., None]


def quaternion_from_mrp(p) -> np.ndarray:
    r"""Quaternion of modified Rodrigues parameters :math:`\mathbf p = \mathbf k\tan(\alpha/4)`.

    .. math:: q = \frac{(1-\mathbf p^2,\; 2\mathbf p)}{1+\mathbf p^2}

    Parameters
    ----------
    p : array_like, shape (..., 3)

    Returns
    -------
    ndarray, shape (..., 4)

    References
    ----------
    Shuster (1993), section 9.
    """
    p = as_float_array(p, "p", (3,))
    p2 = np.sum(p * p, -1)
    return np.concatenate([((1 - p2) / (1 + p2))[..., None], 2 * p / (1 + p2)[..., None]], -1)


def mrp_from_quaternion(q) -> np.ndarray:
    r"""Modified Rodrigues parameters :math:`\mathbf v/(1+w)` with ``w >= 0`` (so :math:`|\mathbf p|\le 1`).

    Parameters
    ----------
    q : array_like, shape (..., 4)

    Returns
    -------
    ndarray, shape (..., 3)
    """
    q = _canonical(_as_quaternion(q))
    return q[..., 1:] / (1.0 + q[..., :1])


# ---------------------------------------------------------------------------
# Euler angles, all 12 sequences
# ---------------------------------------------------------------------------
_AXES = {"x": 0, "y": 1, "z": 2}


def _parse_seq(seq):
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


def quaternion_from_euler(seq: str, angles, *, degrees: bool = False) -> np.ndarray:
    r"""Quaternion from Euler angles in any of the 12 sequences.

    Lower-case ``seq`` (``"xyz"``) is extrinsic: rotations about the fixed
    axes, the first applied first, :math:`R = R_{c}(\gamma)R_{b}(\beta)R_{a}(\alpha)`.
    Upper-case (``"XYZ"``) is intrinsic: about the moving axes,
    :math:`R = R_{a}(\alpha)R_{b}(\beta)R_{c}(\gamma)`. Same as scipy.

    Parameters
    ----------
    seq : str
        Three axes, consecutive ones different (Tait-Bryan or proper Euler).
    angles : array_like, shape (..., 3)
    degrees : bool
        Angles in degrees.

    Returns
    -------
    ndarray, shape (..., 4)

    Raises
    ------
    InvalidInputError
        Invalid sequence, wrong shape or non-finite angles.
    """
    axes, intrinsic = _parse_seq(seq)
    ang = as_float_array(angles, "angles", (3,))
    if degrees:
        ang = np.deg2rad(ang)
    qs = []
    for i, ax in enumerate(axes):
        a = ang[..., i]
        e = np.zeros(a.shape + (4,))
        e[..., 0] = np.cos(a / 2)
        e[..., ax + 1] = np.sin(a / 2)
        qs.append(e)
    if intrinsic:
        q = _qmul(_qmul(qs[0], qs[1]), qs[2])
    else:
        q = _qmul(_qmul(qs[2], qs[1]), qs[0])
    return q


def euler_from_quaternion(seq: str, q, *, degrees: bool = False) -> np.ndarray:
    r"""Euler angles of a quaternion in any of the 12 sequences.

    Direct method of Bernardes & Viollet (2022). Angles: first and third in
    :math:`(-\pi, \pi]`, the second in :math:`[0, \pi]` (proper Euler) or
    :math:`[-\pi/2, \pi/2]` (Tait-Bryan). At gimbal lock the third angle is
    set to zero and the first carries the whole rotation.

    Parameters
    ----------
    seq : str
        See :func:`quaternion_from_euler`.
    q : array_like, shape (..., 4)
    degrees : bool
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
    """
    axes, intrinsic = _parse_seq(seq)
    q = _as_quaternion(q)
    if intrinsic:
        axes = axes[::-1]
    i, j, k = axes
    proper = i == k
    if proper:
        k = 3 - i - j
    sgn = float((i - j) * (j - k) * (k - i) / 2)  # permutation sign of (i, j, k)
    w, v = q[..., 0], q[..., 1:]
    if proper:
        a, b, c, d = w, v[..., i], v[..., j], v[..., k] * sgn
    else:
        a = w - v[..., j]
        b = v[..., i] + v[..., k] * sgn
        c = v[..., j] + w
        d = v[..., k] * sgn - v[..., i]
    th2 = 2.0 * np.arctan2(np.hypot(c, d), np.hypot(a, b))
    hp = np.arctan2(b, a)
    hm = np.arctan2(d, c)
    tol = 1e-12
    lock0 = np.abs(th2) <= tol
    lockpi = np.abs(th2 - np.pi) <= tol
    th1 = np.where(lock0, 2 * hp, np.where(lockpi, 2 * hm, hp - hm))
    th3 = np.where(lock0 | lockpi, 0.0, hp + hm)
    if not proper:
        th3 = sgn * th3
        th2 = th2 - np.pi / 2
    out = np.stack([th1, th2, th3], -1)
    if intrinsic:
        out = out[..., ::-1]
    out = (out + np.pi) % (2 * np.pi) - np.pi
    out = np.where(np.isclose(out, -np.pi, atol=0, rtol=1e-15), np.pi, out)
    if not proper:
        mid = 1
        out[..., mid] = np.clip(out[..., mid], -np.pi / 2, np.pi / 2)
    return np.rad2deg(out) if degrees else out


# ---------------------------------------------------------------------------
# Gibbs <-> everything
# ---------------------------------------------------------------------------
def gibbs_from_axis_angle(axis, angle) -> np.ndarray:
    r"""Gibbs vector :math:`\mathbf k\tan(\alpha/2)` (paper eq. 1.8).

    Raises
    ------
    SingularChartError
        If an angle is an odd multiple of :math:`\pi`.
    """
    return gibbs_from_quaternion(quaternion_from_axis_angle(axis, angle))


def axis_angle_from_gibbs(n) -> tuple[np.ndarray, np.ndarray]:
    r"""Axis and angle :math:`\alpha = 2\arctan|\mathbf n|` of a Gibbs vector (paper eq. 1.8)."""
    return axis_angle_from_quaternion(quaternion_from_gibbs(n))


def gibbs_from_rotvec(rotvec) -> np.ndarray:
    """Gibbs vector of a rotation vector. Raises SingularChartError at angle pi."""
    return gibbs_from_quaternion(quaternion_from_rotvec(rotvec))


def rotvec_from_gibbs(n) -> np.ndarray:
    """Rotation vector (scipy's alpha*k) of a Gibbs vector."""
    return rotvec_from_quaternion(quaternion_from_gibbs(n))


def gibbs_from_mrp(p) -> np.ndarray:
    r"""Gibbs vector :math:`2\mathbf p/(1-\mathbf p^2)` of MRPs. Raises SingularChartError at :math:`|\mathbf p| = 1`."""
    return gibbs_from_quaternion(quaternion_from_mrp(p))


def mrp_from_gibbs(n) -> np.ndarray:
    """Modified Rodrigues parameters of a Gibbs vector."""
    return mrp_from_quaternion(quaternion_from_gibbs(n))


def gibbs_from_euler(seq: str, angles, *, degrees: bool = False) -> np.ndarray:
    """Gibbs vector from Euler angles (see :func:`quaternion_from_euler`)."""
    return gibbs_from_quaternion(quaternion_from_euler(seq, angles, degrees=degrees))


def euler_from_gibbs(seq: str, n, *, degrees: bool = False) -> np.ndarray:
    """Euler angles of a Gibbs vector (see :func:`euler_from_quaternion`)."""
    return euler_from_quaternion(seq, quaternion_from_gibbs(n), degrees=degrees)


def gibbs_compose(n1, n2) -> np.ndarray:
    r"""Gibbs vector of the product :math:`R(\mathbf n_1)R(\mathbf n_2)`, in closed form.

    .. math:: \mathbf n_{12} = \frac{\mathbf n_1 + \mathbf n_2 + \mathbf n_1\times\mathbf n_2}{1 - \mathbf n_1\cdot\mathbf n_2}

    (divide the Hamilton product of :math:`(1,\mathbf n_1)` and
    :math:`(1,\mathbf n_2)` by its scalar part).

    Parameters
    ----------
    n1, n2 : array_like, shape (..., 3)

    Returns
    -------
    ndarray, shape (..., 3)

    Raises
    ------
    SingularChartError
        If :math:`\mathbf n_1\cdot\mathbf n_2 = 1`: the product is a rotation by :math:`\pi`.
    """
    n1 = as_float_array(n1, "n1", (3,))
    n2 = as_float_array(n2, "n2", (3,))
    den = 1.0 - np.sum(n1 * n2, -1)
    if np.any(den == 0):
        raise SingularChartError(
            "gibbs_compose: n1 . n2 = 1, the product is a rotation by pi where the Gibbs vector "
            "is infinite; compose quaternions instead"
        )
    return (n1 + n2 + np.cross(n1, n2)) / den[..., None]


def gibbs_inverse(n) -> np.ndarray:
    r"""Gibbs vector of :math:`R(\mathbf n)^{-1} = R(\mathbf n)^T`, which is :math:`-\mathbf n`."""
    return -as_float_array(n, "n", (3,))


# ---------------------------------------------------------------------------
# charts
# ---------------------------------------------------------------------------
def gibbs_chart(q, reference) -> np.ndarray:
    r"""Local Gibbs vector of ``q`` in the chart centred on ``reference``.

    Returns :math:`\mathbf n` with :math:`R(q) = R(q_0)R(\mathbf n)`, i.e. the
    Gibbs vector of :math:`q_0^{-1}\otimes q`. The free rigid body is
    left-invariant, so its equations in :math:`\mathbf n` are the same in
    every such chart.

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
    """
    q = _as_quaternion(q)
    q0 = _as_quaternion(reference, "reference")
    rel = _qmul(q0 * np.array([1.0, -1.0, -1.0, -1.0]), q)
    if np.any(rel[..., 0] == 0):
        raise SingularChartError(
            "the attitude is a rotation by pi relative to the chart reference; choose another reference"
        )
    return rel[..., 1:] / rel[..., :1]


def quaternion_from_chart(reference, n) -> np.ndarray:
    r"""Attitude :math:`q_0\otimes q(\mathbf n)` of the local Gibbs vector ``n`` in the chart at ``reference``.

    Parameters
    ----------
    reference : array_like, shape (..., 4)
    n : array_like, shape (..., 3)

    Returns
    -------
    ndarray, shape (..., 4)
    """
    q0 = _as_quaternion(reference, "reference")
    n = as_float_array(n, "n", (3,))
    return _qmul(q0, _quaternion_from_gibbs(n))


# ---------------------------------------------------------------------------
# the paper's matrices
# ---------------------------------------------------------------------------
def conversion_matrix(n) -> np.ndarray:
    r"""The paper's conversion matrix :math:`A(\mathbf n)` (eq. 1.12).

    .. math:: A_{ij} = \frac{\delta_{ij} - \epsilon_{ijk}n_k}{1+\mathbf n^2}
              = \frac{\mathbf 1 + [\mathbf n]_\times}{1+\mathbf n^2}

    Parameters
    ----------
    n : array_like, shape (..., 3)

    Returns
    -------
    ndarray, shape (..., 3, 3)

    References
    ----------
    Paper eq. 1.11-1.12.
    """
    n = as_float_array(n, "n", (3,))
    return _A(n)


def _A(n):
    return (np.eye(3) + _skew(n)) / (1.0 + np.sum(n * n, -1))[..., None, None]


def inverse_conversion_matrix(n) -> np.ndarray:
    r"""The paper's :math:`\tilde A(\mathbf n) = A^{-1}(\mathbf n)` (eq. 1.12, corrected).

    .. math:: \tilde A_{ij} = \delta_{ij} + n_i n_j + \epsilon_{ijk}n_k
              = \mathbf 1 + \mathbf n\mathbf n^T - [\mathbf n]_\times

    The paper prints :math:`n_j n_j` for the middle term; the inverse of
    :math:`A` has :math:`n_i n_j` (see ``eulerpoisson audit``).

    Parameters
    ----------
    n : array_like, shape (..., 3)

    Returns
    -------
    ndarray, shape (..., 3, 3)

    References
    ----------
    Paper eq. 1.12.
    """
    n = as_float_array(n, "n", (3,))
    return _At(n)


def _At(n):
    return np.eye(3) + _outer(n, n) - _skew(n)


def matrix_from_conversion(n) -> np.ndarray:
    r""":math:`R = A\tilde A^T` (paper, after eq. 1.12); equals :func:`matrix_from_gibbs`."""
    n = as_float_array(n, "n", (3,))
    return _A(n) @ np.swapaxes(_At(n), -1, -2)


def omega_from_gibbs_rate(n, ndot) -> np.ndarray:
    r"""Body angular velocity :math:`\boldsymbol\Omega = 2A^T\dot{\mathbf n}` (eq. 1.11).

    .. math:: \boldsymbol\Omega = \frac{2(\dot{\mathbf n} - \mathbf n\times\dot{\mathbf n})}{1+\mathbf n^2}

    Parameters
    ----------
    n, ndot : array_like, shape (..., 3)

    Returns
    -------
    ndarray, shape (..., 3)

    References
    ----------
    Paper eq. 1.11, 1.24.
    """
    n = as_float_array(n, "n", (3,))
    nd = as_float_array(ndot, "ndot", (3,))
    return 2.0 * (nd - np.cross(n, nd)) / (1.0 + np.sum(n * n, -1))[..., None]


def gibbs_rate_from_omega(n, omega) -> np.ndarray:
    r""":math:`\dot{\mathbf n} = \tfrac12\tilde A^T\boldsymbol\Omega` (eq. 1.30), the inverse of eq. 1.11.

    .. math:: \dot{\mathbf n} = \tfrac12\left(\boldsymbol\Omega + \mathbf n\times\boldsymbol\Omega + (\mathbf n\cdot\boldsymbol\Omega)\mathbf n\right)

    Parameters
    ----------
    n, omega : array_like, shape (..., 3)

    Returns
    -------
    ndarray, shape (..., 3)

    References
    ----------
    Paper eq. 1.30.
    """
    n = as_float_array(n, "n", (3,))
    w = as_float_array(omega, "omega", (3,))
    return 0.5 * (w + np.cross(n, w) + np.sum(n * w, -1)[..., None] * n)


def _as_inertia_matrix(inertia):
    from .body import RigidBody

    if isinstance(inertia, RigidBody):
        return inertia.inertia
    I = as_float_array(inertia, "inertia")
    if I.shape[-1:] == (3,) and (I.ndim == 1 or I.shape[-2:] != (3, 3)):
        return I[..., :, None] * np.eye(3)
    if I.shape[-2:] != (3, 3):
        raise InvalidInputError(
            f"inertia must be three principal moments (..., 3) or a tensor (..., 3, 3), got shape {I.shape}"
        )
    return I


def metric(n, inertia) -> np.ndarray:
    r"""The metric :math:`G(\mathbf n) = 4AIA^T` of the geodesic problem (eq. 1.13).

    The kinetic energy is :math:`L = \tfrac12 G_{ij}\dot n_i\dot n_j`.

    Parameters
    ----------
    n : array_like, shape (..., 3)
    inertia : array_like, shape (..., 3) or (..., 3, 3), or RigidBody
        Principal moments or the full (body-frame) inertia tensor.

    Returns
    -------
    ndarray, shape (..., 3, 3)

    References
    ----------
    Paper eq. 1.13.
    """
    n = as_float_array(n, "n", (3,))
    I = _as_inertia_matrix(inertia)
    A = _A(n)
    return 4.0 * A @ I @ np.swapaxes(A, -1, -2)


def inverse_metric(n, inertia) -> np.ndarray:
    r"""The inverse metric :math:`G^{-1} = \tfrac14\tilde A^T I^{-1}\tilde A` (eq. 1.14).

    Parameters
    ----------
    n : array_like, shape (..., 3)
    inertia : array_like, shape (..., 3) or (..., 3, 3), or RigidBody

    Returns
    -------
    ndarray, shape (..., 3, 3)

    References
    ----------
    Paper eq. 1.14.
    """
    n = as_float_array(n, "n", (3,))
    I = _as_inertia_matrix(inertia)
    At = _At(n)
    return 0.25 * np.swapaxes(At, -1, -2) @ np.linalg.inv(I) @ At


# ---------------------------------------------------------------------------
# the Attitude class
# ---------------------------------------------------------------------------
class Attitude:
    """A batch of attitudes (rotations), stored as unit quaternions.

    A thin object over the ``<to>_from_<from>`` functions of this module, in
    the style of :class:`scipy.spatial.transform.Rotation`. ``a * b`` (or
    ``a @ b``) is the rotation :math:`R_a R_b`; ``a.inv()`` the inverse;
    ``a.apply(v)`` rotates body vectors into space.

    Parameters
    ----------
    quaternion : array_like, shape (..., 4)
        Scalar-first quaternions, normalized on construction.

    Examples
    --------
    >>> from eulerpoisson import Attitude
    >>> a = Attitude.from_gibbs([0.0, 0.0, 1.0])   # 90 degrees about z
    >>> a.as_rotvec().round(6)
    array([0.      , 0.      , 1.570796])
    """

    __slots__ = ("_q",)

    def __init__(self, quaternion):
        self._q = _as_quaternion(quaternion, "quaternion")

    # factories ------------------------------------------------------------
    @classmethod
    def identity(cls, shape=()) -> "Attitude":
        """The identity rotation, broadcast to ``shape``."""
        shape = (shape,) if isinstance(shape, int) else tuple(shape)
        q = np.zeros(shape + (4,))
        q[..., 0] = 1.0
        return cls(q)

    @classmethod
    def random(cls, shape=(), rng=None) -> "Attitude":
        """Uniformly distributed random rotations (normalized Gaussian quaternions)."""
        rng = np.random.default_rng(rng)
        shape = (shape,) if isinstance(shape, int) else tuple(shape)
        return cls(rng.standard_normal(shape + (4,)))

    @classmethod
    def from_quaternion(cls, q) -> "Attitude":
        """From scalar-first quaternions (..., 4); normalized."""
        return cls(q)

    @classmethod
    def from_gibbs(cls, n) -> "Attitude":
        """From the paper's Gibbs vectors (..., 3) (eq. 1.8-1.9)."""
        return cls(quaternion_from_gibbs(n))

    @classmethod
    def from_matrix(cls, R) -> "Attitude":
        """From rotation matrices (..., 3, 3)."""
        return cls(quaternion_from_matrix(R))

    @classmethod
    def from_axis_angle(cls, axis, angle) -> "Attitude":
        """From axes (..., 3) and angles (...) in radians."""
        return cls(quaternion_from_axis_angle(axis, angle))

    @classmethod
    def from_rotvec(cls, rotvec) -> "Attitude":
        """From rotation vectors alpha*k (scipy's rotvec), (..., 3)."""
        return cls(quaternion_from_rotvec(rotvec))

    @classmethod
    def from_mrp(cls, p) -> "Attitude":
        """From modified Rodrigues parameters (..., 3)."""
        return cls(quaternion_from_mrp(p))

    @classmethod
    def from_euler(cls, seq: str, angles, *, degrees: bool = False) -> "Attitude":
        """From Euler angles; ``seq`` as in scipy (``'xyz'`` extrinsic, ``'XYZ'`` intrinsic)."""
        return cls(quaternion_from_euler(seq, angles, degrees=degrees))

    @classmethod
    def from_scipy(cls, rotation) -> "Attitude":
        """From a :class:`scipy.spatial.transform.Rotation` (scalar-last internally)."""
        from scipy.spatial.transform import Rotation

        if not isinstance(rotation, Rotation):
            raise TypeError(f"rotation must be a scipy Rotation, got {type(rotation).__name__}")
        return cls(rotation.as_quat(scalar_first=True))

    @classmethod
    def from_chart(cls, reference, n) -> "Attitude":
        """From a local Gibbs vector ``n`` in the chart at ``reference`` (R = R0 R(n))."""
        ref = reference.as_quaternion() if isinstance(reference, Attitude) else reference
        return cls(quaternion_from_chart(ref, n))

    # views ----------------------------------------------------------------
    def as_quaternion(self, canonical: bool = False) -> np.ndarray:
        """Unit quaternions (..., 4); ``canonical=True`` makes ``w >= 0``."""
        return _canonical(self._q) if canonical else self._q.copy()

    def as_gibbs(self) -> np.ndarray:
        """Gibbs vectors (..., 3). Raises SingularChartError at angle pi."""
        return gibbs_from_quaternion(self._q)

    def as_chart(self, reference) -> np.ndarray:
        """Local Gibbs vectors relative to ``reference`` (an Attitude or quaternions)."""
        ref = reference.as_quaternion() if isinstance(reference, Attitude) else reference
        return gibbs_chart(self._q, ref)

    def as_matrix(self) -> np.ndarray:
        """Rotation matrices (..., 3, 3)."""
        return _matrix_from_unit_quaternion(self._q)

    def as_axis_angle(self) -> tuple[np.ndarray, np.ndarray]:
        """Unit axes (..., 3) and angles in [0, pi] (...)."""
        return axis_angle_from_quaternion(self._q)

    def as_rotvec(self) -> np.ndarray:
        """Rotation vectors alpha*k (..., 3)."""
        return rotvec_from_quaternion(self._q)

    def as_mrp(self) -> np.ndarray:
        """Modified Rodrigues parameters (..., 3) with norm <= 1."""
        return mrp_from_quaternion(self._q)

    def as_euler(self, seq: str, *, degrees: bool = False) -> np.ndarray:
        """Euler angles (..., 3) in the sequence ``seq``."""
        return euler_from_quaternion(seq, self._q, degrees=degrees)

    def as_scipy(self):
        """A :class:`scipy.spatial.transform.Rotation` (flattened to 1-D batches or a single rotation)."""
        from scipy.spatial.transform import Rotation

        q = self._q
        return Rotation.from_quat(q.reshape(-1, 4) if q.ndim > 2 else q, scalar_first=True)

    # algebra --------------------------------------------------------------
    def __mul__(self, other: "Attitude") -> "Attitude":
        if not isinstance(other, Attitude):
            return NotImplemented
        return Attitude(_qmul(self._q, other._q))

    __matmul__ = __mul__

    def inv(self) -> "Attitude":
        """The inverse rotations."""
        return Attitude(self._q * np.array([1.0, -1.0, -1.0, -1.0]))

    def apply(self, vectors, inverse: bool = False) -> np.ndarray:
        """Rotate vectors (..., 3): ``R v`` (body to space) or ``R^T v`` with ``inverse=True``."""
        v = as_float_array(vectors, "vectors", (3,))
        R = self.as_matrix()
        if inverse:
            R = np.swapaxes(R, -1, -2)
        return np.einsum("...ij,...j->...i", R, v)

    def magnitude(self) -> np.ndarray:
        """Rotation angles in [0, pi]."""
        return self.as_axis_angle()[1]

    def angle_to(self, other: "Attitude") -> np.ndarray:
        """Angle (radians, in [0, pi]) of the rotation taking ``self`` to ``other``."""
        rel = _qmul(self._q * np.array([1.0, -1.0, -1.0, -1.0]), other._q)
        return 2.0 * np.arctan2(_norm(rel[..., 1:]), np.abs(rel[..., 0]))

    # container ------------------------------------------------------------
    @property
    def shape(self) -> tuple[int, ...]:
        """Batch shape."""
        return self._q.shape[:-1]

    def __len__(self) -> int:
        if not self.shape:
            raise TypeError("a single Attitude has no len()")
        return self.shape[0]

    def __getitem__(self, idx) -> "Attitude":
        if not self.shape:
            raise TypeError("a single Attitude cannot be indexed")
        return Attitude(self._q[idx])

    def __repr__(self) -> str:
        if self.shape == ():
            w, x, y, z = self._q
            return f"Attitude(quaternion=[{w:.6g}, {x:.6g}, {y:.6g}, {z:.6g}])"
        return f"Attitude(shape={self.shape})"
