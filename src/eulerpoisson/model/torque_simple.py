r"""Torques constant in the body frame (:class:`BodyTorque`) or in the space frame (:class:`SpaceTorque`)."""

from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING, Any, cast

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .torque_base import (
    IntegralContext,
    PolynomialTorque,
    Torque,
    TorqueParam,
    body_frame,
    plain,
    register_torque,
    rotate_about_z,
    vector_param,
)

if TYPE_CHECKING:
    from .equations import Model

__all__ = ["BodyTorque", "SpaceTorque"]


@register_torque
class BodyTorque(Torque):
    r"""A torque constant in the body frame (a thruster fixed to the body).

    Parameters
    ----------
    tau : array_like, shape (..., 3)
        Body frame.

    Examples
    --------
    >>> import numpy as np, eulerpoisson as ep
    >>> kick = ep.torques.BodyTorque([0.0, 0.0, 0.5])
    >>> tr = ep.solve([1.0, 2.0, 2.5], [0.0, 2.0], omega0=[0.0, 0.0, 0.0], torque=kick, method="taylor")
    >>> print(np.round(tr.omega[-1], 12) + 0.0)                      # about a principal axis: 2.5 Omega' = 0.5
    [0.  0.  0.4]
    """

    kind = "body_torque"
    summary = "a torque constant in the body frame"
    cli = (
        TorqueParam(
            "tau",
            "--body-torque",
            "body_torque",
            "vector3",
            help="constant torque in the body frame",
            units="N m",
            metavar="TX,TY,TZ",
        ),
    )

    def __init__(self, tau: ArrayLike) -> None:
        self.tau = vector_param(tau, "tau", "BodyTorque")

    @property
    def batch_shape(self) -> tuple[int, ...]:
        return self.tau.shape[:-1]

    def evaluate(
        self, t: ArrayLike, R: NDArray[np.float64], omega: NDArray[np.float64], inertia: NDArray[np.float64]
    ) -> NDArray[np.float64]:
        return np.broadcast_to(self.tau, np.broadcast_shapes(self.tau.shape, np.shape(omega))).copy()

    def polynomial(self) -> PolynomialTorque:
        return PolynomialTorque(constant=self.tau)

    def shifted(self, t_start: float, phi: ArrayLike) -> BodyTorque:
        """Unchanged: a body-frame torque turns with nothing in space (:meth:`Torque.shifted`)."""
        return self

    def to_dict(self) -> dict[str, Any]:
        return {"kind": self.kind, "tau": plain(self.tau)}

    def __getitem__(self, idx: Any) -> BodyTorque:
        return BodyTorque(self.tau[idx]) if self.tau.ndim > 1 else self

    def __repr__(self) -> str:
        return f"BodyTorque(tau={plain(self.tau)!r})"


@register_torque
class SpaceTorque(Torque):
    r"""A torque constant in the space frame, :math:`\boldsymbol\tau = R^T\boldsymbol\tau_s`.

    Parameters
    ----------
    tau : array_like, shape (..., 3)
        Space frame.

    Examples
    --------
    >>> import numpy as np, eulerpoisson as ep
    >>> push = ep.torques.SpaceTorque([0.1, 0.0, 0.0])
    >>> tr = ep.solve([1.0, 2.0, 2.5], [0.0, 3.0], omega0=[0.0, 0.2, 0.0], torque=push, method="taylor")
    >>> print(np.round(tr.m[-1] - tr.m[0], 12) + 0.0)                # m grows by tau_s t
    [0.3 0.  0. ]
    """

    kind = "space_torque"
    summary = "a torque constant in the space frame"
    cli = (
        TorqueParam(
            "tau",
            "--space-torque",
            "space_torque",
            "vector3",
            help="constant torque in the space frame",
            units="N m",
            metavar="TX,TY,TZ",
        ),
    )

    def __init__(self, tau: ArrayLike) -> None:
        self.tau = vector_param(tau, "tau", "SpaceTorque")

    @property
    def batch_shape(self) -> tuple[int, ...]:
        return self.tau.shape[:-1]

    def evaluate(
        self, t: ArrayLike, R: NDArray[np.float64], omega: NDArray[np.float64], inertia: NDArray[np.float64]
    ) -> NDArray[np.float64]:
        return body_frame(R, self.tau)

    def polynomial(self) -> PolynomialTorque:
        eye = np.broadcast_to(np.eye(3), self.tau.shape[:-1] + (3, 3))
        return PolynomialTorque(constant=np.zeros(3), vectors=(self.tau,), maps=(eye,))

    def shifted(self, t_start: float, phi: ArrayLike) -> SpaceTorque:
        """``tau`` turned by ``-phi`` about z (see :meth:`Torque.shifted`)."""
        turn = bool(np.any(np.asarray(phi) != 0))
        return SpaceTorque(rotate_about_z(self.tau, -np.asarray(phi))) if turn else self

    @classmethod
    def integrals(cls, model: Model, torques: Sequence[Torque], ctx: IntegralContext) -> dict[str, np.ndarray]:
        r"""Constant space-frame torques: the components of :math:`\mathbf m - \boldsymbol\tau_s t`."""
        tau = sum(ctx.per_body(tq.tau, 1) for tq in cast(Sequence[SpaceTorque], torques))
        rest = ctx.m - ctx.t[:, None] * tau
        return {f"m_{ax} - tau_{ax} t": rest[..., i] for i, ax in enumerate("xyz")}

    def to_dict(self) -> dict[str, Any]:
        return {"kind": self.kind, "tau": plain(self.tau)}

    def __getitem__(self, idx: Any) -> SpaceTorque:
        return SpaceTorque(self.tau[idx]) if self.tau.ndim > 1 else self

    def __repr__(self) -> str:
        return f"SpaceTorque(tau={plain(self.tau)!r})"
