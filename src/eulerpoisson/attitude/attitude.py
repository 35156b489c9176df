r"""The :class:`Attitude` class: a batch of rotations over the ``<to>_from_<from>`` functions.

``Attitude`` stores unit quaternions and converts through the functions of
:mod:`.quaternion`, :mod:`.gibbs`, :mod:`.rotvec` and :mod:`.euler`;
:data:`AttitudeLike` names what the API accepts as an attitude.
"""

from __future__ import annotations

from collections.abc import Iterator
from typing import TYPE_CHECKING, Any, TypeAlias

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..numerics.quaternion import qmul
from ..util.validate import as_bool, as_float_array, as_shape, check_broadcast
from .common import scaled_norm
from .euler import euler_from_quaternion, quaternion_from_euler
from .gibbs import gibbs_chart, gibbs_from_unit_quaternion, quaternion_from_chart, quaternion_from_gibbs
from .quaternion import (
    CONJUGATE_SIGNS,
    as_quaternion,
    canonical_unit_quaternion,
    matrix_from_unit_quaternion,
    quaternion_from_matrix,
    quaternion_from_scipy,
    scipy_from_quaternion,
)
from .rotvec import (
    axis_angle_from_quaternion,
    mrp_from_quaternion,
    quaternion_from_axis_angle,
    quaternion_from_mrp,
    quaternion_from_rotvec,
    rotvec_from_quaternion,
)

if TYPE_CHECKING:
    from scipy.spatial.transform import Rotation

#: an attitude as the API takes it: an :class:`Attitude`, a scipy ``Rotation`` or unit quaternions (w, x, y, z)
AttitudeLike: TypeAlias = "Attitude | Rotation | ArrayLike"

__all__ = ["Attitude"]


def _check_attitude(other, name="other"):
    if not isinstance(other, Attitude):
        raise TypeError(f"{name} must be an Attitude, got {type(other).__name__}")
    return other


def _ref_quaternion(reference):
    return reference._q if isinstance(reference, Attitude) else reference


class Attitude:
    r"""A batch of attitudes (rotations), stored as unit quaternions.

    A thin object over the ``<to>_from_<from>`` functions of this package, in
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
        return canonical_unit_quaternion(self._q) if as_bool(canonical, "canonical") else self._q.copy()

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
        return gibbs_from_unit_quaternion(self._q)

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
        return Attitude(self._q * CONJUGATE_SIGNS)

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
        rel = qmul(self._q * CONJUGATE_SIGNS, other._q)
        return 2.0 * np.arctan2(scaled_norm(rel[..., 1:]), np.abs(rel[..., 0]))

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
