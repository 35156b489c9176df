r"""The rigid body: inertia tensor, principal frame and point-mass bodies.

A :class:`RigidBody` holds the inertia tensor :math:`I` in the body frame,
either diagonal (three principal moments) or a full symmetric tensor, checks
that it describes a physical body, and gives its principal moments and axes.
:meth:`RigidBody.from_particles` builds one from the point masses of the
paper's action (eq. 1.1).

References
----------
Paper eq. 1.1-1.3, 1.5, 1.25. L. D. Landau and E. M. Lifshitz, *Mechanics*, §32.
"""

from __future__ import annotations

import numpy as np

from ._validate import as_float_array
from .errors import InvalidInertiaError, InvalidInputError

__all__ = ["RigidBody"]

#: relative tolerance used to flag symmetric / spherical / planar bodies and
#: to accept the triangle inequality as an equality
DEGENERACY_RTOL = 1e-12


def _check_tensor(I: np.ndarray, name: str = "inertia") -> None:
    scale = np.max(np.abs(I), axis=(-1, -2), keepdims=True)
    if np.any(scale == 0):
        raise InvalidInertiaError(f"{name} is zero; a rigid body needs a positive-definite inertia tensor")
    asym = np.max(np.abs(I - np.swapaxes(I, -1, -2)) / scale)
    if asym > 1e-12:
        raise InvalidInertiaError(
            f"{name} is not symmetric: max |I - I^T| / max |I| = {asym:.3g}; an inertia tensor must be symmetric"
        )


def _check_moments(ev: np.ndarray, name: str = "inertia") -> None:
    """Positive and triangle inequalities on principal moments (..., 3)."""
    if np.any(ev <= 0):
        bad = ev[np.any(ev <= 0, axis=-1)][0]
        raise InvalidInertiaError(
            f"{name} is not positive definite: principal moments {np.round(bad, 15).tolist()}; "
            "every principal moment must be > 0 (a body needs at least three non-collinear masses)"
        )
    s = np.sort(ev, axis=-1)
    slack = s[..., 0] + s[..., 1] - s[..., 2]
    tol = DEGENERACY_RTOL * np.sum(s, -1)
    if np.any(slack < -tol):
        bad = s[slack < -tol][0]
        raise InvalidInertiaError(
            "inertia violates the triangle inequality I1 + I2 >= I3 of a physical body: principal moments "
            f"{bad.tolist()} have {bad[0]} + {bad[1]} < {bad[2]}"
        )


