r"""The equations of motion as one object: :class:`Model` = a body plus torques.

Every solution method consumes a :class:`Model`: the free-body part (the
inertia tensor, :class:`~eulerpoisson.RigidBody`) and zero or more torques
(:mod:`eulerpoisson.torques`). The model gives

- the vector field of :math:`(q, \boldsymbol\Omega)` (:meth:`Model.rhs`),

  .. math:: \dot q = \tfrac12\,q\otimes(0, \boldsymbol\Omega), \qquad
            I\dot{\boldsymbol\Omega} = (I\boldsymbol\Omega)\times\boldsymbol\Omega
            + \boldsymbol\tau(t, R, \boldsymbol\Omega)

  (paper eq. 1.4-1.5 with the torque of the Euler–Poisson equations);
- the energy with the potential of the conservative torques
  (:meth:`Model.energy`), and the conserved quantities of the model
  (:meth:`Model.integrals`), recognized from the data: the free body's energy
  and spatial angular momentum; for a heavy top the energy and the vertical
  component of :math:`\mathbf m`, plus :math:`M_3` for a Lagrange top, the
  Kovalevskaya integral when :math:`I_1 = I_2 = 2I_3` with the centre of mass
  in the equatorial plane, the Goryachev–Chaplygin integral when
  :math:`I_1 = I_2 = 4I_3` on its level :math:`\mathbf m\cdot\hat{\mathbf g} = 0`;
  the Jacobi integral for the gravity gradient; each torque class states
  its own (:meth:`eulerpoisson.torques.Torque.integrals`);
- what a method needs to decide whether it can run the model
  (:attr:`Model.is_free`, :meth:`Model.polynomial`, :meth:`Model.potential`,
  :meth:`Model.lagrange_top`).

The free-body shortcuts of the methods (the principal frame, left
invariance, chart restarts) are taken only when :attr:`Model.is_free`.

References
----------
Paper eq. 1.4-1.5. Borisov and Mamaev, *Rigid Body Dynamics* (2018), §2.1-2.3
(the Euler–Poisson equations and their integrable cases). S. Kovalevskaya,
"Sur le problème de la rotation d'un corps solide autour d'un point fixe",
Acta Math. 12 (1889) 177-232. D. N. Goryachev (1900), S. A. Chaplygin (1901).
"""

from __future__ import annotations

from typing import NamedTuple, cast

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..attitude.core import matrix_from_unit_quaternion
from ..errors import InvalidInputError
from ..numerics.quaternion import qmul_components
from .body import RigidBody
from .torques import (
    SYMMETRY_RTOL,
    CallableTorque,
    Gravity,
    IntegralContext,
    PolynomialTorque,
    Torque,
    TorqueLike,
    as_torques,
)

__all__ = ["Model", "LagrangeTop", "as_model"]


def _mv(A, v):
    return np.einsum("...ij,...j->...i", A, v)


def _dot(a, b):
    return np.einsum("...i,...i->...", a, b)


def _dot3(a, b):
    """``a . b`` over the last axis (length 3) as an explicit sum of three products: no reduction whose
    order could depend on the batch, so an element of a batch gives the bits it gives alone."""
    return a[..., 0] * b[..., 0] + a[..., 1] * b[..., 1] + a[..., 2] * b[..., 2]


class LagrangeTop(NamedTuple):
    r"""A heavy symmetric top with its centre of mass on the symmetry axis, in its own frame.

    The body frame is rotated by :math:`P` (``frame``, :math:`\det P = 1`) so
    that the symmetry axis is :math:`\mathbf e_3`: :math:`I = P\,\mathrm{diag}(A, A, C)P^T`,
    :math:`\mathbf c = P(0, 0, \ell)`.
    """

    A: np.ndarray
    C: np.ndarray
    mass: np.ndarray
    ell: np.ndarray
    g: np.ndarray
    frame: np.ndarray


