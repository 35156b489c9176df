r"""The torque of a magnetic field on a magnetic dipole of the body (:class:`MagneticDipoleTorque`).

References
----------
J. R. Wertz (ed.), *Spacecraft Attitude Determination and Control*, Reidel (1978), §17.2.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import TYPE_CHECKING, Any, cast

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..errors import InvalidInputError
from .torque_base import (
    IntegralContext,
    PolynomialTorque,
    Torque,
    TorqueParam,
    batched_dot,
    batched_matvec,
    body_frame,
    common_direction,
    cross_matrix,
    param_batch_shape,
    plain,
    register_torque,
    rotate_about_z,
    vector_param,
)

if TYPE_CHECKING:
    from .equations import Model

__all__ = ["MagneticDipoleTorque"]


@register_torque
class MagneticDipoleTorque(Torque):
    r"""The torque of a magnetic field on a body that carries a magnetic dipole.

    .. math:: \boldsymbol\tau = \boldsymbol\mu\times R^T\mathbf B(t), \qquad
              U = -(R\boldsymbol\mu)\cdot\mathbf B ,

    with :math:`\boldsymbol\mu` the body's magnetic dipole moment (body frame,
    A m², e.g. a magnetorquer or a permanent magnet) and :math:`\mathbf B` the
    magnetic flux density (space frame, T); the torque is in N m. The field
    is either constant, and the torque is then conservative (the sign:
    :math:`\delta U = -(R[\delta\boldsymbol\theta]_\times\boldsymbol\mu)\cdot\mathbf B
    = -(\boldsymbol\mu\times R^T\mathbf B)\cdot\delta\boldsymbol\theta`), autonomous
    and polynomial in the Poisson vector :math:`\mathbf b = R^T\mathbf B` (a heavy
    top with :math:`\mu\mathbf c \to \boldsymbol\mu`, :math:`\mathbf g \to \mathbf B`:
    every method that runs :class:`Gravity` runs it, and the model conserves the
    energy and :math:`\mathbf m\cdot\hat{\mathbf B}`); or a function of time
    ``field(t) -> (..., 3)`` (a field that turns, as seen along an orbit), and
    the torque is then time dependent and has no potential (``rk`` only).

    Parameters
    ----------
    dipole : array_like, shape (..., 3)
        :math:`\boldsymbol\mu`, body frame (A m²).
    field : array_like, shape (..., 3), or callable
        :math:`\mathbf B`, space frame (T): a constant, or a function of the
        time ``field(t)`` returning an array (3,) or (..., 3) that broadcasts
        against the batch (``t`` as :meth:`Torque.evaluate` receives it).

    Raises
    ------
    InvalidInputError
        A ``dipole`` or constant ``field`` of the wrong shape, with NaN, or
        batch shapes that do not broadcast; a callable field that returns
        an array not ending in 3 or not finite (when evaluated).
    TypeError
        Non-numeric parameters.

    Notes
    -----
    With a callable field the torque cannot be written to a file
    (``to_dict`` raises :class:`NotImplementedError`, as for
    :class:`CallableTorque`: files record it as unrecorded); indexing a
    batch (``torque[i]``) indexes the dipole and keeps the function.

    References
    ----------
    J. R. Wertz (ed.), *Spacecraft Attitude Determination and Control*,
    Reidel (1978), §17.2 (magnetic disturbance torque, :math:`\mathbf N =
    \mathbf m\times\mathbf B`). M. J. Sidi, *Spacecraft Dynamics and
    Control*, Cambridge (1997), §7.4 (magnetic torquers).

    Examples
    --------
    >>> import numpy as np, eulerpoisson as ep
    >>> mag = ep.torques.MagneticDipoleTorque(dipole=[0.0, 0.0, 2.0], field=[3e-5, 0.0, 0.0])
    >>> mag, mag.conservative, mag.time_dependent
    (MagneticDipoleTorque(dipole=[0.0, 0.0, 2.0], field=[3e-05, 0.0, 0.0]), True, False)
    >>> print(mag.evaluate(0.0, np.eye(3), np.zeros(3), np.eye(3)))        # mu x B
    [0.e+00 6.e-05 0.e+00]
    >>> print(mag.potential(0.0, np.eye(3), np.eye(3)))                     # -(R mu).B
    -0.0
    >>> turning = ep.torques.MagneticDipoleTorque([0.0, 0.0, 2.0], lambda t: [3e-5 * np.cos(t), 3e-5 * np.sin(t), 0.0])
    >>> turning.conservative, turning.time_dependent, turning.polynomial() is None
    (False, True, True)
    """

    kind = "magnetic_dipole"
    summary = "a magnetic dipole of the body in a magnetic field (constant or a function of time)"
    cli = (
        TorqueParam(
            "dipole",
            "--magnetic-dipole",
            "magnetic_dipole",
            "vector3",
            help="magnetic torque: the body's magnetic dipole moment, body frame (needs --magnetic-field)",
            units="A m2",
            metavar="MX,MY,MZ",
        ),
        TorqueParam(
            "field",
            "--magnetic-field",
            "magnetic_field",
            "vector3",
            help="magnetic torque: the magnetic flux density, space frame, constant (needs --magnetic-dipole)",
            units="T",
            metavar="BX,BY,BZ",
        ),
    )

    field: NDArray[np.float64] | Callable[..., ArrayLike]

    def __init__(self, dipole: ArrayLike, field: ArrayLike | Callable[..., ArrayLike]) -> None:
        self.dipole = vector_param(dipole, "dipole", "MagneticDipoleTorque")
        if callable(field):
            self.field = field
            self._shape = self.dipole.shape[:-1]
        else:
            B = vector_param(field, "field", "MagneticDipoleTorque")
            self.field = B
            self._shape = param_batch_shape("MagneticDipoleTorque", dipole=self.dipole[..., 0], field=B[..., 0])
        varying = callable(field)
        self.conservative = not varying
        self.time_dependent = varying

    @property
    def field_is_callable(self) -> bool:
        """The field is a function of time."""
        return callable(self.field)

    @property
    def batch_shape(self) -> tuple[int, ...]:
        return self._shape

    def field_at(self, t: ArrayLike) -> NDArray[np.float64]:
        r""":math:`\mathbf B(t)`, space frame, shape (..., 3).

        Raises
        ------
        InvalidInputError
            A callable field that returns an array not ending in 3, complex or boolean values, or NaN or
            infinite values.
        """
        if not callable(self.field):
            return self.field
        value = self.field(t)
        try:
            B = np.asarray(value)
            if np.iscomplexobj(B) or B.dtype == bool:  # the imaginary part would be dropped, True read as 1
                raise InvalidInputError(
                    f"the magnetic field function {self.field!r} returned {B.dtype} values; expected real numbers "
                    "(float64) of shape (..., 3) (the field in the space frame)"
                )
            B = B.astype(float, copy=False)
        except (TypeError, ValueError) as exc:
            if isinstance(exc, InvalidInputError):
                raise
            raise TypeError(
                f"the magnetic field function {self.field!r} must return a float array, got {value!r}"
            ) from None
        if B.ndim == 0 or B.shape[-1] != 3:
            raise InvalidInputError(
                f"the magnetic field function {self.field!r} returned shape {B.shape}; expected (..., 3) "
                "(the field in the space frame)"
            )
        if not np.all(np.isfinite(B)):
            raise InvalidInputError(
                f"the magnetic field function {self.field!r} returned NaN or infinite values at t = {t!s}"
            )
        return B

    def evaluate(
        self, t: ArrayLike, R: NDArray[np.float64], omega: NDArray[np.float64], inertia: NDArray[np.float64]
    ) -> NDArray[np.float64]:
        return np.cross(self.dipole, body_frame(R, self.field_at(t)))

    def potential(self, t: ArrayLike, R: NDArray[np.float64], inertia: NDArray[np.float64]) -> NDArray[np.float64]:
        if callable(self.field):
            raise NotImplementedError(
                "MagneticDipoleTorque with a field that depends on time derives from no potential"
            )
        return -np.einsum("...i,...i->...", self.field, np.einsum("...ij,...j->...i", R, self.dipole))

    def polynomial(self) -> PolynomialTorque | None:
        if callable(self.field):
            return None
        return PolynomialTorque(constant=np.zeros(3), vectors=(self.field,), maps=(cross_matrix(self.dipole),))

    def shifted(self, t_start: float, phi: ArrayLike) -> MagneticDipoleTorque:
        """The field turned by ``-phi`` about z and, for a callable, called at ``s + t_start`` (:meth:`Torque.shifted`)."""
        phi = np.asarray(phi)
        turn = bool(np.any(phi != 0))
        if not callable(self.field):
            return MagneticDipoleTorque(self.dipole, rotate_about_z(self.field, -phi)) if turn else self
        func = self.field

        def field(s, _f=func, _turn=turn):
            B = np.asarray(_f(np.asarray(s) + t_start), dtype=float)
            return rotate_about_z(B, -phi) if _turn else B

        field.__name__ = getattr(func, "__name__", "field")
        return MagneticDipoleTorque(self.dipole, field)

    @classmethod
    def integrals(cls, model: Model, torques: Sequence[Torque], ctx: IntegralContext) -> dict[str, np.ndarray]:
        r"""Constant fields: the energy and, with the fields along one direction :math:`\hat{\mathbf B}`,
        ``m_field`` (:math:`\mathbf m\cdot\hat{\mathbf B}`: the potential is invariant under rotations
        about :math:`\hat{\mathbf B}`). A field that depends on time: nothing."""
        mags = cast(Sequence[MagneticDipoleTorque], torques)
        if any(callable(tq.field) for tq in mags):
            return {}
        per_body = ctx.per_body
        U: Any = 0.0
        for tq in mags:
            U = U - batched_dot(per_body(cast(np.ndarray, tq.field), 1), batched_matvec(ctx.R, per_body(tq.dipole, 1)))
        out = {"energy": ctx.kinetic + U}
        bhat = common_direction([cast(np.ndarray, tq.field) for tq in mags])
        if bhat is not None:
            out["m_field"] = batched_dot(ctx.m, per_body(bhat, 1))
        return out

    def to_dict(self) -> dict[str, Any]:
        if callable(self.field):
            raise NotImplementedError(
                "MagneticDipoleTorque with a callable field cannot be written to a file (a Python function)"
            )
        return {"kind": self.kind, "dipole": plain(self.dipole), "field": plain(self.field)}

    def __getitem__(self, idx: Any) -> MagneticDipoleTorque:
        b = self._shape
        if callable(self.field):
            return MagneticDipoleTorque(np.broadcast_to(self.dipole, b + (3,))[idx], self.field)
        return MagneticDipoleTorque(
            np.broadcast_to(self.dipole, b + (3,))[idx], np.broadcast_to(self.field, b + (3,))[idx]
        )

    def __repr__(self) -> str:
        f = self.field
        shown = repr(getattr(f, "__name__", f)) if callable(f) else repr(plain(f))
        return f"MagneticDipoleTorque(dipole={plain(self.dipole)!r}, field={shown})"
