r"""The closed-form motion (``method="exact"``): the free rigid body and the Lagrange top.

The body angular momentum is given by Jacobi elliptic functions and the
attitude by the rotation that takes the constant spatial angular momentum to
a fixed axis, composed with a rotation about it by an angle given by an
elliptic integral of the third kind (the numerics are in the private modules
``_exact`` and ``_elliptic``). Every output time costs O(1).

For a full (non-diagonal) inertia tensor the motion is computed in the
principal frame :math:`P` and mapped back: with :math:`R_P(t)` the principal
motion from the identity,

.. math:: R(t) = R_0\,P\,R_P(t)\,P^T, \qquad \boldsymbol\Omega(t) = P\,\boldsymbol\Omega_P(t),

which is exact because the free body is left-invariant.

A heavy symmetric top with its centre of mass on the symmetry axis (the
Lagrange top: :meth:`~eulerpoisson.Model.lagrange_top` recognizes it in any
body frame) is solved in closed form too (:mod:`.lagrange`): the body frame
is turned so that the symmetry axis is :math:`\mathbf e_3` (:math:`R_{top} =
RF`), solved there and turned back. Other torques are refused with
:class:`~eulerpoisson.errors.UnsupportedModelError`.

References
----------
Paper section 2 (integrability). L. D. Landau and E. M. Lifshitz, *Mechanics*,
§37. E. Celledoni, F. Fassò, N. Säfström and A. Zanna, "The exact computation
of the free rigid body motion and its use in splitting methods", SIAM J. Sci.
Comput. 30 (2008) 2084-2112.
"""

from __future__ import annotations

import copy
import math
from dataclasses import dataclass

import numpy as np

from ...attitude.core import quaternion_from_rotation_matrix
from ...numerics.quaternion import qmul
from ...util import jit
from ...util.validate import MAX_PHASE as MAX_PHASE  # (the limit it enforces, read by tests and callers)
from ...util.validate import check_phase
from ..problem import Problem, compose_initial, left_composed
from ..registry import Method, MethodOptions, MethodResult, overrides, register_method

__all__ = ["Exact"]


def _check_phase_range(problem: Problem, speed=None) -> None:
    r"""Refuse times at which float64 no longer determines the phase of the motion
    (:func:`~eulerpoisson.util.validate.check_phase`).

    The frequencies of the motion (the elliptic :math:`\lambda` and the
    precession rate, both of the order of :math:`|\boldsymbol\Omega|`) are
    rounded numbers: a relative error of a few ulp becomes a phase error of
    about :math:`4\varepsilon|\boldsymbol\Omega||t|`. Beyond
    :math:`|\boldsymbol\Omega||t| = 2^{48}` that is more than a tenth of a
    radian, and far beyond it any point of the orbit would be as good an
    answer as another: an error instead of a silent guess.

    Raises
    ------
    InvalidInputError
        If :math:`|\boldsymbol\Omega_0||t| > 2^{48}` for some body and time
        (``speed`` replaces :math:`|\boldsymbol\Omega_0|` when given: a
        heavy top's rate includes :math:`\sqrt{\mu g\ell/A}`).
    """
    what = "|omega0| |t|" if speed is None else "(|omega0| + sqrt(mass |g| |ell| / A)) |t|"  # a heavy top's rate
    check_phase(problem.t, problem.omega0, speed, what=what)


@dataclass(frozen=True)
class ExactOptions(MethodOptions):
    """``method="exact"`` has no options.

    Examples
    --------
    >>> import eulerpoisson as ep
    >>> from eulerpoisson.solvers import ExactOptions
    >>> ExactOptions().to_dict()
    {}
    >>> ep.solve([1.0, 2.0, 2.5], [1.0], omega0=[1.0, 0.1, 0.5], method=ExactOptions()).method
    'exact'
    """

    method = "exact"


