r"""The ``solve`` driver: one call for every registered method.

A method receives a :class:`~eulerpoisson.solvers.problem.Problem` (bodies,
initial attitudes and body angular velocities, output times, all batched) and
returns the attitude quaternions and body angular velocities at the output
times; :func:`solve` wraps them in a :class:`~eulerpoisson.trajectory.Trajectory`.

References
----------
Paper eq. 1.4-1.5 (the equations solved) and 1.23.1 (the general solution as
the exponential of the Hamiltonian vector field).
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

from numpy.typing import ArrayLike

from ..trajectory import Trajectory
from .engine import collect, prepare_run
from .quick import quick_solve
from .registry import MethodOptions

if TYPE_CHECKING:
    from ..attitude.core import AttitudeLike
    from ..model.body import RigidBody
    from ..model.equations import Model
    from ..model.torques import TorqueLike

__all__ = ["solve"]


def solve(
    body: RigidBody | Model | ArrayLike,
    t: ArrayLike,
    *,
    omega0: ArrayLike | None = None,
    m0: ArrayLike | None = None,
    attitude0: AttitudeLike | None = None,
    gibbs0: ArrayLike | None = None,
    torque: TorqueLike = None,
    method: str | MethodOptions | None = None,
    workers: int | None = None,
    **options: Any,
) -> Trajectory:
    r"""Motion of rigid bodies, free or under torque, at the output times ``t``.

    Parameters
    ----------
    body : RigidBody, Model or array_like
        The body (or a batch of bodies; an array is passed to
        :class:`RigidBody`), or a :class:`~eulerpoisson.Model` with its torques.
    t : float or array_like, shape (T,)
        Output times, any order; negative times run the motion backwards
        from the initial state at ``t = 0``.
    omega0 : array_like, shape (..., 3), optional
        Initial body angular velocity :math:`\boldsymbol\Omega(0)` in the
        body frame.
    m0 : array_like, shape (..., 3), optional
        Initial spatial angular momentum :math:`\mathbf m = RI\boldsymbol\Omega`.
        Exactly one of ``omega0`` and ``m0``.
    attitude0 : Attitude, scipy Rotation or array_like, shape (..., 4), optional
        Initial attitude (unit quaternions w, x, y, z, norm 1 within
        :data:`~eulerpoisson.attitude.UNIT_QUATERNION_TOLERANCE`); the identity by
        default, as for the paper's trajectories through the unit of SO(3) (eq. 1.2).
    gibbs0 : array_like, shape (..., 3), optional
        Initial attitude as the Gibbs vector n = k tan(alpha/2) (eq. 1.8),
        instead of ``attitude0``.
    torque : Torque, callable, list of them, or None
        Torques (:mod:`eulerpoisson.torques`: ``Gravity``, ``GravityGradient``,
        ``BodyTorque``, ``SpaceTorque``; a callable ``torque(t, q, omega) ->
        tau_body`` vectorized over the batch; a list is their sum). None: the
        free body. For a heavy top the inertia is about the fixed point.
    method : str, MethodOptions or None
        A name from :func:`available_methods`: ``"exact"`` (closed form:
        the free body and the Lagrange top) and the integrators; or a
        method's typed options (``TaylorOptions(tol=1e-12)``,
        ``SymplecticOptions(scheme="gauss6", dt=0.01)``, ...), which name
        their method. None (default): the most accurate method that can run
        the model, ``"exact"`` where the closed form exists, else
        ``"taylor"`` (polynomial torques), else the first that can; the
        trajectory's ``method`` records the choice. The command line makes
        the same choice.
    workers : int or None
        Threads that solve a batch of bodies: chunks of the batch are solved
        in parallel by the compiled kernels (:mod:`~eulerpoisson.solvers.parallel`).
        None (default): the environment variable ``EULERPOISSON_WORKERS``
        if set, else every core this process may use; 1: the calling thread
        only. The results are the same, bit for bit, for every value. Small
        problems (fewer than 32 bodies, or less than about 10 ms of work)
        always run on the calling thread, and so does ``method="rk"``
        (scipy's integrators hold the GIL).
    **options
        Method options (e.g. ``tol`` or ``dt``); unknown ones raise TypeError.

    Returns
    -------
    Trajectory
        Times, attitudes, angular velocities and integrals. ``stats`` holds
        the method's counters (over the whole batch: totals such as
        ``steps`` summed over the chunks of a threaded solve, maxima such
        as ``steps_max`` taken over them), ``wall_time`` (seconds from the
        start of the solution to the finished trajectory) and ``threads``
        (the threads that solved the batch). A stepping method's long run
        (more than :data:`~eulerpoisson.solvers.engine.SEGMENT` monotonic
        output times, or a great many turns of the fastest body) is solved
        in segments, each continued from the last state of the previous one,
        exactly as a file of the same run is written
        (:mod:`~eulerpoisson.solvers.engine`); ``stats["segments"]`` then
        counts them.

    Raises
    ------
    TypeError
        Neither or both of ``omega0``/``m0``; both ``attitude0`` and
        ``gibbs0``; ``workers`` not an integer; an unknown keyword (named
        as an argument of ``solve`` when no method has it, with the closest
        name) or an option of another method.
    InvalidInputError
        Unknown method, bad shapes, NaN/inf, a non-unit quaternion,
        ``workers`` < 1 (or an invalid ``EULERPOISSON_WORKERS``).
    UnsupportedModelError
        The method cannot run the model (e.g. ``method="exact"`` with a
        gravity gradient); the message names the methods that can.
    InvalidInertiaError
        A non-physical inertia tensor.

    Examples
    --------
    >>> import eulerpoisson as ep
    >>> tr = ep.solve([1.0, 2.0, 3.0], [0.0, 1.0, 10.0], omega0=[1.0, 0.1, 0.5])
    >>> tr.omega.shape
    (3, 3)
    >>> top = ep.torques.Gravity(mass=1.0, center_of_mass=[0.0, 0.0, 0.1])
    >>> tr = ep.solve([1.0, 1.0, 0.5], [0.0, 1.0], omega0=[0.0, 0.2, 20.0], torque=top, method="taylor")
    >>> tr.omega.shape
    (2, 3)
    """
    quick = quick_solve(
        body,
        t,
        omega0=omega0,
        m0=m0,
        attitude0=attitude0,
        gibbs0=gibbs0,
        torque=torque,
        method=method,
        workers=workers,
        **options,
    )
    if quick is not None:  # one free body at a few times: the same result without the general set-up
        return quick
    args: dict[str, Any] = dict(
        omega0=omega0, m0=m0, attitude0=attitude0, gibbs0=gibbs0, torque=torque, method=method, workers=workers
    )
    # a tuple is a list of times here (not solve_to_file's grid)
    run = prepare_run(body, list(t) if isinstance(t, tuple) else t, in_memory=True, stacklevel=3, **args, **options)
    return collect(run)
