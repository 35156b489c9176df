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

from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..errors import InvalidInertiaError, InvalidInputError
from ..util.validate import as_bool, as_float_array, describe_value

__all__ = ["RigidBody", "cached_body"]

#: relative tolerance used to flag symmetric / spherical / planar bodies and
#: to accept the triangle inequality as an equality
DEGENERACY_RTOL = 1e-12

#: particles whose centred positions have a second singular value below this
#: fraction of the first are collinear
COLLINEAR_RTOL = 1e-12

#: relative tolerance of the symmetry check ``max|I - I^T| <= SYMMETRY_RTOL max|I|``
SYMMETRY_RTOL = 1e-12


#: smallest principal moment accepted: the smallest normal float64 (a subnormal moment has no
#: finite inverse, 1/5e-324 = inf)
MIN_MOMENT = float(np.finfo(float).tiny)

#: tensors whose largest entry lies outside [2**-EXP_SAFE, 2**EXP_SAFE] are scaled by a power of
#: two before the eigen-decomposition (exact; inside the range nothing is scaled, bit for bit)
EXP_SAFE = 500


def _check_not_empty(a: np.ndarray, name: str, tail: int) -> None:
    if a.size == 0:
        raise InvalidInputError(
            f"{name} is an empty batch of shape {a.shape} (batch shape {a.shape[: a.ndim - tail]}); "
            "at least one body is needed"
        )


def _quarter_sum(x: np.ndarray) -> np.ndarray:
    """``sum(x, -1) / 4`` without overflow (exact scaling by 1/4: ``(4 r) * _quarter_sum(x)`` has the
    bits of ``r * sum(x)`` whenever the latter is finite and normal)."""
    return np.sum(0.25 * x, -1)


def _safe_exponent(a: np.ndarray) -> np.ndarray:
    """Per-tensor power of two ``e`` (batch shape) that brings ``max|a|`` of a tensor (..., 3, 3) near 1
    when it lies outside ``[2**-EXP_SAFE, 2**EXP_SAFE]``; 0 (no scaling) inside."""
    e = np.frexp(np.max(np.abs(a), axis=(-1, -2)))[1]
    return np.where(np.abs(e) > EXP_SAFE, e, 0)


def check_tensor(I: np.ndarray, name: str = "inertia") -> None:
    scale = np.max(np.abs(I), axis=(-1, -2), keepdims=True)
    if np.any(scale == 0):
        raise InvalidInertiaError(f"{name} is zero; a rigid body needs a positive-definite inertia tensor")
    with np.errstate(over="ignore"):
        asym = np.max(np.abs(I - np.swapaxes(I, -1, -2)) / scale)
    if asym > SYMMETRY_RTOL:
        raise InvalidInertiaError(
            f"{name} is not symmetric: max |I - I^T| / max |I| = {asym:.3g}; an inertia tensor must be symmetric"
        )


def _raise_not_positive(ev: np.ndarray, bad_mask: np.ndarray, name: str):
    bad = ev[np.any(bad_mask, axis=-1)][0]
    # round-off noise such as -1e-17 prints as 0; huge values are printed as they are (np.round
    # multiplies by 10**15 and would overflow)
    shown = [float(np.round(x, 15)) if abs(x) < 1e200 else float(x) for x in bad]
    raise InvalidInertiaError(
        f"{name} is not positive definite: principal moments {shown}; "
        "every principal moment must be > 0 (a body needs at least three non-collinear masses)"
    )


def _raise_tiny(ev: np.ndarray, bad_mask: np.ndarray, name: str):
    bad = ev[np.any(bad_mask, axis=-1)][0]
    raise InvalidInertiaError(
        f"{name} has a principal moment below the smallest normal float64 {MIN_MOMENT:.6g}: principal "
        f"moments {bad.tolist()}; the inverse inertia 1/I would not be finite (rescale the units)"
    )