@register_method
class Exact(Method):
    r"""Closed-form solution by Jacobi elliptic functions and Carlson's integrals.

    Accurate to a few ulps times :math:`|\boldsymbol\Omega||t|` (the
    conditioning of the phase), O(1) per output time, vectorized over bodies
    and times; no options. Models: the free body, and the Lagrange top (a
    symmetric body, centre of mass on the symmetry axis, one
    :class:`~eulerpoisson.torques.Gravity`; every regime, see
    :mod:`.lagrange`).

    Raises
    ------
    InvalidInputError
        At times with :math:`|\boldsymbol\Omega_0||t| > 2^{48}`, where
        float64 no longer determines the phase of the motion.

    Examples
    --------
    >>> import numpy as np, eulerpoisson as ep
    >>> from eulerpoisson.solvers.exact import Exact
    >>> Exact.name, Exact.order
    ('exact', None)
    >>> tr = ep.solve([3.0, 5.0, 8.0], [0.0, 1e6], omega0=[0.0, 0.4, 0.00125])   # any time, O(1)
    >>> print(tr.method, np.round(tr.drift()["energy"], 12))
    exact 0.0
    """

    name = "exact"
    Options = ExactOptions
    order = None
    description = "closed form (Jacobi elliptic functions, elliptic integral of the third kind)"

    @classmethod
    def supports(cls, model) -> str | None:
        if model.is_free or _lagrange_parameters(model) is not None:
            return None
        return (
            "the closed form covers the free body and the Lagrange top (a symmetric body with its centre of mass "
            f"on the symmetry axis under one Gravity torque), and the model has {model.describe()}"
        )

    #: compiled kernels or NumPy, chosen for a whole batch by :meth:`for_batch` (None: from the problem run)
    _compiled: bool | None = None
    #: the free body's path (:meth:`_free_path`), chosen for a whole batch by :meth:`for_batch`
    _path: str | None = None
    #: whether the body frame is the principal frame of every body, decided for a whole batch by
    #: :meth:`for_batch` (None: from the problem run), so that a chunk of diagonal tensors in a batch
    #: that has full ones takes the same path as the whole batch (the same signs of zeros)
    _principal: bool | None = None

    def numpy_estimate(self, problem: Problem) -> float:
        """Seconds of the NumPy path on one core (below ``NUMPY_BELOW``, numba is not used).

        Measured (benchmarks/README.md, cold start): the free body about 2 ms per call, 8 microseconds per
        body and 2 per (body, time); the Lagrange top about 5 ms, 20 and 2.5.
        """
        return _numpy_seconds(math.prod(problem.batch_shape), problem.t.shape[0], problem.model.is_free)

    def python_estimate(self, problem: Problem) -> float:
        """Seconds of the scalar kernel run as plain Python (the free body): about 0.1 ms per body and 0.11 ms
        per (body, time) (the compiled kernel's numbers, no numba start; :func:`~eulerpoisson.util.jit.python_twins`)."""
        return _python_seconds(math.prod(problem.batch_shape), problem.t.shape[0])

    def _free_path(self, problem: Problem) -> str:
        """The free body's path, from the size of the run alone: ``"compiled"``, ``"python"`` or ``"numpy"``.

        The compiled kernels above :func:`~eulerpoisson.util.jit.use_compiled`'s threshold; below it, where the
        scalar kernel as plain Python is faster than NumPy (a few evaluations), that (or the compiled kernel
        when numba is already active in the process: the same numbers, bit for bit); NumPy otherwise.
        """
        if self._path is not None:
            return self._path
        return _free_path_from(self.numpy_estimate(problem), self.python_estimate(problem))

    def _use_compiled(self, problem: Problem) -> bool:
        return self._compiled if self._compiled is not None else jit.use_compiled(self.numpy_estimate(problem))

    def for_batch(self, problem: Problem) -> Exact:
        """This method with the batch-wide choices made: compiled kernels or NumPy (:meth:`numpy_estimate`), principal frame."""
        planned = copy.copy(self)
        if problem.model.is_free:
            planned._path = self._free_path(problem)
            planned._compiled = planned._path == "compiled"
        else:
            planned._compiled = self._use_compiled(problem)
        planned._principal = _principal_frame(problem)
        return planned

    def run_one(self, body, q0, omega0, t) -> MethodResult | None:
        """One free body whose principal frame is the body frame (the quick lane, :meth:`Method.run_one`):
        what :meth:`run` computes for it, without the problem."""
        if (type(self) is not Exact and overrides(self, Exact, _RUN_HOOKS)) or not _all_identity(body.principal_axes):
            return None  # (a subclass that decides or runs otherwise: the general route, through its own methods)
        T = t.shape[0]
        path = self._path if self._path is not None else _one_body_path(T)
        check_phase(t, omega0)
        Ip = body.principal_moments
        motion = _MOTION if _MOTION is not None else _motion()
        Mp, q_rel = motion.one_body_motion(Ip, Ip * omega0, t, compiled=_COMPILED_ARG.get(path, path))
        return MethodResult(
            q=left_composed(q0, q_rel),
            omega=Mp / Ip,
            stats={"evaluations": T, "compiled": path == "compiled" and jit.USE_NUMBA, "threads": 1},
        )

    def run(self, problem: Problem) -> MethodResult:
        # (the problem is checked: float64, finite, moments > 0; the kernels need no second check)
        from .motion import exact_motion_unchecked as exact_motion

        if not problem.model.is_free:
            return self._run_lagrange(problem)
        path = self._free_path(problem)
        compiled: bool | str = {"compiled": True, "numpy": False}.get(path, path)

        _check_phase_range(problem)
        Ip = problem.principal_moments
        if self._principal if self._principal is not None else _principal_frame(problem):
            # the body frame is the principal frame of every body (a batch of moments, or diagonal
            # tensors): no rotations (three einsums and the test of the tensors cost more per body
            # than the closed form itself in the Monte-Carlo case)
            # M0 = I Omega0 with a diagonal I: the moments times Omega0 (the matrix product adds zeros)
            Mp, q_rel = exact_motion(Ip, Ip * problem.omega0, problem.t, compiled=compiled)
            omega = Mp / Ip[..., None, :]
        else:
            P = problem.principal_axes  # (*B, 3, 3), det +1
            Mp0 = np.einsum("...ji,...j->...i", P, problem.M0)
            Mp, q_rel = exact_motion(Ip, Mp0, problem.t, compiled=compiled)
            omega_p = Mp / Ip[..., None, :]
            omega = np.einsum("...ij,...tj->...ti", P, omega_p)
            qP = quaternion_from_rotation_matrix(P)[..., None, :]
            qPc = qP * np.array([1.0, -1.0, -1.0, -1.0])
            q_rel = qmul(qmul(qP, q_rel), qPc)
        q = compose_initial(problem, q_rel)
        return MethodResult(
            q=q,
            omega=omega,
            stats={"evaluations": math.prod(q.shape[:-1]), "compiled": path == "compiled" and jit.USE_NUMBA},
        )

    def work_estimate(self, problem: Problem) -> float:
        """Seconds on one core (decides whether threads pay off): the measured costs of the lane kernel.

        About 0.6 microseconds to set a body up and evaluate it once, 0.15 per further (body, time)
        evaluation (benchmarks/bench_exact.py); the Lagrange top about 1 microsecond per (body, time).
        """
        B = int(np.prod(problem.batch_shape, dtype=int))
        T = problem.t.shape[0]
        if not problem.model.is_free:
            return 1.0e-6 * B * (1 + T)
        return 0.6e-6 * B + 0.15e-6 * B * max(T - 1, 0)

    def _run_lagrange(self, problem: Problem) -> MethodResult:
        from .lagrange import lagrange_top_motion

        bshape = problem.batch_shape
        A, C, mass, ell, g, F = (
            np.broadcast_to(x, bshape + x.shape[len(problem.model.batch_shape) :])
            for x in _lagrange_parameters(problem.model)
        )
        rate = np.sqrt(np.sum(problem.omega0 * problem.omega0, axis=-1)) + np.sqrt(
            mass * np.sqrt(np.sum(g * g, axis=-1)) * np.abs(ell) / A
        )
        _check_phase_range(problem, rate)
        compiled = self._use_compiled(problem)
        if _all_identity(F):
            # the symmetry axis is the third body axis already: no change of frame
            q, w = lagrange_top_motion(A, C, mass, ell, g, problem.q0, problem.omega0, problem.t, compiled=compiled)
        else:
            qF = quaternion_from_rotation_matrix(F)
            q0 = qmul(problem.q0, qF)
            w0 = np.einsum("...ji,...j->...i", F, problem.omega0)
            q, w = lagrange_top_motion(A, C, mass, ell, g, q0, w0, problem.t, compiled=compiled)
            q = qmul(q, (qF * np.array([1.0, -1.0, -1.0, -1.0]))[..., None, :])
            w = np.einsum("...ij,...tj->...ti", F, w)
        return MethodResult(
            q=q,
            omega=w,
            stats={
                "evaluations": int(np.prod(q.shape[:-1])),
                "model": "lagrange top",
                "compiled": bool(compiled and _numba_in_use()),
            },
        )


