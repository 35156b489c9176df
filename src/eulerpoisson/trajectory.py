r"""The result of :func:`~eulerpoisson.solve`: a :class:`Trajectory`.

A trajectory holds the output times, the attitude (unit quaternions with a
continuous sign) and the body angular velocity of one body or a batch of
bodies; everything else — rotation matrices, Gibbs vectors, body and spatial
angular momenta, energy, the drift of the integrals, the motion of the
particles of a point-mass body (paper eq. 1.2) — is derived from them.
Trajectories are written to and read from NetCDF with CF-style attributes.
"""

from __future__ import annotations

import math
import os
from collections.abc import Mapping
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .attitude.core import matrix_from_unit_quaternion, quaternion_make_continuous
from .errors import InvalidInputError
from .model.body import RigidBody
from .model.equations import Model
from .util.validate import as_float_array

if TYPE_CHECKING:
    import xarray
    from matplotlib.figure import Figure

    from .io.read import LazyTrajectory
    from .model.torques import TorqueLike

__all__ = ["Trajectory", "FORMAT_VERSION"]

#: version of the NetCDF layout written by :meth:`Trajectory.to_netcdf`
FORMAT_VERSION = 1

CONVENTIONS = (
    "x_space = R x_body; dR/dt = R [Omega]x with Omega the body angular velocity; "
    "quaternion scalar first (w, x, y, z), Hamilton product; Gibbs vector n = (x, y, z)/w = k tan(alpha/2); "
    "M = I Omega (body frame), m = R I Omega (space frame), E = Omega.I Omega/2. "
    "Units are those of the inputs (any consistent system; SI names are given for orientation)."
)


#: a quaternion whose norm is within this of 1 is stored as it is (4 ulp of 1)
_UNIT_SLACK = 4 * float(np.finfo(float).eps)
#: at most this many samples are checked in plain floats
_FEW = 8
_FLOAT64 = np.dtype(np.float64)


def _unit_continuous(t: np.ndarray, q: np.ndarray, continuous: bool = True) -> np.ndarray:
    """Quaternions (..., T, 4) as a trajectory stores them: normalized, with signs continuous in time.

    Body by body along the time axis (``t``, any order): any split of a batch gives the same bits.

    Raises
    ------
    InvalidInputError
        A zero quaternion.
    """
    # a fixed summation order (an einsum or a reduction may sum in an order that depends on the
    # memory layout, and then two equal arrays could be normalized differently)
    if q.ndim == 2 and q.shape[0] <= _FEW and (not continuous or q.shape[0] < 2):
        # a few samples that need no sign change: the same test in plain floats (the same operations)
        for w, x, y, z in q.tolist():
            n = math.sqrt(w * w + x * x + y * y + z * z)
            if n == 0 or abs(n - 1.0) > _UNIT_SLACK:
                break  # (normalized, or refused, below)
        else:
            return q
    w, x, y, z = q[..., 0], q[..., 1], q[..., 2], q[..., 3]
    nrm = np.sqrt(w * w + x * x + y * y + z * z)[..., None]
    if (nrm == 0).any():
        raise InvalidInputError("quaternion contains a zero quaternion, which is not a rotation")
    # normalize, but leave already-unit quaternions bit for bit (files round-trip exactly)
    off = np.abs(nrm - 1.0) > _UNIT_SLACK
    if off.any():
        q = np.where(off, q / nrm, q)
    if not continuous:
        return q
    if t.size < 2:
        return q  # one sample (or none): its sign is kept
    if np.all(t[1:] >= t[:-1]):  # the usual case: no reordering needed
        return quaternion_make_continuous(q, axis=-2) if q.ndim > 1 else q
    order = np.argsort(t, kind="stable")
    qs = quaternion_make_continuous(np.take(q, order, axis=-2), axis=-2)
    inv = np.empty_like(order)
    inv[order] = np.arange(order.size)
    return np.take(qs, inv, axis=-2)