def check_moments(ev: np.ndarray, name: str = "inertia", triangle: bool = True) -> None:
    """Positive, normal (not subnormal) and (unless ``triangle=False``) triangle inequalities on
    principal moments (..., 3)."""
    if not np.all(np.isfinite(ev)):
        bad = ev[np.any(~np.isfinite(ev), axis=-1)][0]
        raise InvalidInertiaError(
            f"{name} has a principal moment that is not finite (it overflows float64): principal moments "
            f"{bad.tolist()} (rescale the units)"
        )
    if np.any(ev <= 0):
        _raise_not_positive(ev, ev <= 0, name)
    if np.any(ev < MIN_MOMENT):
        _raise_tiny(ev, ev < MIN_MOMENT, name)
    if not triangle:
        return
    s = np.sort(ev, axis=-1)
    with np.errstate(over="ignore"):  # s0 + s1 = inf only when it exceeds s2: satisfied
        slack = s[..., 0] + s[..., 1] - s[..., 2]
    tol = (4 * DEGENERACY_RTOL) * _quarter_sum(s)  # = DEGENERACY_RTOL * sum(s), without overflow
    if np.any(slack < -tol):
        bad = s[slack < -tol][0]
        raise InvalidInertiaError(
            f"{name} violates the triangle inequality I1 + I2 >= I3 of a physical body: principal moments "
            f"{bad.tolist()} have {bad[0]} + {bad[1]} < {bad[2]} (pass allow_unphysical=True to study "
            "Euler's equations with such moments anyway)"
        )