def _numpy_seconds(n_bodies: int, n_times: int, free: bool) -> float:
    """:meth:`Exact.numpy_estimate` for a problem of this size (the whole run's size decides, :func:`~eulerpoisson.util.jit.run_shape`)."""
    return _numpy_cost(*jit.run_shape(n_bodies, n_times), free)


def _numpy_cost(B: int, T: int, free: bool) -> float:
    """Seconds of the NumPy path for a run of ``B`` bodies at ``T`` times."""
    if not free:
        return 5e-3 + 20e-6 * B + 2.5e-6 * B * T
    return 2e-3 + 8e-6 * B + 2e-6 * B * T


def _python_seconds(n_bodies: int, n_times: int) -> float:
    """:meth:`Exact.python_estimate` for a problem of this size."""
    return _python_cost(*jit.run_shape(n_bodies, n_times))


def _python_cost(B: int, T: int) -> float:
    """Seconds of the scalar kernel as plain Python for a run of ``B`` bodies at ``T`` times."""
    return 1.0e-4 * B + 1.1e-4 * B * T


_MOTION = None


def _motion():
    """The module of the closed form (imported on first use, not with the package)."""
    global _MOTION
    from . import motion

    _MOTION = motion
    return motion


#: the methods through which the exact method decides and runs: a subclass redefining one takes the general route
_RUN_HOOKS = ("run", "for_batch", "numpy_estimate", "python_estimate", "_free_path")
#: the ``compiled`` argument of the kernels' entry points for each path
_COMPILED_ARG = {"compiled": True, "numpy": False}