class Model:
    r"""The equations of motion: a rigid body and the torques acting on it.

    Parameters
    ----------
    body : RigidBody or array_like
        The body or a batch of bodies (an array is passed to :class:`RigidBody`).
        For a heavy top the inertia is about the fixed point (the body origin).
    torque : Torque, callable, list of them, or None
        :mod:`eulerpoisson.torques` objects, callables ``torque(t, q, omega) ->
        tau_body``, or a list of them (their sum); None: the free body.

    Raises
    ------
    TypeError
        A torque that is neither a :class:`~eulerpoisson.torques.Torque` nor callable.
    InvalidInputError
        Parameter batch shapes that do not broadcast with the body's.

    Examples
    --------
    >>> import eulerpoisson as ep
    >>> top = ep.Model([2.0, 2.0, 1.0], ep.torques.Gravity(1.0, [0.0, 0.0, 0.5]))
    >>> top.is_free, top.lagrange_top() is not None
    (False, True)
    """

    def __init__(self, body: RigidBody | ArrayLike, torque: TorqueLike = None) -> None:
        self.torques: tuple[Torque, ...]
        if torque is None and type(body) is RigidBody:  # the free body (the common case, without the steps below)
            self.body = body
            self.torques = ()
            self.batch_shape = body.batch_shape
            return
        if isinstance(body, Model):
            raise TypeError("body is already a Model; pass its body and torques, or the Model itself to solve()")
        if not isinstance(body, RigidBody):
            if isinstance(body, (str, bytes)) or body is None:
                raise TypeError(f"body must be a RigidBody or an inertia array, got {body!r}")
            body = RigidBody(body)
        self.body = body
        self.torques = as_torques(torque)
        shapes = [body.batch_shape] + [tq.batch_shape for tq in self.torques]
        try:
            self.batch_shape = np.broadcast_shapes(*shapes) if self.torques else body.batch_shape
        except ValueError:
            desc = ", ".join(f"{type(t).__name__} {t.batch_shape}" for t in self.torques)
            raise InvalidInputError(
                f"the batch shapes of the body {body.batch_shape} and of the torque parameters ({desc}) do not broadcast"
            ) from None

    # ------------------------------------------------------------------
    @property
    def is_free(self) -> bool:
        """No torque: the free rigid body (every free-body shortcut applies)."""
        return not self.torques

    @property
    def is_conservative(self) -> bool:
        """Every torque derives from a potential."""
        return all(t.conservative for t in self.torques)

    @property
    def is_autonomous(self) -> bool:
        return not any(t.time_dependent for t in self.torques)

    def describe(self) -> str:
        """A one-line description (``"free body"``, ``"Gravity(...) + BodyTorque(...)"``)."""
        return "free body" if self.is_free else " + ".join(repr(t) for t in self.torques)

    def to_records(self) -> list[dict]:
        """The torques as JSON-able records (:func:`~eulerpoisson.torques.torque_from_dict` reads them)."""
        return [t.to_dict() for t in self.torques]

    def __repr__(self) -> str:
        return f"Model({self.body!r}, torque={list(self.torques)!r})"

    def _repr_html_(self) -> str:
        """A compact HTML table for notebooks: :func:`eulerpoisson.util.htmlrepr.model_html`."""
        from ..util.htmlrepr import model_html

        return model_html(self)

    def element(self, index: tuple[int | np.integer, ...]) -> Model:
        """The model of one element of a batch: ``index`` is a full index into a batch shape that this
        model's batch shape broadcasts to (numpy's right-aligned broadcasting rules)."""
        index = tuple(int(i) for i in index)

        def sub(shape):
            k = len(shape)
            tail = index[len(index) - k :] if k else ()
            return tuple(0 if n == 1 else i for i, n in zip(tail, shape))

        body = self.body[sub(self.body.batch_shape)] if self.body.batch_shape else self.body
        return Model(body, [t[sub(t.batch_shape)] if t.batch_shape else t for t in self.torques])

    # ------------------------------------------------------------------
    # the vector field
    # ------------------------------------------------------------------
    def torque(self, t: ArrayLike, q: ArrayLike, omega: ArrayLike) -> NDArray[np.float64]:
        r"""Total body-frame torque :math:`\boldsymbol\tau(t, q, \boldsymbol\Omega)`, shape (..., 3).

        Parameters
        ----------
        t : float or ndarray, shape (...)
        q : ndarray, shape (..., 4)
            Unit quaternions (scalar first).
        omega : ndarray, shape (..., 3)
        """
        omega = np.asarray(omega, dtype=float)
        out = np.zeros(np.broadcast_shapes(omega.shape, np.shape(q)[:-1] + (3,)))
        if not self.torques:
            return out
        q = np.asarray(q, dtype=float)
        R = matrix_from_unit_quaternion(q)
        inertia = self.body.inertia
        for tq in self.torques:
            if tq.kind == "callable":
                out = out + cast(CallableTorque, tq).evaluate(t, R, omega, inertia, q=q)
            else:
                out = out + tq.evaluate(t, R, omega, inertia)
        return out

    def omega_dot(self, t: ArrayLike, q: ArrayLike, omega: ArrayLike) -> NDArray[np.float64]:
        r""":math:`\dot{\boldsymbol\Omega} = I^{-1}\big((I\boldsymbol\Omega)\times\boldsymbol\Omega + \boldsymbol\tau\big)`, shape (..., 3)."""
        omega = np.asarray(omega, dtype=float)
        M = _mv(self.body.inertia, omega)
        rhs = np.cross(M, omega)
        if self.torques:
            rhs = rhs + self.torque(t, q, omega)
        return _mv(self.body.inertia_inv, rhs)

    def rhs(self, t: ArrayLike, q: ArrayLike, omega: ArrayLike) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        r"""The vector field :math:`(\dot q, \dot{\boldsymbol\Omega})`.

        Parameters
        ----------
        t : float or ndarray, shape (...)
        q : ndarray, shape (..., 4)
        omega : ndarray, shape (..., 3)

        Returns
        -------
        qdot : ndarray, shape (..., 4)
            :math:`\tfrac12 q\otimes(0, \boldsymbol\Omega)`.
        omega_dot : ndarray, shape (..., 3)

        References
        ----------
        Paper eq. 1.4 (in quaternions) and 1.5.
        """
        q = np.asarray(q, dtype=float)
        omega = np.asarray(omega, dtype=float)
        zero = np.zeros_like(omega[..., 0])
        qd = 0.5 * np.stack(
            qmul_components(
                q[..., 0], q[..., 1], q[..., 2], q[..., 3], zero, omega[..., 0], omega[..., 1], omega[..., 2]
            ),
            -1,
        )
        return qd, self.omega_dot(t, q, omega)

    def polynomial(self) -> PolynomialTorque | None:
        """The sum of the torques as a :class:`~eulerpoisson.torques.PolynomialTorque`, or None if one is not polynomial."""
        total = PolynomialTorque.zero()
        for tq in self.torques:
            p = tq.polynomial()
            if p is None:
                return None
            total = total + p
        return total

    # ------------------------------------------------------------------
    # energy and integrals
    # ------------------------------------------------------------------
    def potential(self, t: ArrayLike, q: ArrayLike) -> NDArray[np.float64]:
        r"""Sum of the potentials :math:`U(t, R)` of the conservative torques, shape (...).

        Torques without a potential contribute nothing (see :attr:`is_conservative`).
        """
        q = np.asarray(q, dtype=float)
        U = np.zeros(q.shape[:-1])
        if not self.torques:
            return U
        R = matrix_from_unit_quaternion(q)
        for tq in self.torques:
            if tq.conservative:
                U = U + tq.potential(t, R, self.body.inertia)
        return U

    def energy(self, t: ArrayLike, q: ArrayLike, omega: ArrayLike) -> NDArray[np.float64]:
        r"""Kinetic plus potential energy :math:`\tfrac12\boldsymbol\Omega\cdot I\boldsymbol\Omega + U`, shape (...)."""
        omega = np.asarray(omega, dtype=float)
        E = 0.5 * _dot(omega, _mv(self.body.inertia, omega))
        return E + self.potential(t, q) if self.torques else E

    def lagrange_top(self) -> LagrangeTop | None:
        r"""The model as a :class:`LagrangeTop` (symmetric body, centre of mass on the axis, one Gravity), else None.

        A spherical body (three equal moments) with its centre of mass off
        the origin is a Lagrange top about the axis through the centre of
        mass; a centre of mass at the origin is a free body under no torque
        (not reported here). For a batch the fields have the batch shape
        (``frame``: ``(*batch, 3, 3)``), computed element by element in
        vectorized arithmetic (the same bits for an element alone or in any
        batch); None unless every element is a Lagrange top.
        """
        if len(self.torques) != 1 or not isinstance(self.torques[0], Gravity):
            return None
        grav = self.torques[0]
        shape = tuple(self.batch_shape)
        c = np.broadcast_to(np.asarray(grav.center_of_mass, dtype=float), shape + (3,))
        cn = np.sqrt(_dot3(c, c))
        if np.any(cn == 0.0):
            return None
        ev = np.broadcast_to(self.body.principal_moments, shape + (3,))
        P = np.broadcast_to(self.body.principal_axes, shape + (3, 3))
        inertia = np.broadcast_to(self.body.inertia, shape + (3, 3))
        tol = SYMMETRY_RTOL * np.max(ev, axis=-1)
        chat = c / cn[..., None]
        Ic = _dot3(inertia, chat[..., None, :])
        C = _dot3(chat, Ic)
        d = Ic - C[..., None] * chat
        # the centre of mass must lie on an eigenvector whose eigenvalue is simple or the body a sphere,
        if np.any(np.sqrt(_dot3(d, d)) > tol):
            return None
        # and the other two moments (the eigenvalue C removed once) must be equal
        k = np.argmin(np.abs(ev - C[..., None]), axis=-1)
        rest = ev[np.arange(3) != k[..., None]].reshape(shape + (2,))
        if np.any(np.abs(rest[..., 0] - rest[..., 1]) > tol):
            return None
        A = 0.5 * (rest[..., 0] + rest[..., 1])
        # frame: e3 = chat, e1 any unit vector perpendicular to it (the principal axis farthest from C,
        # or for a sphere the coordinate axis least aligned with chat)
        j = np.argmax(np.abs(ev - C[..., None]), axis=-1)
        from_axes = np.take_along_axis(P, j[..., None, None], axis=-1)[..., 0]
        from_eye = np.eye(3)[np.argmin(np.abs(chat), axis=-1)]
        trial = np.where((np.ptp(ev, axis=-1) > tol)[..., None], from_axes, from_eye)
        e1 = trial - _dot3(trial, chat)[..., None] * chat
        e1 = e1 / np.sqrt(_dot3(e1, e1))[..., None]
        e2 = np.cross(chat, e1)
        F = np.stack([e1, e2, chat], axis=-1)
        mass = np.array(np.broadcast_to(np.asarray(grav.mass, dtype=float), shape))
        g = np.array(np.broadcast_to(np.asarray(grav.g, dtype=float), shape + (3,)))
        return LagrangeTop(A=np.asarray(A), C=np.asarray(C), mass=mass, ell=np.asarray(cn), g=g, frame=F)

    def integrals(self, t: ArrayLike, q: ArrayLike, omega: ArrayLike) -> dict[str, NDArray[np.float64]]:
        r"""The conserved quantities of the model along a trajectory.

        Parameters
        ----------
        t : ndarray, shape (T,)
        q : ndarray, shape ``(*batch, T, 4)``
            Unit quaternions; the model's batch shape broadcasts to ``batch``.
        omega : ndarray, shape ``(*batch, T, 3)``

        Returns
        -------
        dict of str to ndarray, shape ``(*batch, T)``
            Free body: ``energy``, ``m_x``, ``m_y``, ``m_z`` (spatial angular
            momentum) and ``m_norm``. Heavy top (gravity along one direction):
            ``energy`` and ``m_vertical`` (:math:`\mathbf m\cdot\hat{\mathbf g}`),
            plus, for one body, ``M3`` (:math:`\mathbf M\cdot\mathbf e_3` about the
            symmetry axis) for a Lagrange top, ``kovalevskaya`` for
            :math:`I = \mathrm{diag}(2,2,1)I_3` with the centre of mass in the
            equatorial plane,

            .. math:: K = \big|(\Omega_1 + i\Omega_2)^2 - \kappa(c_1 + ic_2)(\gamma_1 + i\gamma_2)\big|^2,

            and ``goryachev_chaplygin`` for :math:`\mathrm{diag}(4,4,1)I_3`,
            :math:`G = \Omega_3(\Omega_1^2 + \Omega_2^2) - \kappa\gamma_3(c_1\Omega_1 + c_2\Omega_2)`,
            reported only where its level :math:`\mathbf m\cdot\hat{\mathbf g} = 0` holds at the
            first state (:math:`\kappa = \mu|\mathbf g|/I_3`,
            :math:`\boldsymbol\gamma = -R^T\hat{\mathbf g}`, components in the frame of
            the symmetry axis). Gravity gradient alone: ``jacobi``,
            :math:`J = \tfrac12\boldsymbol\Omega\cdot I\boldsymbol\Omega
            - \nu\,\hat{\mathbf e}_z\cdot\mathbf m + \tfrac32\nu^2\mathbf r\cdot I\mathbf r`.
            Constant space-frame torques alone: the components of
            :math:`\mathbf m - \boldsymbol\tau_s t`. Magnetic dipoles in constant
            fields alone: ``energy`` and, with parallel fields, ``m_field``
            (:math:`\mathbf m\cdot\hat{\mathbf B}`). Other models: the ``energy``
            when every torque is conservative and autonomous, else what holds for
            them (possibly nothing). Each torque class says what it conserves
            (:meth:`eulerpoisson.torques.Torque.integrals`).

        References
        ----------
        Borisov and Mamaev (2018), §2.2-2.3; Kovalevskaya (1889); Goryachev (1900),
        Chaplygin (1901); Beletsky (1966), ch. 1 (the Jacobi integral).
        """
        t = np.asarray(t, dtype=float)
        q = np.asarray(q, dtype=float)
        omega = np.asarray(omega, dtype=float)
        per_body = IntegralContext.per_body
        inertia = per_body(self.body.inertia, 2)
        # the same expressions as Trajectory.M, .m and .energy (so that the drifts agree to the last bit)
        R = matrix_from_unit_quaternion(q)
        M = np.einsum("...ij,...j->...i", inertia, omega)
        m = np.einsum("...ij,...j->...i", R, M)
        kinetic = 0.5 * np.sum(omega * M, -1)
        out: dict[str, np.ndarray] = {}
        if self.is_free:
            out["energy"] = kinetic
            out["m_x"], out["m_y"], out["m_z"] = m[..., 0], m[..., 1], m[..., 2]
            out["m_norm"] = np.sqrt(_dot(m, m))
            return out
        # what the torques conserve: the hook of their class when they are all of one, else the base rule
        kinds = {type(tq) for tq in self.torques}
        hook = kinds.pop() if len(kinds) == 1 else Torque
        ctx = IntegralContext(t=t, R=R, omega=omega, M=M, m=m, kinetic=kinetic, inertia=inertia)
        out.update(hook.integrals(self, self.torques, ctx))
        return out

    # ------------------------------------------------------------------
    # continuing from a later time
    # ------------------------------------------------------------------
    def shifted(self, t_start: float) -> tuple[Model, NDArray[np.float64]]:
        r"""The model seen from the time ``t_start`` on: ``(model', phi)``.

        With :math:`s = t - t_\mathrm{start}`, the motion under ``model'``
        from the state at ``t_start`` rotated by :math:`R_z(-\varphi)` is the
        original motion, rotated by :math:`R_z(-\varphi)` in space. A torque
        that turns the space frame (:attr:`~eulerpoisson.torques.Torque.frame_rate`,
        a gravity gradient of mean motion :math:`\nu`: its orbit direction is
        :math:`\hat{\mathbf r}(t_\mathrm{start} + s) = R_z(\varphi)\hat{\mathbf r}(s)`)
        sets :math:`\varphi = \nu t_\mathrm{start}` (the first one with a rate not
        zero); every torque is then shifted by its own
        :meth:`~eulerpoisson.torques.Torque.shifted` (space-fixed vectors turned by
        :math:`-\varphi`, a Python function called at the shifted time with the
        attitude turned back, body-frame torques unchanged).

        Parameters
        ----------
        t_start : float

        Returns
        -------
        model : Model
            The same body under the shifted torques.
        phi : ndarray, shape () or the batch shape of the rate
            :math:`\varphi` (rad; zero when no torque turns the frame).

        Raises
        ------
        InvalidInputError
            A time-dependent torque of a class that cannot be shifted.

        Examples
        --------
        >>> import numpy as np, eulerpoisson as ep
        >>> model = ep.Model([1.0, 2.0, 2.5], [ep.torques.GravityGradient(0.5), ep.torques.SpaceTorque([1.0, 0.0, 0.0])])
        >>> later, phi = model.shifted(np.pi)
        >>> print(phi, np.round(later.torques[1].tau, 12) + 0.0)        # phi = nu t_start; tau turned by -phi
        1.5707963267948966 [ 0. -1.  0.]
        """
        phi = np.zeros(())
        for tq in self.torques:
            rate = tq.frame_rate
            if rate is not None and np.any(rate != 0):
                phi = np.asarray(rate, dtype=float) * t_start
                break
        return Model(self.body, [tq.shifted(t_start, phi) for tq in self.torques]), phi


def as_model(body: Model | RigidBody | ArrayLike, torque: TorqueLike = None) -> Model:
    """A :class:`Model` from ``body`` (a Model, a RigidBody or an inertia array) and ``torque``.

    Raises
    ------
    TypeError
        A Model together with a separate ``torque``.
    """
    if isinstance(body, Model):
        if torque is not None:
            raise TypeError("give the torque either in the Model or as torque=, not both")
        return body
    return Model(body, torque)
