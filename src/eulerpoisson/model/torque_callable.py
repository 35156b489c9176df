r"""Torques given as Python functions (:class:`CallableTorque`), their stand-in when read back from a file
(:class:`UnrecordedTorque`), and what ``torque=`` accepts (:data:`TorqueLike`, :func:`as_torques`).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import Any, TypeAlias

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..errors import InvalidInputError
from .torque_base import (
    Torque,
    register_torque,
    z_rotation_quaternion,
)

__all__ = ["CallableTorque", "UnrecordedTorque", "TorqueLike", "as_torques"]


class CallableTorque(Torque):
    r"""Any Python function ``torque(t, q, omega) -> tau_body``.

    The function receives the time (a float, or an array broadcast against the
    batch), the attitude quaternions ``q`` (..., 4) (scalar first) and the body
    angular velocities (..., 3), and must return the body-frame torque with the
    shape of ``omega`` (real numbers; one vector (3,) is taken for every body
    of a batch), vectorized over the batch. Only methods that evaluate a
    right-hand side can run it (``rk``).

    Parameters
    ----------
    func : callable
    conservative : bool, default False
        Informational only (a callable has no potential here).

    Raises
    ------
    TypeError
        ``func`` is not callable (here), or returns something that is not numbers (at ``evaluate``).
    InvalidInputError
        At ``evaluate``: the function returned a scalar or a shape that is not ``(..., 3)``
        broadcastable to the shape of ``omega``, complex or boolean values, or NaN or infinite values.

    Examples
    --------
    >>> import numpy as np, eulerpoisson as ep
    >>> def damping(t, q, omega):
    ...     return -0.1 * omega
    >>> tq = ep.torques.CallableTorque(damping)
    >>> tq, tq.kind
    (CallableTorque('damping'), 'callable')
    >>> print(tq.evaluate(0.0, np.eye(3), np.array([1.0, 2.0, 3.0]), np.eye(3)))
    [-0.1 -0.2 -0.3]
    >>> try:
    ...     ep.torques.CallableTorque(lambda t, q, omega: 0.1).evaluate(0.0, np.eye(3), np.ones(3), np.eye(3))
    ... except ep.InvalidInputError as err:
    ...     print(err)
    the torque function CallableTorque('<lambda>') returned shape (); expected (3,) (the shape of omega: ...
    """

    kind = "callable"
    summary = "a Python function torque(t, q, omega) -> tau_body"
    depends_on_omega = True  # unknown: assume the worst
    time_dependent = True

    def __init__(self, func: Callable[..., ArrayLike]) -> None:
        if not callable(func):
            raise TypeError(f"torque must be a Torque or a callable torque(t, q, omega), got {func!r}")
        self.func = func

    def evaluate(
        self,
        t: ArrayLike,
        R: NDArray[np.float64],
        omega: NDArray[np.float64],
        inertia: NDArray[np.float64],
        q: NDArray[np.float64] | None = None,
    ) -> NDArray[np.float64]:
        if q is None:
            from ..attitude.core import quaternion_from_rotation_matrix

            q = quaternion_from_rotation_matrix(R)
        tau = self.func(t, q, omega)
        expected = np.shape(omega)
        try:
            raw = np.asarray(tau)
        except (TypeError, ValueError):
            raise TypeError(f"the torque function {self.func!r} must return a float array, got {tau!r}") from None
        if np.iscomplexobj(raw) or raw.dtype == bool:
            # a complex torque would lose its imaginary part, a boolean one would be 0 and 1: refuse both
            raise InvalidInputError(
                f"the torque function {self!r} returned {raw.dtype} values; expected real numbers (float64) "
                f"of shape {expected} (one body-frame torque per body)"
            )
        try:
            tau = raw.astype(float, copy=False)
        except (TypeError, ValueError):
            raise TypeError(f"the torque function {self.func!r} must return a float array, got {tau!r}") from None
        if tau.ndim == 0 or tau.shape[-1] != 3:
            # a scalar (or a list of one value) would silently become the same value on all three axes
            raise InvalidInputError(
                f"the torque function {self!r} returned shape {tau.shape}; expected {expected} (the shape of "
                f"omega: one body-frame torque vector (3 components) per body)"
            )
        if tau.shape != expected:
            try:
                tau = np.broadcast_to(tau, expected)  # one vector (3,) for every body of a batch
            except ValueError:
                raise InvalidInputError(
                    f"the torque function {self.func!r} returned shape {tau.shape}; expected {expected} "
                    f"(the shape of omega: one body-frame torque per body)"
                ) from None
        if not np.all(np.isfinite(tau)):
            raise InvalidInputError(f"the torque function {self.func!r} returned NaN or infinite values at t = {t!s}")
        return tau

    def shifted(self, t_start: float, phi: ArrayLike) -> CallableTorque:
        """The function called at ``s + t_start`` with the attitude turned back by ``phi`` (:meth:`Torque.shifted`)."""
        from ..numerics.quaternion import qmul

        turn = bool(np.any(np.asarray(phi) != 0))
        func, rz = self.func, z_rotation_quaternion(phi)

        def shifted(s, q, omega, _f=func, _rz=rz, _turn=turn):
            return _f(np.asarray(s) + t_start, qmul(_rz, q) if _turn else q, omega)

        shifted.__name__ = getattr(func, "__name__", "torque")
        return CallableTorque(shifted)

    def __repr__(self) -> str:
        return f"CallableTorque({getattr(self.func, '__name__', self.func)!r})"


@register_torque
class UnrecordedTorque(Torque):
    """Stand-in, read from a file, for a torque whose code was not recorded (a callable).

    The trajectory's data is intact; anything that must evaluate the torque
    raises :class:`NotImplementedError` naming it.

    Examples
    --------
    >>> import numpy as np, eulerpoisson as ep
    >>> tq = ep.torques.UnrecordedTorque("CallableTorque('damping')")   # as read back from a file
    >>> tq, tq.to_dict()
    (UnrecordedTorque("CallableTorque('damping')"), {'kind': 'unrecorded', 'description': "CallableTorque('damping')"})
    >>> try:
    ...     tq.evaluate(0.0, np.eye(3), np.zeros(3), np.eye(3))
    ... except NotImplementedError as err:
    ...     print(err)
    the torque CallableTorque('damping') was a Python function and was not saved in the file
    """

    kind = "unrecorded"
    summary = "a torque read from a file whose code was not recorded"
    depends_on_omega = True
    time_dependent = True

    def __init__(self, description: str = "") -> None:
        self.description = description

    def evaluate(
        self, t: ArrayLike, R: NDArray[np.float64], omega: NDArray[np.float64], inertia: NDArray[np.float64]
    ) -> NDArray[np.float64]:
        raise NotImplementedError(f"the torque {self.description} was a Python function and was not saved in the file")

    def to_dict(self) -> dict[str, Any]:
        return {"kind": self.kind, "description": self.description}

    def __repr__(self) -> str:
        return f"UnrecordedTorque({self.description!r})"


#: what ``torque=`` accepts: a :class:`Torque`, a callable ``torque(t, q, omega) -> tau_body``, a list of
#: them, or None (the free body)
TorqueLike: TypeAlias = "Torque | Callable[..., ArrayLike] | Sequence[Torque | Callable[..., ArrayLike]] | None"


def as_torques(torque: TorqueLike) -> tuple[Torque, ...]:
    """Normalize ``torque=`` (None, a Torque, a callable, or a list of them) to a tuple of :class:`Torque`.

    Raises
    ------
    TypeError
        An entry that is neither a :class:`Torque` nor callable.

    Examples
    --------
    >>> import eulerpoisson as ep
    >>> ep.torques.as_torques(None)
    ()
    >>> ep.torques.as_torques([ep.torques.BodyTorque([0.0, 0.0, 1.0]), lambda t, q, omega: 0.0 * omega])
    (BodyTorque(tau=[0.0, 0.0, 1.0]), CallableTorque('<lambda>'))
    """
    if torque is None:
        return ()
    if isinstance(torque, Torque):
        return (torque,)
    if isinstance(torque, (list, tuple)):
        out: list[Torque] = []
        for item in torque:
            out.extend(as_torques(item))
        return tuple(out)
    if callable(torque):
        return (CallableTorque(torque),)
    raise TypeError(
        f"torque must be a Torque (eulerpoisson.torques.Gravity, GravityGradient, BodyTorque, SpaceTorque), "
        f"a callable torque(t, q, omega) -> tau_body, or a list of them; got {torque!r}"
    )