def _one_body_path(n_times: int) -> str:
    """:meth:`Exact._free_path` of one body at ``n_times`` times (the whole run's size decides).

    The same choice as :func:`_free_path_from` on the estimated costs, remembered by the run's shape, the
    threshold in force (:func:`~eulerpoisson.util.jit.numpy_below`) and whether numba is active.
    """
    shape = jit.run_shape(1, n_times)
    key = (shape, jit.numpy_below(), jit.numba_active())
    path = _ONE_BODY_PATHS.get(key)
    if path is None:
        B, T = shape
        path = _free_path_from(_numpy_cost(B, T, True), _python_cost(B, T))
        if len(_ONE_BODY_PATHS) >= 256:
            _ONE_BODY_PATHS.clear()
        _ONE_BODY_PATHS[key] = path
    return path


#: :func:`_one_body_path`'s choices by (run shape, threshold, numba active)
_ONE_BODY_PATHS: dict[tuple, str] = {}


def _free_path_from(numpy_seconds: float, python_seconds: float) -> str:
    """:meth:`Exact._free_path` from the estimated seconds of the NumPy path and of the plain-Python kernel."""
    if jit.use_compiled(numpy_seconds):
        return "compiled"
    if python_seconds < numpy_seconds:
        return "compiled" if jit.USE_NUMBA and jit.numba_active() else "python"
    return "numpy"


def _numba_in_use() -> bool:
    from ...util.jit import USE_NUMBA

    return USE_NUMBA


_IDENTITY9 = np.eye(3).reshape(9)


def _all_identity(frames) -> bool:
    """Whether every 3x3 matrix of ``frames`` (shape ``(..., 3, 3)``) is the identity, exactly."""
    if type(frames) is np.ndarray and frames.ndim == 2:  # one matrix: plain floats
        return frames.tolist() == _IDENTITY33_LIST
    if np.ndim(frames) == 2:
        return np.ravel(frames).tolist() == _IDENTITY9_LIST
    return bool((np.reshape(frames, (-1, 9)) == _IDENTITY9).all())


_IDENTITY9_LIST = _IDENTITY9.tolist()
_IDENTITY33_LIST = np.eye(3).tolist()


def _principal_frame(problem: Problem) -> bool:
    """Whether every principal frame of the batch is the body frame (``principal_axes`` the identity)."""
    return _all_identity(problem.body.principal_axes)


def _lagrange_parameters(model):
    """``(A, C, mass, ell, g, F)`` of a (batch of) Lagrange top(s), each with the model's batch shape, or None.

    One vectorized call of :meth:`~eulerpoisson.model.equations.Model.lagrange_top` for the whole batch
    (no loop over the bodies in Python).
    """
    lt = model.lagrange_top()
    if lt is None:
        return None
    return lt.A, lt.C, lt.mass, lt.ell, lt.g, lt.frame