def stored_attitudes(t: np.ndarray, quaternion, omega) -> np.ndarray:
    """What :class:`Trajectory` does to a solver's output, for part of a batch (the solve driver runs it in the
    thread that solved the part): ``quaternion`` and ``omega`` checked (finite, shapes), the quaternions
    returned as the trajectory stores them (:func:`_unit_continuous`).

    Raises
    ------
    InvalidInputError
        As :class:`Trajectory` (the driver then builds the trajectory of the whole batch again, so that the
        message is about the whole batch).
    """
    if (
        type(quaternion) is np.ndarray
        and type(omega) is np.ndarray
        and quaternion.ndim == 2
        and quaternion.shape[0] <= _FEW
        and quaternion.dtype == _FLOAT64
        and omega.dtype == _FLOAT64
        and quaternion.shape[1:] == (4,)
        and omega.shape[-1:] == (3,)
        and math.isfinite(sum(quaternion.ravel().tolist()) + sum(omega.ravel().tolist()))
    ):
        # a few samples whose values are all finite (an infinite or NaN one makes the sum so): the checks in
        # plain floats (the sum, not each value, to spare Python calls)
        return _unit_continuous(t, quaternion)
    q = as_float_array(quaternion, "quaternion", (4,))
    as_float_array(omega, "omega", (3,))
    return _unit_continuous(t, q)


