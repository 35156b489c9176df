r"""The gravity-gradient torque of a circular orbit (:class:`GravityGradient`).

References
----------
P. C. Hughes, *Spacecraft Attitude Dynamics*, Wiley (1986), §8.3.
"""

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
    batched_dot,
    batched_matvec,
    body_frame,
    plain,
    register_torque,
    scalar_param,
)

if TYPE_CHECKING:
    from .equations import Model

__all__ = ["GravityGradient"]


@register_torque
class GravityGradient(Torque):
    r"""Gravity-gradient torque on a body in a circular orbit.

    The orbit lies in the space frame's :math:`x`–:math:`y` plane; the unit
    vector from the planet to the body is :math:`\hat{\mathbf r}(t) =
    (\cos\nu t, \sin\nu t, 0)` with the mean motion :math:`\nu`. To second
    order in the body's size,

    .. math:: \boldsymbol\tau = 3\nu^2\,\mathbf r\times(I\mathbf r), \qquad
              U = \tfrac32\nu^2\,\mathbf r\cdot I\mathbf r, \qquad
              \mathbf r = R^T\hat{\mathbf r}(t),

    with :math:`I` the inertia about the centre of mass (the body origin).
    The potential depends on time through :math:`\hat{\mathbf r}(t)`, so the
    energy is not conserved; in the frame rotating with the orbit the
    Jacobi integral is (:meth:`~eulerpoisson.Model.integrals`).

    Parameters
    ----------
    mean_motion : float or array_like, shape (...)
        :math:`\nu` (rad per time unit), >= 0.

    References
    ----------
    P. C. Hughes, *Spacecraft Attitude Dynamics* (1986), §8.3; V. V. Beletsky,
    *Motion of an Artificial Satellite about its Center of Mass* (1966), ch. 1.

    Examples
    --------
    >>> import numpy as np, eulerpoisson as ep
    >>> gg = ep.torques.GravityGradient(mean_motion=0.1)
    >>> print(gg.direction(0.0), gg.conservative, gg.time_dependent)
    [1. 0. 0.] True True
    >>> R = ep.Attitude.from_rotvec([0.0, 0.0, 0.3]).as_matrix()
    >>> print(np.round(gg.evaluate(0.0, R, np.zeros(3), np.diag([1.0, 2.0, 2.5])), 9) + 0.0)
    [ 0.          0.         -0.00846964]
    """

    kind = "gravity_gradient"
    summary = "gravity gradient on a body in a circular orbit in the space x-y plane"
    conservative = True
    time_dependent = True
    cli = (
        TorqueParam(
            "mean_motion",
            "--gravity-gradient",
            "gravity_gradient",
            "number",
            help="gravity-gradient torque of a circular orbit with mean motion NU >= 0 (rad per time unit)",
            units="rad s-1",
            metavar="NU",
        ),
    )

    def __init__(self, mean_motion: ArrayLike) -> None:
        self.mean_motion = scalar_param(mean_motion, "mean_motion", "GravityGradient", nonnegative=True)

    @property
    def batch_shape(self) -> tuple[int, ...]:
        return self.mean_motion.shape

    def direction(self, t: ArrayLike) -> NDArray[np.float64]:
        r""":math:`\hat{\mathbf r}(t)` in the space frame, shape (..., 3)."""
        phase = np.asarray(t, dtype=float) * self.mean_motion
        return np.stack([np.cos(phase), np.sin(phase), np.zeros_like(phase)], -1)

    def evaluate(
        self, t: ArrayLike, R: NDArray[np.float64], omega: NDArray[np.float64], inertia: NDArray[np.float64]
    ) -> NDArray[np.float64]:
        r = body_frame(R, self.direction(t))
        Ir = np.einsum("...ij,...j->...i", inertia, r)
        return 3.0 * (self.mean_motion**2)[..., None] * np.cross(r, Ir)

    def potential(self, t: ArrayLike, R: NDArray[np.float64], inertia: NDArray[np.float64]) -> NDArray[np.float64]:
        r = body_frame(R, self.direction(t))
        Ir = np.einsum("...ij,...j->...i", inertia, r)
        return 1.5 * self.mean_motion**2 * np.einsum("...i,...i->...", r, Ir)

    def polynomial(self) -> PolynomialTorque:
        return PolynomialTorque(constant=np.zeros(3), orbit_rate=self.mean_motion, orbit_gain=3.0 * self.mean_motion**2)

    @property
    def frame_rate(self) -> NDArray[np.float64]:
        """The mean motion: the orbit turns the space frame at this rate about z."""
        return self.mean_motion

    def shifted(self, t_start: float, phi: ArrayLike) -> GravityGradient:
        """Unchanged: in the space frame turned with the orbit the torque is the same (:meth:`Torque.shifted`)."""
        return self

    @classmethod
    def integrals(cls, model: Model, torques: Sequence[Torque], ctx: IntegralContext) -> dict[str, np.ndarray]:
        r"""One gravity gradient: the Jacobi integral ``jacobi`` (:meth:`eulerpoisson.Model.integrals`)."""
        if len(torques) != 1:
            return {}
        nu = ctx.per_body(cast(GravityGradient, torques[0]).mean_motion, 0)
        phase = ctx.t * nu
        rhat = np.stack([np.cos(phase), np.sin(phase), np.zeros_like(phase)], -1)
        r = np.einsum("...ji,...j->...i", ctx.R, rhat)
        return {
            "jacobi": ctx.kinetic - nu * ctx.m[..., 2] + 1.5 * nu**2 * batched_dot(r, batched_matvec(ctx.inertia, r))
        }

    def to_dict(self) -> dict[str, Any]:
        return {"kind": self.kind, "mean_motion": plain(self.mean_motion)}

    def __getitem__(self, idx: Any) -> GravityGradient:
        return GravityGradient(np.broadcast_to(self.mean_motion, self.batch_shape)[idx])

    def __repr__(self) -> str:
        return f"GravityGradient(mean_motion={plain(self.mean_motion)!r})"