def _principal_from_moments(
    a: np.ndarray, name: str, triangle: bool = True
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    check_moments(a, name, triangle)
    ev = a.copy()
    I = ev[..., :, None] * np.eye(3)
    P = np.broadcast_to(np.eye(3), I.shape).copy()
    return I, ev, P


def _principal_from_tensor(
    a: np.ndarray, name: str, triangle: bool = True
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    check_tensor(a, name)
    # very large or very small tensors are scaled by a power of two (exact) so that neither the
    # symmetrization nor the eigen-decomposition overflows or underflows; ordinary ones are untouched
    e = _safe_exponent(a)
    scaled = bool(np.any(e != 0))
    if scaled:
        a = np.ldexp(a, -e[..., None, None])
    I = 0.5 * (a + np.swapaxes(a, -1, -2))
    ev, P = np.linalg.eigh(I)
    # right-handed principal frame
    P[..., :, 2] *= np.sign(np.linalg.det(P))[..., None]
    # diagonal tensors keep their frame and the order of their moments
    diag = np.all(I - I * np.eye(3) == 0, axis=(-1, -2))
    ev = np.where(diag[..., None], np.diagonal(I, axis1=-2, axis2=-1), ev)
    P = np.where(diag[..., None, None], np.eye(3), P)
    if scaled:
        if np.any(ev <= 0):
            _raise_not_positive(np.ldexp(ev, e[..., None]), ev <= 0, name)
        ev_s = ev
        with np.errstate(under="ignore"):
            ev = np.ldexp(ev_s, e[..., None])
            I = np.ldexp(I, e[..., None, None])
        if np.any(ev < MIN_MOMENT):
            _raise_tiny(ev, ev < MIN_MOMENT, name)
    check_moments(ev, name, triangle)
    return I, ev, P


class RigidBody:
    r"""A rigid body given by its inertia tensor in the body frame.

    Parameters
    ----------
    inertia : array_like, shape (..., 3) or (..., 3, 3)
        Three principal moments :math:`(I_1, I_2, I_3)` (the body frame is then
        the principal frame) or a full symmetric positive-definite tensor.
        Leading axes make a batch of bodies. An array whose last two axes
        are (3, 3) is always read as tensors, never as a batch of moments
        whose batch shape ends in 3: use :meth:`from_moments` for those.
    name : str, optional, keyword-only
        A label used in plots and files.
    allow_unphysical : bool, keyword-only
        Accept positive moments that violate the triangle inequality (no mass
        distribution has them, but Euler's equations are well defined; e.g.
        the often-quoted "tennis racket" moments (3, 5, 9)). Default False.

    Attributes
    ----------
    inertia : ndarray, shape (..., 3, 3)
        Inertia tensor in the body frame.
    principal_moments : ndarray, shape (..., 3)
        Eigenvalues of ``inertia``; in the given order for diagonal input,
        ascending otherwise.
    principal_axes : ndarray, shape (..., 3, 3)
        Right-handed orthonormal columns (``det P = +1``):
        ``inertia = P diag(moments) P^T``.
    masses, positions, center_of_mass : ndarray or None
        Set by :meth:`from_particles`: the masses (N,), the positions
        relative to the centre of mass (N, 3), and the centre of mass (3,).
    name : str or None

    Raises
    ------
    InvalidInertiaError
        Not symmetric, not positive definite, a principal moment below
        the smallest normal float64 (:data:`MIN_MOMENT`, whose inverse
        would not be finite), or violating the triangle inequality
        (:math:`I_1 + I_2 < I_3` is not a physical body).
    InvalidInputError
        Wrong shape, an empty batch, NaN or infinite entries.
    TypeError
        ``allow_unphysical`` not a bool (``bool`` or ``numpy.bool_``).

    Notes
    -----
    Degenerate but physical bodies are accepted and flagged:
    :attr:`is_symmetric` (two equal moments: a symmetric top, ``kind``
    ``"prolate"`` or ``"oblate"``), :attr:`is_sphere` (three equal),
    :attr:`is_planar` (:math:`I_1 + I_2 = I_3`: all mass in a plane).

    See Also
    --------
    RigidBody.from_moments : unambiguous construction from principal moments.
    RigidBody.from_particles : a body of point masses (paper eq. 1.1).
    RigidBody.in_principal_frame : the same body with a diagonal tensor.

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

    def __init__(self, inertia: ArrayLike, *, name: str | None = None, allow_unphysical: bool = False) -> None:
        a = as_float_array(inertia, "inertia")
        triangle = not as_bool(allow_unphysical, "allow_unphysical")
        if a.ndim >= 2 and a.shape[-2:] == (3, 3):
            _check_not_empty(a, "inertia", 2)
            I, ev, P = _principal_from_tensor(a, "inertia", triangle)
        elif a.ndim >= 1 and a.shape[-1] == 3:
            _check_not_empty(a, "inertia", 1)
            I, ev, P = _principal_from_moments(a, "inertia", triangle)
        else:
            raise InvalidInputError(
                f"inertia must be three principal moments, shape (..., 3), or a 3x3 tensor, "
                f"shape (..., 3, 3); got shape {a.shape}"
            )
        self._set(I, ev, P, name)

    def _set(self, I: NDArray[np.float64], ev: NDArray[np.float64], P: NDArray[np.float64], name: str | None) -> None:
        self.inertia = I
        self.principal_moments = ev
        self.principal_axes = P
        self.name = name
        self.masses: np.ndarray | None = None
        self.positions: np.ndarray | None = None
        self.center_of_mass: np.ndarray | None = None

    @classmethod
    def from_moments(cls, moments: ArrayLike, *, name: str | None = None, allow_unphysical: bool = False) -> RigidBody:
        """A body (or batch) given by principal moments only, shape (..., 3).

        Unambiguous where ``RigidBody(moments)`` is not: a batch of moments of
        shape ``(..., 3, 3)`` (batch shape ending in 3) would be read as
        tensors by the constructor.

        Parameters
        ----------
        moments : array_like, shape (..., 3)
            Principal moments; the body frame is the principal frame.
        name : str, optional, keyword-only

        Returns
        -------
        RigidBody

        Raises
        ------
        InvalidInertiaError
            A moment <= 0 or below :data:`MIN_MOMENT`, or a violated
            triangle inequality.
        InvalidInputError
            Wrong shape, an empty batch, NaN or infinite entries.
        TypeError
            ``allow_unphysical`` not a bool.
        """
        a = as_float_array(moments, "moments", (3,))
        triangle = not as_bool(allow_unphysical, "allow_unphysical")
        _check_not_empty(a, "moments", 1)
        body = cls.__new__(cls)
        body._set(*_principal_from_moments(a, "moments", triangle), name)
        return body

    # ------------------------------------------------------------------
    @classmethod
    def from_particles(cls, masses: ArrayLike, positions: ArrayLike, *, name: str | None = None) -> RigidBody:
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
            Shapes that do not match, non-positive or non-finite masses,
            fewer than three non-collinear masses (the inertia tensor would be
            singular), or masses and positions whose inertia tensor overflows
            or underflows float64 (masses and positions are scaled by powers of
            two internally, so only an inertia that is itself out of range is
            refused).
        """
        m = as_float_array(masses, "masses")
        x = as_float_array(positions, "positions", (3,))
        if m.ndim != 1 or x.ndim != 2 or x.shape[0] != m.shape[0]:
            raise InvalidInputError(
                f"masses must have shape (N,) and positions (N, 3) with the same N; got {m.shape} and {x.shape}"
            )
        if m.shape[0] < 3:
            raise InvalidInputError(f"a rigid body needs at least three non-collinear masses, got {m.shape[0]}")
        if np.any(m <= 0):
            raise InvalidInputError(f"masses must all be > 0, got {describe_value(m)}")
        # The inertia is homogeneous, I(s x, mu m) = mu s^2 I(x, m): masses and positions are scaled
        # by powers of two (exact, so ordinary inputs give the same bits as without scaling) to keep
        # sum(m x x) from overflowing or underflowing; only the final rescaling can leave the range.
        em = int(np.frexp(np.max(m))[1])
        ex = int(np.frexp(np.max(np.abs(x)))[1])
        ms = np.ldexp(m, -em)
        xs = np.ldexp(x, -ex)
        cs = (ms[:, None] * xs).sum(0) / ms.sum()
        xrs = xs - cs
        scale = np.max(np.abs(xrs))
        sv = np.linalg.svd(xrs / (scale if scale > 0 else 1.0), compute_uv=False)
        if scale == 0 or sv[1] <= COLLINEAR_RTOL * sv[0]:
            raise InvalidInputError(
                f"the {m.shape[0]} masses are collinear (or coincide): a rigid body needs at least three "
                "non-collinear masses (its inertia tensor would be singular)"
            )
        gs = np.einsum("n,ni,nj->ij", ms, xrs, xrs)
        Is = np.trace(gs) * np.eye(3) - gs
        c = np.ldexp(cs, ex)
        with np.errstate(over="ignore", under="ignore"):
            xr = np.ldexp(xrs, ex)
            I = np.ldexp(Is, em + 2 * ex)
            ev_s = np.linalg.eigvalsh(Is)
            ev = np.ldexp(ev_s, em + 2 * ex)
        sizes = (
            f"masses up to {np.max(m):.6g} and positions relative to the centre of mass up to "
            f"{np.ldexp(scale, ex):.6g} in absolute value"
        )
        if not (np.all(np.isfinite(I)) and np.all(np.isfinite(ev)) and np.all(np.isfinite(xr))):
            raise InvalidInputError(
                f"the inertia tensor of these particles overflows float64 ({sizes}): "
                "rescale the units of masses or positions"
            )
        if np.min(ev_s) > 0 and np.min(ev) < MIN_MOMENT:
            raise InvalidInputError(
                f"the inertia tensor of these particles underflows float64 (smallest principal moment "
                f"about {np.min(ev_s):.6g} * 2**{em + 2 * ex}, below {MIN_MOMENT:.6g}; {sizes}): "
                "rescale the units of masses or positions"
            )
        body = cls(I, name=name)
        body.masses = m
        body.positions = xr
        body.center_of_mass = c
        return body

    def in_principal_frame(self) -> RigidBody:
        r"""The same body described in its principal frame.

        Returns a body whose inertia tensor is ``diag(principal_moments)``;
        for a body made of particles the positions are rotated into the
        principal frame, :math:`\mathbf x' = P^T\mathbf x`, and the centre
        of mass is kept.

        Returns
        -------
        RigidBody
            Diagonal, same batch shape.
        """
        body = RigidBody.from_moments(self.principal_moments, name=self.name)
        if self.positions is not None:
            body.masses = self.masses
            body.positions = self.positions @ self.principal_axes
            body.center_of_mass = self.center_of_mass
        return body

    # ------------------------------------------------------------------
    @property
    def batch_shape(self) -> tuple[int, ...]:
        """Shape of the batch of bodies (``()`` for one body)."""
        return self.principal_moments.shape[:-1]

    @property
    def inertia_inv(self) -> NDArray[np.float64]:
        r"""Inverse inertia tensor :math:`I^{-1} = P\,\mathrm{diag}(1/I_k)P^T`, shape (..., 3, 3)."""
        P = self.principal_axes
        return P @ ((1.0 / self.principal_moments)[..., :, None] * np.swapaxes(P, -1, -2))

    @property
    def mass_matrix(self) -> NDArray[np.float64]:
        r"""The paper's mass matrix :math:`g_{ij} = \sum_N m_N x^i_N x^j_N`, shape (..., 3, 3).

        Obtained from the inertia tensor by inverting :math:`I = \mathrm{tr}(g)\mathbf 1 - g`:
        :math:`g = \tfrac12\mathrm{tr}(I)\mathbf 1 - I` (eq. 1.3 uses :math:`g`). Positive
        semi-definite exactly when the triangle inequalities hold; singular for a planar body.
        """
        I = self.inertia
        # tensors near the float64 limits are scaled by a power of two (exact; g itself is in range)
        e = _safe_exponent(I)
        if np.any(e != 0):
            I = np.ldexp(I, -e[..., None, None])
        tr = np.trace(I, axis1=-2, axis2=-1)
        g = 0.5 * tr[..., None, None] * np.eye(3) - I
        return np.ldexp(g, e[..., None, None]) if np.any(e != 0) else g

    def _rel_close(self, a, b):
        # DEGENERACY_RTOL * sum|I_k|, without overflow for moments near the float64 maximum
        s = _quarter_sum(np.abs(self.principal_moments))
        with np.errstate(over="ignore", invalid="ignore"):
            return np.abs(a - b) <= (4 * DEGENERACY_RTOL) * s

    @staticmethod
    def _flag(x):
        x = np.asarray(x)
        return bool(x) if x.ndim == 0 else x

    @property
    def is_sphere(self) -> bool | NDArray[np.bool_]:
        """All three principal moments equal (within ``DEGENERACY_RTOL``).

        A bool for one body, a boolean array of the batch shape otherwise.
        """
        I = self.principal_moments
        return self._flag(self._rel_close(I[..., 0], I[..., 1]) & self._rel_close(I[..., 1], I[..., 2]))

    @property
    def is_symmetric(self) -> bool | NDArray[np.bool_]:
        """At least two principal moments equal: a symmetric top (or a sphere).

        A bool for one body, a boolean array of the batch shape otherwise.
        """
        I = np.sort(self.principal_moments, -1)
        return self._flag(self._rel_close(I[..., 0], I[..., 1]) | self._rel_close(I[..., 1], I[..., 2]))

    @property
    def is_planar(self) -> bool | NDArray[np.bool_]:
        """The triangle inequality is an equality, ``I1 + I2 = I3``: all mass in one plane.

        A bool for one body, a boolean array of the batch shape otherwise.
        """
        I = np.sort(self.principal_moments, -1)
        with np.errstate(over="ignore"):  # I1 + I2 = inf > I3: not planar
            s = I[..., 0] + I[..., 1]
        return self._flag(self._rel_close(s, I[..., 2]))

    @property
    def is_diagonal(self) -> bool:
        """The body frame is a principal frame (every tensor of the batch is diagonal)."""
        I = self.inertia
        if I.ndim == 2:  # one body: its six off-diagonal entries (the diagonal ones are finite)
            (a, b, c), (d, e, f), (g, h, i) = I.tolist()
            return b == 0 and c == 0 and d == 0 and f == 0 and g == 0 and h == 0
        return bool(np.all(I - I * np.eye(3) == 0))

    @property
    def kind(self) -> str | NDArray[np.str_]:
        """``'sphere'``, ``'prolate'`` (rod-like: the unique moment is the smallest),
        ``'oblate'`` (disk-like: the unique moment is the largest) or ``'asymmetric'``.

        A string for one body, an array of strings for a batch.
        """
        I = np.sort(self.principal_moments, -1)
        lo = self._rel_close(I[..., 0], I[..., 1])
        hi = self._rel_close(I[..., 1], I[..., 2])
        out = np.where(lo & hi, "sphere", np.where(lo, "oblate", np.where(hi, "prolate", "asymmetric")))
        return str(out) if out.ndim == 0 else out

    # ------------------------------------------------------------------
    def angular_momentum(self, omega: ArrayLike) -> NDArray[np.float64]:
        r"""Body angular momentum :math:`\mathbf M = I\boldsymbol\Omega` (eq. 1.24).

        Parameters
        ----------
        omega : array_like, shape (..., 3)
            Body angular velocity; broadcast against the batch shape.

        Returns
        -------
        ndarray, shape (..., 3)

        Raises
        ------
        InvalidInputError
            Wrong shape or non-finite values.
        """
        w = as_float_array(omega, "omega", (3,))
        return np.einsum("...ij,...j->...i", self.inertia, w)

    def angular_velocity(self, M: ArrayLike) -> NDArray[np.float64]:
        r"""Body angular velocity :math:`\boldsymbol\Omega = I^{-1}\mathbf M` (eq. 1.24).

        Parameters
        ----------
        M : array_like, shape (..., 3)
            Body angular momentum; broadcast against the batch shape.

        Returns
        -------
        ndarray, shape (..., 3)

        Raises
        ------
        InvalidInputError
            Wrong shape or non-finite values.
        """
        M = as_float_array(M, "M", (3,))
        return np.einsum("...ij,...j->...i", self.inertia_inv, M)

    def energy(self, omega: ArrayLike) -> NDArray[np.float64]:
        r"""Kinetic energy :math:`E = \tfrac12\boldsymbol\Omega\cdot I\boldsymbol\Omega` (eq. 1.25).

        Parameters
        ----------
        omega : array_like, shape (..., 3)
            Body angular velocity; broadcast against the batch shape.

        Returns
        -------
        ndarray, shape (...)

        Raises
        ------
        InvalidInputError
            Wrong shape or non-finite values.
        """
        w = as_float_array(omega, "omega", (3,))
        with np.errstate(over="ignore", invalid="ignore"):
            E = 0.5 * np.sum(w * self.angular_momentum(w), -1)
        if not np.all(np.isfinite(E)):
            raise InvalidInputError(
                f"energy overflows float64 (max |omega| = {float(np.max(np.abs(w))):.3g}); rescale omega"
            )
        return E

    def to_principal(self, v: ArrayLike) -> NDArray[np.float64]:
        """Components of body-frame vectors in the principal frame: ``P^T v``.

        Parameters
        ----------
        v : array_like, shape (..., 3)

        Returns
        -------
        ndarray, shape (..., 3)

        Raises
        ------
        InvalidInputError
            Wrong shape or non-finite values.
        """
        v = as_float_array(v, "v", (3,))
        return np.einsum("...ji,...j->...i", self.principal_axes, v)

    def from_principal(self, v: ArrayLike) -> NDArray[np.float64]:
        """Body-frame components of principal-frame vectors: ``P v``.

        Parameters
        ----------
        v : array_like, shape (..., 3)

        Returns
        -------
        ndarray, shape (..., 3)

        Raises
        ------
        InvalidInputError
            Wrong shape or non-finite values.
        """
        v = as_float_array(v, "v", (3,))
        return np.einsum("...ij,...j->...i", self.principal_axes, v)

    def __getitem__(self, idx: Any) -> RigidBody:
        """Bodies of the batch (indexes the batch axes only, never the tensor axes)."""
        if self.batch_shape == ():
            raise TypeError("a single RigidBody cannot be indexed")
        shape = self.batch_shape
        pos = np.arange(int(np.prod(shape))).reshape(shape)[idx]
        body = RigidBody.__new__(RigidBody)
        body._set(
            self.inertia.reshape(-1, 3, 3)[pos],
            self.principal_moments.reshape(-1, 3)[pos],
            self.principal_axes.reshape(-1, 3, 3)[pos],
            self.name,
        )
        return body

    def __repr__(self) -> str:
        if self.batch_shape == ():
            mom = ", ".join(f"{x:.6g}" for x in self.principal_moments)
            diag = "" if self.is_diagonal else ", full tensor"
            nm = f"{self.name!r}, " if self.name else ""
            return f"RigidBody({nm}principal_moments=[{mom}]{diag}, kind={self.kind!r})"
        return f"RigidBody(batch_shape={self.batch_shape})"

    def _repr_html_(self) -> str:
        """A compact HTML table for notebooks (a batch summarized): :func:`eulerpoisson.util.htmlrepr.body_html`."""
        from ..util.htmlrepr import body_html

        return body_html(self)


#: the checked arrays (inertia, principal moments, principal axes) of the bodies made by :func:`cached_body`
_BODY_CACHE: dict[tuple[float, float, float], tuple[np.ndarray, np.ndarray, np.ndarray]] = {}
_BODY_CACHE_MAX = 256


def cached_body(moments: tuple[float, float, float]) -> RigidBody:
    """``RigidBody(list(moments))``, checked once per distinct moments (for many small calls with the same body).

    Each call returns a new body with arrays of its own (a body's arrays may be changed by whoever holds it);
    only the checks and the principal data are computed once.

    Parameters
    ----------
    moments : tuple of three floats
        Principal moments.

    Raises
    ------
    InvalidInertiaError, InvalidInputError
        As :class:`RigidBody` (nothing is cached then).

    Examples
    --------
    >>> from eulerpoisson.model.body import cached_body
    >>> a, b = cached_body((1.0, 2.0, 3.0)), cached_body((1.0, 2.0, 3.0))
    >>> a is b, a.inertia is b.inertia, (a.inertia == b.inertia).all()
    (False, False, np.True_)
    """
    data = _BODY_CACHE.get(moments)
    if data is None:
        body = RigidBody(list(moments))
        if len(_BODY_CACHE) >= _BODY_CACHE_MAX:
            _BODY_CACHE.clear()
        _BODY_CACHE[moments] = (body.inertia.copy(), body.principal_moments.copy(), body.principal_axes.copy())
        return body
    body = RigidBody.__new__(RigidBody)
    body._set(data[0].copy(), data[1].copy(), data[2].copy(), None)
    return body