class Trajectory:
    r"""Motion of one body or a batch of bodies at a set of output times.

    Parameters
    ----------
    t : array_like, shape (T,)
        Output times, a 1-D array (``T = 0`` is allowed: an empty
        trajectory, whose :meth:`drift` raises).
    quaternion : array_like, shape ``(*batch, T, 4)``
        Attitudes (made unit and sign-continuous in time here).
    omega : array_like, shape ``(*batch, T, 3)``
        Body angular velocities.
    body : RigidBody
        One body, or a batch whose shape broadcasts to ``batch``.
    torque : Torque, list of Torque, or None
        The torques of the motion (:mod:`eulerpoisson.torques`); None for the
        free body. They define :attr:`energy` (with the potential),
        :meth:`integrals` and :meth:`drift`. Keyword only.
    method : str
        Name of the method that produced it.
    options : dict, optional
        The method's options.
    stats : dict, optional
        Counters (wall time, steps, ...).
    keep_signs : bool, default False
        Keep the sign of every quaternion as given (normalized only): for
        samples selected from a trajectory whose signs were made continuous
        over all its samples (indexing does this), where continuity over the
        selection alone could flip some. Keyword only.

    Raises
    ------
    InvalidInputError
        ``t`` not 1-D, inconsistent shapes, NaN or infinite values, a zero
        quaternion, or a body batch that does not broadcast to the batch of
        the states.
    TypeError
        ``body`` not a :class:`RigidBody`, ``method`` not a string,
        ``options``/``stats`` not mappings.

    Attributes
    ----------
    t, quaternion, omega, body, model, method, options, stats

    Notes
    -----
    Derived quantities are properties computed on access: :attr:`matrix`,
    :attr:`gibbs` (NaN where the rotation angle is :math:`\pi`, flagged by
    :attr:`gibbs_singular`), :attr:`M`, :attr:`m`, :attr:`energy`.

    Examples
    --------
    >>> import numpy as np, eulerpoisson as ep
    >>> tr = ep.solve([1.0, 2.0, 2.5], np.linspace(0.0, 10.0, 101), omega0=[1.0, 0.1, 0.5])
    >>> tr
    Trajectory(method='exact', T=101, t=[0, 10])
    >>> tr.quaternion.shape, tr.omega.shape, tr.matrix.shape
    ((101, 4), (101, 3), (101, 3, 3))
    >>> print(np.round(tr.omega[-1], 6))
    [ 0.856743 -0.639521  0.192891]
    >>> {k: bool(v < 1e-12) for k, v in tr.drift().items()}          # the integrals are conserved
    {'energy': True, 'm_norm': True, 'm_x': True, 'm_y': True, 'm_z': True}
    >>> print(tr[::50].t)                                            # index the samples
    [ 0.  5. 10.]
    """

    def __init__(
        self,
        t: ArrayLike,
        quaternion: ArrayLike,
        omega: ArrayLike,
        body: RigidBody,
        method: str = "",
        options: dict[str, Any] | None = None,
        stats: dict[str, Any] | None = None,
        *,
        torque: TorqueLike = None,
        keep_signs: bool = False,
        _prepared: bool = False,
    ) -> None:
        # _prepared (private, for the solve driver): ``quaternion`` and ``omega`` are float64 arrays already
        # checked and stored by :func:`stored_attitudes` (chunk by chunk, in the threads that solved them)
        self.t = as_float_array(t, "t")
        if self.t.ndim != 1:
            raise InvalidInputError(f"t must be a 1-D array of output times, shape (T,); got shape {self.t.shape}")
        if not isinstance(body, RigidBody):
            raise TypeError(f"body must be a RigidBody, got {type(body).__name__} {body!r}")
        if not isinstance(method, str):
            raise TypeError(f"method must be a string, got {type(method).__name__} {method!r}")
        for nm, val in (("options", options), ("stats", stats)):
            if val is not None and type(val) is not dict and not isinstance(val, Mapping):
                raise TypeError(f"{nm} must be a dict (or None), got {type(val).__name__} {val!r}")
        if _prepared:
            q = np.asarray(quaternion, dtype=np.float64)
            self.omega = np.asarray(omega, dtype=np.float64)
        else:
            q = as_float_array(quaternion, "quaternion", (4,))
            self.omega = as_float_array(omega, "omega", (3,))
        if q.shape[-2:-1] != self.t.shape or self.omega.shape[:-1] != q.shape[:-1]:
            raise InvalidInputError(
                f"inconsistent trajectory shapes: t {self.t.shape}, quaternion {q.shape}, omega {self.omega.shape}"
            )
        bshape = q.shape[:-2]
        try:
            ok = body.batch_shape == () or np.broadcast_shapes(body.batch_shape, bshape) == bshape
        except ValueError:
            ok = False
        if not ok:
            raise InvalidInputError(
                f"the body's batch shape {body.batch_shape} does not broadcast to the trajectory's batch "
                f"shape {bshape} (quaternion {q.shape}, omega {self.omega.shape})"
            )
        if _prepared:
            self.quaternion = q
        elif keep_signs:
            self.quaternion = _unit_continuous(self.t, q, continuous=False)  # normalized only
        else:
            self.quaternion = _unit_continuous(self.t, q)
        self.body = body
        self.model = Model(body, torque)
        if self.model.batch_shape != () and np.broadcast_shapes(self.model.batch_shape, bshape) != bshape:
            raise InvalidInputError(
                f"the torque parameters' batch shape {self.model.batch_shape} does not broadcast to the "
                f"trajectory's batch shape {bshape}"
            )
        self.method = method
        self.options = dict(options or {})
        self.stats = dict(stats or {})

    @classmethod
    def _assembled(
        cls,
        t: np.ndarray,
        quaternion: np.ndarray,
        omega: np.ndarray,
        model: Model,
        method: str,
        options: dict[str, Any],
        stats: dict[str, Any],
    ) -> Trajectory:
        """The trajectory that ``Trajectory(t, quaternion, omega, model.body, method, options, stats,
        torque=model.torques, _prepared=True)`` makes, without its checks (for the solve driver's quick lane,
        which has made every part as that call would: ``t`` a float64 array (T,), ``quaternion`` and ``omega``
        returned by :func:`stored_attitudes` and checked by it, ``model`` of one free body, ``stats`` a dict of
        its own: the trajectory keeps it)."""
        self = cls.__new__(cls)
        self.t = t
        self.omega = omega
        self.quaternion = quaternion
        self.body = model.body
        self.model = model
        self.method = method
        self.options = dict(options)
        self.stats = stats  # (made for this trajectory by the caller)
        return self

    # ------------------------------------------------------------------
    @property
    def batch_shape(self) -> tuple[int, ...]:
        """Shape of the batch of bodies (``()`` for one body)."""
        return self.quaternion.shape[:-2]

    def __len__(self) -> int:
        return self.t.shape[0]

    @property
    def _inertia(self) -> np.ndarray:
        return self.body.inertia[..., None, :, :]

    @property
    def matrix(self) -> NDArray[np.float64]:
        """Rotation matrices R(t), ``(*batch, T, 3, 3)``."""
        return matrix_from_unit_quaternion(self.quaternion)

    @property
    def gibbs_singular(self) -> NDArray[np.bool_]:
        r"""Boolean mask ``(*batch, T)``: rotation angle exactly :math:`\pi`, where the global Gibbs vector is infinite."""
        return self.quaternion[..., 0] == 0

    @property
    def gibbs(self) -> NDArray[np.float64]:
        """Global Gibbs vectors n(t) = (x, y, z)/w, ``(*batch, T, 3)``; NaN where :attr:`gibbs_singular`."""
        w = self.quaternion[..., :1]
        with np.errstate(divide="ignore", invalid="ignore"):
            n = self.quaternion[..., 1:] / w
        return np.where(w == 0, np.nan, n)

    @property
    def M(self) -> NDArray[np.float64]:
        r"""Body angular momentum :math:`\mathbf M = I\boldsymbol\Omega`, ``(*batch, T, 3)``."""
        return np.einsum("...ij,...j->...i", self._inertia, self.omega)

    @property
    def m(self) -> NDArray[np.float64]:
        r"""Spatial angular momentum :math:`\mathbf m = RI\boldsymbol\Omega`, ``(*batch, T, 3)``; constant for the free body."""
        return np.einsum("...ij,...j->...i", self.matrix, self.M)

    @property
    def kinetic_energy(self) -> NDArray[np.float64]:
        r"""Kinetic energy :math:`\tfrac12\boldsymbol\Omega\cdot I\boldsymbol\Omega`, ``(*batch, T)``."""
        return 0.5 * np.sum(self.omega * self.M, -1)

    @property
    def potential_energy(self) -> NDArray[np.float64]:
        r"""Potential energy :math:`U(t, R)` of the conservative torques, ``(*batch, T)``; 0 for the free body."""
        if self.model.is_free:
            return np.zeros(self.omega.shape[:-1])
        T = self.t.shape[0]
        Rt = np.moveaxis(self.matrix, -3, 0)  # time first: the torques' parameters broadcast over the batch
        tt = self.t.reshape((T,) + (1,) * len(self.batch_shape))
        U = np.zeros((T,) + self.batch_shape)
        for tq in self.model.torques:
            if tq.conservative:
                U = U + tq.potential(tt, Rt, self.body.inertia)
        return np.moveaxis(U, 0, -1)

    @property
    def energy(self) -> NDArray[np.float64]:
        r"""Energy :math:`E = \tfrac12\boldsymbol\Omega\cdot I\boldsymbol\Omega + U`, ``(*batch, T)``.

        The kinetic energy plus the potential of the conservative torques
        (:attr:`kinetic_energy`, :attr:`potential_energy`); the kinetic energy
        alone for the free body.
        """
        if self.model.is_free:
            return self.kinetic_energy
        return self.kinetic_energy + self.potential_energy

    def integrals(self) -> dict[str, NDArray[np.float64]]:
        """The conserved quantities of the trajectory's model at every output time, each ``(*batch, T)``.

        See :meth:`eulerpoisson.Model.integrals` for which ones (energy and
        spatial angular momentum for the free body; energy, vertical angular
        momentum, and the Lagrange, Kovalevskaya or Goryachev–Chaplygin
        integral for heavy tops; the Jacobi integral for the gravity gradient).
        """
        return self.model.integrals(self.t, self.quaternion, self.omega)

    def drift(self) -> dict[str, NDArray[np.float64]]:
        r"""Relative drift of every integral of motion of the model over the trajectory.

        Relative to the value at the first output time ``t[0]`` (the
        initial state when ``t[0] = 0``). Free body: for the energy
        :math:`\max_t|E(t)-E_0|/|E_0|`, for :math:`|\mathbf m|` the same, and
        for each component :math:`\max_t|m_i(t)-m_i(t_0)|/|\mathbf m(t_0)|`.
        Under torque: each integral of :meth:`integrals`, the energy-like
        ones (``energy``, ``jacobi``) relative to the sum of the magnitudes
        of their terms at ``t[0]`` (kinetic plus :math:`|U|`, so a zero total
        energy does not divide by zero), the angular momenta relative to
        :math:`|\mathbf m(t_0)|`, the others to their own magnitude. Zero
        scales (a body at rest) give absolute values.

        Returns
        -------
        dict
            One entry per integral (free body: ``"energy"``, ``"m_norm"``,
            ``"m_x"``, ``"m_y"``, ``"m_z"``), each an array of the batch shape
            (a float for one body). Empty for a model with no known integral.

        Raises
        ------
        InvalidInputError
            For an empty trajectory (no output times, ``T = 0``): the drift is
            measured from the values at ``t[0]``, which it does not have. (An
            empty result would be read as "no drift"; the error is explicit.)
        """
        if self.t.size == 0:
            raise InvalidInputError(
                "drift() is measured from the integrals at the first output time t[0], and this trajectory "
                "has no output times (T = 0)"
            )

        from .model.drift import DriftAccumulator

        acc = DriftAccumulator(self.model)  # the same computation as for long runs seen in pieces
        acc.update(self.t, self.quaternion, self.omega)
        return acc.result()

    def particles(
        self, center0: ArrayLike = (0.0, 0.0, 0.0), velocity0: ArrayLike = (0.0, 0.0, 0.0)
    ) -> NDArray[np.float64]:
        r"""Positions of the body's point masses, :math:`\mathbf y_N(t) = \mathbf C_0 + \mathbf V_0 t + R(t)\mathbf x_N(0)` (paper eq. 1.2).

        Parameters
        ----------
        center0 : array_like, shape (3,)
            Centre of mass at t = 0 (defaults to the body's own centre of mass
            if it was built with :meth:`RigidBody.from_particles` and
            ``center0`` is not given).
        velocity0 : array_like, shape (3,)
            Velocity of the centre of mass.

        Returns
        -------
        ndarray, shape ``(*batch, T, N, 3)``

        Raises
        ------
        InvalidInputError
            If the body was not built from particles.
        """
        if self.body.positions is None:
            raise InvalidInputError(
                "this trajectory's body has no particles; build it with RigidBody.from_particles(masses, positions)"
            )
        C0 = as_float_array(center0, "center0", (3,))
        V0 = as_float_array(velocity0, "velocity0", (3,))
        x0 = self.body.positions  # relative to the centre of mass, body frame = space frame at q = 1
        y = np.einsum("...tij,nj->...tni", self.matrix, x0)
        return y + C0 + V0 * self.t[:, None, None]

    # ------------------------------------------------------------------
    def to_xarray(self) -> xarray.Dataset:
        """The trajectory as an :class:`xarray.Dataset` with CF-style attributes: :func:`eulerpoisson.io.netcdf.to_xarray`.

        Batches are flattened to a ``body`` dimension (the batch shape is kept
        in the ``batch_shape`` attribute).

        Raises
        ------
        MissingDependencyError
            If xarray is not installed (extra ``io``).
        """
        from .io import netcdf

        return netcdf.to_xarray(self)

    def to_netcdf(self, path: str | os.PathLike[str]) -> None:
        """Write the trajectory to a NetCDF-4 file, atomically: :func:`eulerpoisson.io.netcdf.write_netcdf`.

        An existing NetCDF file or empty file is replaced; any other file (a configuration, data: recognized by
        its content), a folder or a store is not.

        Raises
        ------
        OutputError
            ``path`` holds something that is not a NetCDF file.
        MissingDependencyError
            If h5netcdf is missing (extra ``io``).
        OSError
            The file cannot be written (the message names it).
        """
        from .io import netcdf

        netcdf.write_netcdf(self, path)

    @classmethod
    def from_netcdf(cls, path: str | os.PathLike[str]) -> Trajectory:
        """Read a trajectory written by :meth:`to_netcdf`: :func:`eulerpoisson.io.netcdf.read_netcdf`.

        Returns
        -------
        Trajectory
            Bit for bit the one written (times, attitudes, angular velocities).

        Raises
        ------
        TypeError, FileNotFoundError, EulerPoissonError, InvalidInputError, MissingDependencyError
            As :func:`eulerpoisson.io.netcdf.read_netcdf`.
        """
        from .io import netcdf

        return netcdf.read_netcdf(path)

    @classmethod
    def open(cls, path: str | os.PathLike[str]) -> Trajectory | LazyTrajectory:
        """Open a trajectory file of any format eulerpoisson writes, by its content.

        NetCDF-4 (:meth:`to_netcdf`) and NetCDF-3 classic files are read into
        memory (:meth:`from_netcdf`); a Zarr store written by
        ``simulate --out run.zarr`` (:func:`eulerpoisson.io.stream.solve_to_file`)
        gives a :class:`eulerpoisson.io.read.LazyTrajectory`, which reads
        the metadata and the first and last samples now and the others on
        demand (``lazy[a:b]``,
        ``lazy.iter_chunks()``, ``lazy.load()``; plots draw it chunk by chunk).

        Raises
        ------
        TypeError, FileNotFoundError, EulerPoissonError, InvalidInputError, MissingDependencyError
            As :func:`eulerpoisson.io.read.open_trajectory`.
        """
        from .io.read import open_trajectory

        return open_trajectory(path)

    # ------------------------------------------------------------------
    # selecting and evaluating
    # ------------------------------------------------------------------
    def __getitem__(self, index: Any) -> Trajectory:
        """The samples ``index`` (an int, a slice, an integer or boolean array) of the time axis.

        ``len(tr)`` is the number of output times and ``tr[i]`` the trajectory
        reduced to sample ``i`` (for every body of a batch); ``tr[::10]``
        thins it. Select a time by value with :meth:`sel`, evaluate at any
        time with ``tr(t)``.

        Raises
        ------
        TypeError
            A float or a tuple index.
        IndexError
            Out of range.
        """
        if isinstance(index, (tuple, float, np.floating, str)) or isinstance(index, (bool, np.bool_)):
            raise TypeError(
                f"a trajectory is indexed by sample (int, slice or integer array), got {index!r}; "
                f"select by time with tr.sel(t=...) or evaluate with tr(t)"
            )
        idx = np.arange(self.t.shape[0])[index]
        idx = np.atleast_1d(idx)
        return Trajectory(
            self.t[idx],
            self.quaternion[..., idx, :],
            self.omega[..., idx, :],
            self.body,
            self.method,
            self.options,
            self.stats,
            torque=list(self.model.torques),
            keep_signs=True,  # the signs of the whole trajectory: a selection never flips a sample
        )

    def sel(self, t: ArrayLike, method: str | None = None) -> Trajectory:
        """The samples at the output times ``t`` (exact match, or ``method="nearest"``).

        Parameters
        ----------
        t : float or array_like
            Times to select.
        method : {None, "nearest"}
            None: every time must be one of the output times.

        Raises
        ------
        KeyError
            A time that is not an output time (with ``method=None``).
        ValueError
            An unknown ``method``; an empty trajectory.
        """
        want = np.atleast_1d(as_float_array(t, "t"))
        if self.t.size == 0:
            raise ValueError("sel() on a trajectory with no output times")
        if method not in (None, "nearest"):
            raise ValueError(f"sel(method=...) must be None or 'nearest', got {method!r}")
        order = np.argsort(self.t, kind="stable")
        ts = self.t[order]
        pos = np.clip(np.searchsorted(ts, want), 0, ts.size - 1)
        left = np.clip(pos - 1, 0, ts.size - 1)
        pick = np.where(np.abs(ts[left] - want) < np.abs(ts[pos] - want), left, pos)
        if method is None and np.any(ts[pick] != want):
            bad = float(want[ts[pick] != want][0])
            raise KeyError(
                f"t = {bad!r} is not an output time of this trajectory; use sel(t, method='nearest') "
                f"or evaluate it with tr({bad!r})"
            )
        return self[order[pick]]

    def __call__(self, t: ArrayLike, **options: Any) -> Trajectory:
        r"""The motion at any times ``t``: :func:`eulerpoisson.solvers.engine.evaluate`.

        The closed form (``exact``) evaluates the same solution at the new
        times (from the nearest sample, exactly); an integrator continues from
        the nearest stored sample of each time (a short integration with the
        trajectory's method and options: the dense output, with the
        trajectory's own error at that sample), never from ``t[0]``.
        Time-dependent torques are continued at the right phase. ``options``
        override the method's options.

        Parameters
        ----------
        t : float or array_like, shape (T,)
            Any times (before ``t[0]`` and after ``t[-1]`` too: continued from the end samples).

        Returns
        -------
        Trajectory

        Raises
        ------
        InvalidInputError
            An empty trajectory, bad times, or a method that is not known.
        """
        from .solvers.engine import evaluate

        return evaluate(self, t, **options)

    def plot(self, kind: str = "omega", **kwargs: Any) -> Figure:
        """A picture of the trajectory: :func:`eulerpoisson.viz.plots.plot` (``kind``: omega, invariants,
        polhode, gibbs, attitude, apex); returns the matplotlib figure (or writes ``out=`` when given)."""
        from .viz import plots

        return plots.plot(self, kind, **kwargs)

    def __repr__(self) -> str:
        b = f", batch_shape={self.batch_shape}" if self.batch_shape else ""
        span = f"[{self.t.min():.6g}, {self.t.max():.6g}]" if self.t.size else "[]"
        return f"Trajectory(method={self.method!r}, T={len(self.t)}, t={span}{b})"

    def _repr_html_(self) -> str:
        """A compact HTML table and a small inline SVG picture of Ω(t) and of the energy, for notebooks.

        See :func:`eulerpoisson.util.htmlrepr.trajectory_html` (no matplotlib; decimated, a few kB at any length).
        """
        from .util.htmlrepr import trajectory_html

        return trajectory_html(self)
