r"""What every engine adapter shares: the interface, the run it returns, the sampling plan, the initial state.

An adapter builds a reference case (:class:`~eulerpoisson.oracle.ReferenceCase`) in
an engine's own terms (one free body, its inertia, its initial attitude and rate,
zero gravity, no contact), steps it with the engine's own integrator at a fixed
step ``dt`` and returns what the engine reports, **in the engine's conventions**:
an :class:`EngineRun` says which conventions it claims (a
:class:`~eulerpoisson.oracle.Conventions`) and the oracle's readers
(:func:`~eulerpoisson.oracle.run_from_arrays`, :func:`~eulerpoisson.oracle.compare_run`)
read it as they read a user's file, convention detection included.

An adapter converts only the *representation* an engine gives no quaternion for
(a rotation matrix, modified Rodrigues parameters) into a quaternion of the same
rotation, and says so in :attr:`EngineRun.notes`; the frame of the rate and the
direction of the attitude stay the engine's.
"""

from __future__ import annotations

import importlib
import importlib.metadata
import math
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import NDArray

from ...errors import EulerPoissonError, InvalidInputError
from ..cases import ReferenceCase
from ..runs import Conventions

__all__ = [
    "Engine",
    "EngineRun",
    "EngineUnavailable",
    "SamplePlan",
    "sample_plan",
    "principal_frame",
    "matrix_to_quaternion",
    "quaternion_to_matrix",
    "sampled_loop",
    "principal_state",
    "load",
]


class EngineUnavailable(EulerPoissonError, RuntimeError):
    """An engine that cannot run here (not installed, or its package fails to import or to start).

    The message says why: the install command and its error.

    Examples
    --------
    >>> from eulerpoisson.oracle.engines import EngineUnavailable
    >>> issubclass(EngineUnavailable, RuntimeError)
    True
    """


@dataclass(frozen=True, eq=False)
class EngineRun:
    """What an engine reported for one case, in the engine's own conventions.

    Attributes
    ----------
    t : ndarray, shape (T,)
        Sample times (multiples of the step).
    quaternion : ndarray, shape (T, 4)
        The attitudes as the engine gives them (component order of :attr:`conventions`).
    omega : ndarray, shape (T, 3)
        The angular velocities as the engine gives them (frame of :attr:`conventions`).
    conventions : Conventions
        The conventions the adapter claims for the engine.
    inertia : ndarray, shape (3,) or (3, 3)
        The inertia in the frame the attitudes describe (the case's body frame, or the
        principal frame where the engine takes principal moments only: see ``notes``).
    steps : int
        Steps taken.
    wall_s : float
        Wall time of the stepping alone (building the model and compiling excluded).
    notes : tuple of str
        What the adapter did besides stepping (a representation converted, a default changed).

    Examples
    --------
    >>> import numpy as np
    >>> from eulerpoisson.oracle import Conventions
    >>> from eulerpoisson.oracle.engines import EngineRun
    >>> run = EngineRun(np.array([0.0, 0.1]), np.array([[0.0, 0.0, 0.0, 1.0]] * 2), np.zeros((2, 3)),
    ...                 Conventions("xyzw", "space"), np.array([1.0, 2.0, 3.0]), 10, 0.0)
    >>> run.conventions.quaternion_order, run.steps
    ('xyzw', 10)
    """

    t: NDArray[np.float64]
    quaternion: NDArray[np.float64]
    omega: NDArray[np.float64]
    conventions: Conventions
    inertia: NDArray[np.float64]
    steps: int
    wall_s: float
    notes: tuple = field(default=())


@dataclass(frozen=True)
class SamplePlan:
    """How a run is stepped and sampled: ``samples`` outputs ``every`` steps apart (the first at t = 0).

    Examples
    --------
    >>> from eulerpoisson.oracle.engines import SamplePlan
    >>> plan = SamplePlan(dt=0.01, every=5, samples=3)
    >>> plan.steps, plan.t_end, plan.times.tolist()
    (10, 0.1, [0.0, 0.05, 0.1])
    """

    dt: float
    every: int
    samples: int

    @property
    def steps(self) -> int:
        """Steps in all."""
        return self.every * (self.samples - 1)

    @property
    def t_end(self) -> float:
        """Time of the last sample."""
        return self.steps * self.dt

    @property
    def times(self) -> NDArray[np.float64]:
        """Sample times ``k * every * dt`` (exact multiples, not accumulated)."""
        return np.arange(self.samples, dtype=float) * (self.every * self.dt)


