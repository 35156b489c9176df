r"""The heavy top (:class:`Gravity`): uniform gravity on a body with a fixed point, and its integrals.

Beside the energy and the vertical angular momentum, the classical integrable tops have a third
integral that :meth:`Gravity.integrals` recognizes from the inertia and the centre of mass: Lagrange's
(a symmetric top, :meth:`eulerpoisson.Model.lagrange_top`), Kovalevskaya's (moments 2:2:1, the centre
of mass in the equatorial plane) and Goryachev–Chaplygin's (moments 4:4:1, on the zero area level).

References
----------
Leimanis (1965), ch. I; Borisov and Mamaev (2018), §2.1.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING, Any, cast

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .torque_base import (
    STANDARD_GRAVITY,
    SYMMETRY_RTOL,
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
    scalar_param,
    vector_param,
)

if TYPE_CHECKING:
    from .equations import Model

__all__ = ["Gravity"]


def _gravity_direction(torques):
    """Common unit direction of g of the Gravity torques among ``torques``, or None."""
    return common_direction([t.g for t in torques if isinstance(t, Gravity)])


def _equatorial_top(model, ratio):
    r"""``(frame, x0y0, kappa, ghat)`` when the model is a heavy top with :math:`I = \mathrm{diag}(r, r, 1)I_3`
    and c in the equatorial plane, else None."""
    gs = [t for t in model.torques if isinstance(t, Gravity)]
    if len(gs) != 1 or len(model.torques) != 1 or model.batch_shape:
        return None
    grav = gs[0]
    ev = model.body.principal_moments
    P = model.body.principal_axes
    order = np.argsort(ev)
    small, a, b = ev[order[0]], ev[order[1]], ev[order[2]]
    if not (abs(a - b) <= SYMMETRY_RTOL * b and abs(a - ratio * small) <= 1e-12 * a):
        return None
    e3 = P[:, order[0]]
    e1 = P[:, order[1]]
    e2 = np.cross(e3, e1)
    F = np.stack([e1, e2, e3], axis=1)  # body = F @ frame
    c = F.T @ grav.center_of_mass
    if abs(c[2]) > SYMMETRY_RTOL * max(float(np.linalg.norm(c)), 1e-300) or np.linalg.norm(c) == 0:
        return None
    gn = float(np.linalg.norm(grav.g))
    kappa = float(grav.mass) * gn / float(small)
    return F, c[:2], kappa, grav.g / gn


@register_torque
class Gravity(Torque):
    r"""A heavy top: uniform gravity on a body with a fixed point at the body origin.

    .. math:: \boldsymbol\tau = \mathbf c\times(\mu R^T\mathbf g), \qquad
              U = -\mu\,\mathbf g\cdot(R\mathbf c),

    with :math:`\mu` the mass, :math:`\mathbf c` the centre of mass in the
    body frame and :math:`\mathbf g` the gravitational acceleration in the
    space frame. The inertia tensor of the body is taken about the fixed
    point (the body origin), not about the centre of mass. With
    :math:`\boldsymbol\gamma = R^T\mathbf g` (the Poisson vector,
    :math:`\dot{\boldsymbol\gamma} = \boldsymbol\gamma\times\boldsymbol\Omega`)
    these are the Euler–Poisson equations.

    Parameters
    ----------
    mass : float or array_like, shape (...)
        > 0.
    center_of_mass : array_like, shape (..., 3)
        Body frame, relative to the fixed point.
    g : array_like, shape (..., 3)
        Space frame; default (0, 0, -9.81).

    Raises
    ------
    InvalidInputError
        Non-positive mass, NaN, wrong shapes, batch shapes that do not broadcast.
    TypeError
        Non-numeric parameters.

    References
    ----------
    Leimanis (1965), ch. I; Borisov and Mamaev (2018), §2.1.

    Examples
    --------
    >>> import numpy as np, eulerpoisson as ep
    >>> top = ep.torques.Gravity(mass=1.0, center_of_mass=[0.0, 0.0, 0.1])   # g = (0, 0, -9.81)
    >>> top
    Gravity(mass=1.0, center_of_mass=[0.0, 0.0, 0.1], g=[0.0, 0.0, -9.81])
    >>> R = ep.Attitude.from_rotvec([np.pi / 2, 0.0, 0.0]).as_matrix()       # the axis horizontal
    >>> print(np.round(top.evaluate(0.0, R, np.zeros(3), np.eye(3)), 12) + 0.0)   # body frame
    [0.981 0.    0.   ]
    >>> print(np.round(top.potential(0.0, np.eye(3), np.eye(3)), 12))        # U = -m g.(R c)
    0.981
    """

    kind = "gravity"
    summary = "heavy top: uniform gravity on a body with a fixed point at the body origin"
    conservative = True
    cli = (
        TorqueParam(
            "center_of_mass",
            "--com",
            "center_of_mass",
            "vector3",
            help="heavy top: centre of mass in the body frame, from the fixed point (the inertia is about it)",
            units="m",
            metavar="CX,CY,CZ",
        ),
        TorqueParam(
            "mass",
            "--mass",
            "mass",
            "positive",
            help="heavy top: mass M > 0 (default 1; needs --com)",
            units="kg",
            metavar="M",
            default=1.0,
        ),
        TorqueParam(
            "g",
            "--gravity",
            "gravity",
            "vector3",
            help="heavy top: gravitational acceleration, space frame (default 0,0,-9.81; needs --com)",
            units="m s-2",
            metavar="GX,GY,GZ",
            default=(0.0, 0.0, -STANDARD_GRAVITY),
        ),
    )

    def __init__(
        self, mass: ArrayLike, center_of_mass: ArrayLike, g: ArrayLike = (0.0, 0.0, -STANDARD_GRAVITY)
    ) -> None:
        self.mass = scalar_param(mass, "mass", "Gravity", positive=True)
        self.center_of_mass = vector_param(center_of_mass, "center_of_mass", "Gravity")
        self.g = vector_param(g, "g", "Gravity")
        self._shape = param_batch_shape(
            "Gravity", mass=self.mass, center_of_mass=self.center_of_mass[..., 0], g=self.g[..., 0]
        )

    @property
    def batch_shape(self) -> tuple[int, ...]:
        return self._shape

    @property
    def moment_arm(self) -> np.ndarray:
        r""":math:`\mu\mathbf c`, shape (..., 3)."""
        return self.mass[..., None] * self.center_of_mass

    def evaluate(
        self, t: ArrayLike, R: NDArray[np.float64], omega: NDArray[np.float64], inertia: NDArray[np.float64]
    ) -> NDArray[np.float64]:
        return np.cross(self.moment_arm, body_frame(R, self.g))

    def potential(self, t: ArrayLike, R: NDArray[np.float64], inertia: NDArray[np.float64]) -> NDArray[np.float64]:
        return -np.einsum("...i,...i->...", self.g, np.einsum("...ij,...j->...i", R, self.moment_arm))

    def polynomial(self) -> PolynomialTorque:
        return PolynomialTorque(constant=np.zeros(3), vectors=(self.g,), maps=(cross_matrix(self.moment_arm),))

    def shifted(self, t_start: float, phi: ArrayLike) -> Gravity:
        """``g`` turned by ``-phi`` about z (see :meth:`Torque.shifted`)."""
        turn = bool(np.any(np.asarray(phi) != 0))
        return Gravity(self.mass, self.center_of_mass, rotate_about_z(self.g, -np.asarray(phi))) if turn else self

    @classmethod
    def integrals(cls, model: Model, torques: Sequence[Torque], ctx: IntegralContext) -> dict[str, np.ndarray]:
        r"""Heavy tops: the energy; with every ``g`` along one direction :math:`\hat{\mathbf g}`,
        ``m_vertical`` (:math:`\mathbf m\cdot\hat{\mathbf g}`); for one body, ``M3`` (a Lagrange top),
        ``kovalevskaya`` and ``goryachev_chaplygin`` (see :meth:`eulerpoisson.Model.integrals`)."""
        per_body = ctx.per_body
        R, M, m, omega = ctx.R, ctx.M, ctx.m, ctx.omega
        out: dict[str, np.ndarray] = {}
        U: Any = 0.0
        for tq in cast(Sequence[Gravity], torques):
            U = U - batched_dot(per_body(tq.g, 1), batched_matvec(R, per_body(tq.moment_arm, 1)))
        out["energy"] = ctx.kinetic + U
        ghat = _gravity_direction(cast(Sequence[Gravity], torques))
        if ghat is None:
            return out
        out["m_vertical"] = batched_dot(m, per_body(ghat, 1))
        if model.batch_shape:
            return out
        lt = model.lagrange_top()
        if lt is not None:
            out["M3"] = batched_dot(M, lt.frame[:, 2])
        for ratio, key in ((2.0, "kovalevskaya"), (4.0, "goryachev_chaplygin")):
            eq = _equatorial_top(model, ratio)
            if eq is None:
                continue
            F, c2, kappa, gh1 = eq
            w = batched_matvec(F.T, omega)
            gamma = -batched_matvec(F.T, np.einsum("...ji,j->...i", R, gh1))
            if key == "kovalevskaya":
                val = (w[..., 0] + 1j * w[..., 1]) ** 2 - kappa * (c2[0] + 1j * c2[1]) * (
                    gamma[..., 0] + 1j * gamma[..., 1]
                )
                out[key] = (val * np.conj(val)).real
            else:
                area = out["m_vertical"]
                scale = float(np.sqrt(np.max(batched_dot(m, m)))) if m.size else 0.0
                if area.size and np.all(np.abs(area[..., 0]) <= 1e-12 * max(scale, 1e-300)):
                    out[key] = w[..., 2] * (w[..., 0] ** 2 + w[..., 1] ** 2) - kappa * gamma[..., 2] * (
                        c2[0] * w[..., 0] + c2[1] * w[..., 1]
                    )
        return out

    def to_dict(self) -> dict[str, Any]:
        return {
            "kind": self.kind,
            "mass": plain(self.mass),
            "center_of_mass": plain(self.center_of_mass),
            "g": plain(self.g),
        }

    def __getitem__(self, idx: Any) -> Gravity:
        b = self._shape
        return Gravity(
            np.broadcast_to(self.mass, b)[idx],
            np.broadcast_to(self.center_of_mass, b + (3,))[idx],
            np.broadcast_to(self.g, b + (3,))[idx],
        )

    def __repr__(self) -> str:
        return f"Gravity(mass={plain(self.mass)!r}, center_of_mass={plain(self.center_of_mass)!r}, g={plain(self.g)!r})"