class RigidBody:
    r"""A rigid body given by its inertia tensor in the body frame.

    Parameters
    ----------
    inertia : array_like, shape (..., 3) or (..., 3, 3)
        Three principal moments :math:`(I_1, I_2, I_3)` (the body frame is then
        the principal frame) or a full symmetric positive-definite tensor.
        Leading axes make a batch of bodies.
    name : str, optional
        A label used in plots and files.

    Attributes
    ----------
    inertia : ndarray, shape (..., 3, 3)
        Inertia tensor in the body frame.
    principal_moments : ndarray, shape (..., 3)
        Eigenvalues of ``inertia``; in the given order for diagonal input,
        ascending otherwise.
    principal_axes : ndarray, shape (..., 3, 3)
        Right-handed orthonormal columns: ``inertia = P diag(moments) P^T``.

    Raises
    ------
    InvalidInertiaError
        Not symmetric, not positive definite, or violating the triangle
        inequality (:math:`I_1 + I_2 < I_3` is not a physical body).
    InvalidInputError
        Wrong shape, NaN or infinite entries.

    Notes
    -----
    Degenerate but physical bodies are accepted and flagged:
    :attr:`is_symmetric` (two equal moments: a symmetric top, ``kind``
    ``"prolate"`` or ``"oblate"``), :attr:`is_sphere` (three equal),
    :attr:`is_planar` (:math:`I_1 + I_2 = I_3`: all mass in a plane).

    References
    ----------
    Paper eq. 1.5 (Euler's equations use this tensor) and 1.25.

    Examples
    --------
    >>> body = RigidBody([1.0, 2.0, 3.0])
    >>> body.kind
    'asymmetric'
    >>> RigidBody([[2, 0, 0], [0, 2, 0], [0, 0, 3]]).kind
    'oblate'
    """

    def __init__(self, inertia, *, name: str | None = None):
        a = as_float_array(inertia, "inertia")
        if a.ndim >= 2 and a.shape[-2:] == (3, 3):
            _check_tensor(a)
            I = 0.5 * (a + np.swapaxes(a, -1, -2))
            offdiag = I - I * np.eye(3)
            if np.all(offdiag == 0):
                ev = np.diagonal(I, axis1=-2, axis2=-1).copy()
                P = np.broadcast_to(np.eye(3), I.shape).copy()
            else:
                ev, P = np.linalg.eigh(I)
                det = np.linalg.det(P)
                P[..., :, 2] *= np.sign(det)[..., None]
        elif a.ndim >= 1 and a.shape[-1] == 3:
            ev = a.copy()
            I = ev[..., :, None] * np.eye(3)
            P = np.broadcast_to(np.eye(3), I.shape).copy()
        else:
            raise InvalidInputError(
                f"inertia must be three principal moments, shape (..., 3), or a 3x3 tensor, "
                f"shape (..., 3, 3); got shape {a.shape}"
            )
        _check_moments(ev)
        self.inertia = I
        self.principal_moments = ev
        self.principal_axes = P
        self.name = name
        self.masses: np.ndarray | None = None
        self.positions: np.ndarray | None = None
        self.center_of_mass: np.ndarray | None = None

    # ------------------------------------------------------------------
    @classmethod
    def from_particles(cls, masses, positions, *, name: str | None = None) -> "RigidBody":
        r"""A body made of point masses (the system of the paper's eq. 1.1).

        The centre of mass :math:`\mathbf C = \sum m_N\mathbf y_N/\sum m_N` is
        removed and the inertia tensor about it is
        :math:`I = \sum_N m_N(\mathbf x_N^2\mathbf 1 - \mathbf x_N\mathbf x_N^T)
        = \mathrm{tr}(g)\mathbf 1 - g` with the paper's
        :math:`g_{ij} = \sum_N m_N x^i_N x^j_N` (eq. 1.3). The body frame is
        the frame of ``positions``, translated to the centre of mass.

        Parameters
        ----------
        masses : array_like, shape (N,)
            Positive masses.
        positions : array_like, shape (N, 3)
            Positions at t = 0.

        Returns
        -------
        RigidBody
            With :attr:`masses`, :attr:`positions` (relative to the centre of
            mass) and :attr:`center_of_mass` set.

        Raises
        ------
        InvalidInputError
            Shapes that do not match, non-positive or non-finite masses, or
            fewer than three non-collinear masses (the inertia tensor would be
            singular).
        """
        m = as_float_array(masses, "masses")
        x = as_float_array(positions, "positions", (3,))
        if m.ndim != 1 or x.ndim != 2 or x.shape[0] != m.shape[0]:
            raise InvalidInputError(
                f"masses must have shape (N,) and positions (N, 3) with the same N; got {m.shape} and {x.shape}"
            )
        if np.any(m <= 0):
            raise InvalidInputError(f"masses must all be > 0, got {m.tolist()}")
        if m.shape[0] < 3:
            raise InvalidInputError(
                f"a rigid body needs at least three non-collinear masses, got {m.shape[0]}"
            )
        c = (m[:, None] * x).sum(0) / m.sum()
        xr = x - c
        scale = np.max(np.abs(xr))
        sv = np.linalg.svd(xr / (scale if scale > 0 else 1.0), compute_uv=False)
        if scale == 0 or sv[1] <= 1e-12 * sv[0]:
            raise InvalidInputError(
                "the masses are collinear (or coincide): a rigid body needs at least three non-collinear masses"
            )
        g = np.einsum("n,ni,nj->ij", m, xr, xr)
        I = np.trace(g) * np.eye(3) - g
        body = cls(I, name=name)
        body.masses = m
        body.positions = xr
        body.center_of_mass = c
        return body

    # ------------------------------------------------------------------
    @property
    def batch_shape(self) -> tuple[int, ...]:
        """Shape of the batch of bodies (``()`` for one body)."""
        return self.principal_moments.shape[:-1]

    @property
    def inertia_inv(self) -> np.ndarray:
        """Inverse inertia tensor, (..., 3, 3)."""
        P = self.principal_axes
        return P @ ((1.0 / self.principal_moments)[..., :, None] * np.swapaxes(P, -1, -2))

    @property
    def mass_matrix(self) -> np.ndarray:
        r"""The paper's :math:`g = \tfrac12\mathrm{tr}(I)\mathbf 1 - I` (inverse of :math:`I = \mathrm{tr}(g)\mathbf 1 - g`, eq. 1.3)."""
        tr = np.trace(self.inertia, axis1=-2, axis2=-1)
        return 0.5 * tr[..., None, None] * np.eye(3) - self.inertia

    def _rel_close(self, a, b):
        s = np.sum(np.abs(self.principal_moments), -1)
        return np.abs(a - b) <= DEGENERACY_RTOL * s

    @property
    def is_sphere(self):
        """All three principal moments equal (within ``DEGENERACY_RTOL``)."""
        I = self.principal_moments
        return self._rel_close(I[..., 0], I[..., 1]) & self._rel_close(I[..., 1], I[..., 2])

    @property
    def is_symmetric(self):
        """At least two principal moments equal: a symmetric top (or a sphere)."""
        I = np.sort(self.principal_moments, -1)
        return self._rel_close(I[..., 0], I[..., 1]) | self._rel_close(I[..., 1], I[..., 2])

    @property
    def is_planar(self):
        """Triangle inequality is an equality, I1 + I2 = I3: a flat body."""
        I = np.sort(self.principal_moments, -1)
        return self._rel_close(I[..., 0] + I[..., 1], I[..., 2])

    @property
    def is_diagonal(self) -> bool:
        """The body frame is a principal frame (the tensor is diagonal)."""
        return bool(np.all(self.inertia - self.inertia * np.eye(3) == 0))

    @property
    def kind(self):
        """``'sphere'``, ``'prolate'`` (rod-like, unique moment smallest), ``'oblate'`` (disk-like) or ``'asymmetric'``.

        A string for one body, an array of strings for a batch.
        """
        I = np.sort(self.principal_moments, -1)
        lo = self._rel_close(I[..., 0], I[..., 1])
        hi = self._rel_close(I[..., 1], I[..., 2])
        out = np.where(lo & hi, "sphere", np.where(lo, "oblate", np.where(hi, "prolate", "asymmetric")))
        return str(out) if out.ndim == 0 else out

    # ------------------------------------------------------------------
    def angular_momentum(self, omega) -> np.ndarray:
        r"""Body angular momentum :math:`\mathbf M = I\boldsymbol\Omega` (eq. 1.24)."""
        w = as_float_array(omega, "omega", (3,))
        return np.einsum("...ij,...j->...i", self.inertia, w)

    def angular_velocity(self, M) -> np.ndarray:
        r"""Body angular velocity :math:`\boldsymbol\Omega = I^{-1}\mathbf M` (eq. 1.24)."""
        M = as_float_array(M, "M", (3,))
        return np.einsum("...ij,...j->...i", self.inertia_inv, M)

    def energy(self, omega) -> np.ndarray:
        r"""Kinetic energy :math:`E = \tfrac12\boldsymbol\Omega\cdot I\boldsymbol\Omega` (eq. 1.25)."""
        w = as_float_array(omega, "omega", (3,))
        return 0.5 * np.sum(w * self.angular_momentum(w), -1)

    def to_principal(self, v) -> np.ndarray:
        """Components of body-frame vectors (..., 3) in the principal frame: ``P^T v``."""
        v = as_float_array(v, "v", (3,))
        return np.einsum("...ji,...j->...i", self.principal_axes, v)

    def from_principal(self, v) -> np.ndarray:
        """Body-frame components of principal-frame vectors: ``P v``."""
        v = as_float_array(v, "v", (3,))
        return np.einsum("...ij,...j->...i", self.principal_axes, v)

    def __getitem__(self, idx) -> "RigidBody":
        if self.batch_shape == ():
            raise TypeError("a single RigidBody cannot be indexed")
        return RigidBody(self.inertia[idx], name=self.name)

    def __repr__(self) -> str:
        if self.batch_shape == ():
            mom = ", ".join(f"{x:.6g}" for x in self.principal_moments)
            diag = "" if self.is_diagonal else ", full tensor"
            nm = f"{self.name!r}, " if self.name else ""
            return f"RigidBody({nm}principal_moments=[{mom}]{diag}, kind={self.kind!r})"
        return f"RigidBody(batch_shape={self.batch_shape})"