def sample_plan(dt: float, t_end: float, sample_interval: float) -> SamplePlan:
    """The plan of a run to (at least) ``t_end`` sampled about every ``sample_interval``.

    Parameters
    ----------
    dt : float
        The step, > 0.
    t_end : float
        The time to reach, > 0 (the last sample is at or just after it).
    sample_interval : float
        The wanted time between samples (rounded to a whole number of steps, at least one).

    Returns
    -------
    SamplePlan

    Raises
    ------
    InvalidInputError
        A step, end time or interval that is not a positive finite number.

    Examples
    --------
    >>> from eulerpoisson.oracle.engines.base import sample_plan
    >>> p = sample_plan(1e-3, 1.0, 0.05)
    >>> p.every, p.samples, p.steps, round(p.t_end, 12)
    (50, 21, 1000, 1.0)
    """
    for name, x in (("dt", dt), ("t_end", t_end), ("sample_interval", sample_interval)):
        if not (isinstance(x, (int, float, np.floating)) and math.isfinite(x) and x > 0):
            raise InvalidInputError(f"{name} must be a positive finite number, got {x!r}")
    every = max(1, int(round(sample_interval / dt)))
    intervals = max(1, int(math.ceil(t_end / (every * dt) - 1e-9)))
    return SamplePlan(float(dt), every, intervals + 1)


def principal_frame(inertia) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Principal moments and a proper rotation ``P`` (columns: the principal axes in body coordinates).

    ``x_body = P x_principal``; for a diagonal inertia ``P`` is the identity.

    Examples
    --------
    >>> import numpy as np
    >>> from eulerpoisson.oracle.engines.base import principal_frame
    >>> m, P = principal_frame([[2.0, 0.1, 0.0], [0.1, 1.5, -0.2], [0.0, -0.2, 1.2]])
    >>> bool(np.allclose(P @ np.diag(m) @ P.T, [[2.0, 0.1, 0.0], [0.1, 1.5, -0.2], [0.0, -0.2, 1.2]]))
    True
    >>> principal_frame([1.0, 2.0, 3.0])[1].tolist()
    [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]
    """
    I = np.asarray(inertia, dtype=float)
    if I.shape == (3,):
        return I.copy(), np.eye(3)
    if np.array_equal(I, np.diag(np.diag(I))):
        return np.diag(I).copy(), np.eye(3)
    m, P = np.linalg.eigh(0.5 * (I + I.T))
    if np.linalg.det(P) < 0:
        P[:, 2] = -P[:, 2]
    return m, P


def quaternion_to_matrix(q) -> NDArray[np.float64]:
    """The rotation matrix of unit quaternions ``(w, x, y, z)`` (Hamilton), shape (..., 3, 3)."""
    from ...attitude.quaternion import matrix_from_unit_quaternion

    q = np.asarray(q, dtype=float)
    return matrix_from_unit_quaternion(q / np.linalg.norm(q, axis=-1, keepdims=True))


def matrix_to_quaternion(R) -> NDArray[np.float64]:
    """A unit quaternion ``(w, x, y, z)`` (Hamilton, w >= 0) of rotation matrices ``R``, shape (..., 4).

    Examples
    --------
    >>> import numpy as np
    >>> from eulerpoisson.oracle.engines.base import matrix_to_quaternion, quaternion_to_matrix
    >>> q = np.array([0.8, 0.36, -0.48, 0.0])
    >>> bool(np.allclose(matrix_to_quaternion(quaternion_to_matrix(q)), q))
    True
    """
    from ...attitude.quaternion import quaternion_from_rotation_matrix

    return quaternion_from_rotation_matrix(np.asarray(R, dtype=float))


def load(module: str) -> Any:
    """Import an engine's module (untyped to the type checker: the engines ship no type information)."""
    return importlib.import_module(module)


def sampled_loop(
    plan: SamplePlan, step: Callable[[int], None], read: Callable[[], tuple]
) -> tuple[NDArray[np.float64], NDArray[np.float64], float]:
    """Step ``plan.every`` steps between readings: ``(quaternions (T, 4), rates (T, 3), wall seconds of stepping)``.

    ``step(n)`` takes ``n`` steps; ``read()`` gives ``(quaternion, rate)`` as the engine reports them. A reading
    that is not finite stops the run there (the rest is NaN): a diverged engine is not stepped further.
    """
    q = np.full((plan.samples, 4), np.nan)
    w = np.full((plan.samples, 3), np.nan)
    q[0], w[0] = read()
    wall = 0.0
    for k in range(1, plan.samples):
        t0 = time.perf_counter()
        step(plan.every)
        wall += time.perf_counter() - t0
        q[k], w[k] = read()
        if not (np.all(np.isfinite(q[k])) and np.all(np.isfinite(w[k]))):
            break
    return q, w, wall


class Engine:
    """One physics engine, driven through its own Python package.

    Subclasses set the class attributes and implement :meth:`simulate`.

    Attributes
    ----------
    name : str
        The engine's name in the report and on the command line.
    title : str
        Its name as people write it.
    package : str
        The package to install from the package index (``pip install PACKAGE``).
    module : str
        The module to import.
    settings : dict of str to str
        The rotational settings a user can choose, each with one line saying what it is.
    conventions : Conventions
        The conventions the engine reports in.
    max_steps : int
        The most steps one run may take (the report's time budget; the run stops at fewer periods).
    min_dt : float
        The smallest step the report runs (a slower engine cannot reach 10 periods below it in its budget).
    precision : str
        ``"float64"`` or ``"float32"``: the engine's arithmetic.

    Examples
    --------
    >>> from eulerpoisson.oracle.engines import get_engine
    >>> engine = get_engine("pybullet")
    >>> engine.package, list(engine.settings), engine.conventions.quaternion_order
    ('pybullet', ['multibody', 'maximal'], 'xyzw')
    >>> ok, why = get_engine("genesis").available()
    >>> ok
    False
    """

    name: str = ""
    title: str = ""
    package: str = ""
    module: str = ""
    settings: dict[str, str] = {}
    conventions: Conventions = Conventions("wxyz", "body", "body-to-space")
    max_steps: int = 100_000
    min_dt: float = 0.0
    precision: str = "float64"

    def available(self) -> tuple[bool, str]:
        """``(True, "")`` when the engine can run here, else ``(False, the reason: the command and its error)``."""
        try:
            importlib.import_module(self.module)
        except Exception as exc:  # noqa: BLE001 - any failure to import is a reason to report, not a crash
            return False, (
                f"`python -m pip install {self.package}` then `import {self.module}`: "
                f"{type(exc).__name__}: {str(exc).splitlines()[0] if str(exc) else ''}".rstrip(": ")
            )
        return True, ""

    def version(self) -> str | None:
        """The installed version of :attr:`package` (None when it is not installed)."""
        try:
            return importlib.metadata.version(self.package)
        except importlib.metadata.PackageNotFoundError:
            return None

    def check_setting(self, setting: str) -> None:
        """Refuse a setting the engine does not offer.

        Raises
        ------
        InvalidInputError
            The message lists the engine's settings.
        """
        if setting not in self.settings:
            raise InvalidInputError(
                f"setting: {self.name} has no setting {setting!r}; settings: {', '.join(self.settings)}"
            )

    def run(self, case: ReferenceCase, dt: float, setting: str, plan: SamplePlan) -> EngineRun:
        """Build ``case`` in the engine, step it with ``setting`` at ``dt`` following ``plan``, return what it reports.

        Parameters
        ----------
        case : ReferenceCase
            The initial state and inertia.
        dt : float
            The step (the plan's).
        setting : str
            One of :attr:`settings`.
        plan : SamplePlan
            The steps and samples (:func:`sample_plan`).

        Returns
        -------
        EngineRun

        Raises
        ------
        InvalidInputError
            An unknown setting, a step that differs from the plan's.
        EngineUnavailable
            The engine cannot run here.
        """
        self.check_setting(setting)
        if not math.isclose(dt, plan.dt, rel_tol=1e-12):
            raise InvalidInputError(f"dt = {dt!r} differs from the plan's step {plan.dt!r}")
        ok, why = self.available()
        if not ok:
            raise EngineUnavailable(f"{self.name}: {why}")
        return self.simulate(case, setting, plan)

    def simulate(self, case: ReferenceCase, setting: str, plan: SamplePlan) -> EngineRun:  # pragma: no cover
        """The engine's run (subclasses)."""
        raise NotImplementedError

    def __repr__(self) -> str:
        return f"<{type(self).__name__} {self.name}: {', '.join(self.settings)}>"


def principal_state(case: ReferenceCase) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
    """The case's initial state in its principal frame: ``(moments, quaternion (w, x, y, z) body to space, Omega)``.

    For engines that take principal moments only: the body is built in its principal frame,
    ``R_principal = R P`` and ``Omega_principal = P^T Omega`` (:func:`principal_frame`).
    """
    moments, P = principal_frame(case.inertia)
    R = quaternion_to_matrix(np.asarray(case.quaternion0, float)) @ P
    return moments, matrix_to_quaternion(R), P.T @ np.asarray(case.omega0, float)
