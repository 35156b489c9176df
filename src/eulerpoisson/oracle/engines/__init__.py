"""Physics engines driven through their own Python packages, one adapter each (the conformance report).

Each adapter (:class:`~.base.Engine`) builds a reference case in its engine, steps it with one of the
engine's settings and returns what the engine reports in its own conventions (:class:`~.base.EngineRun`);
:mod:`eulerpoisson.oracle.conformance` reads that as the oracle reads a user's run.

Examples
--------
>>> from eulerpoisson.oracle.engines import ENGINE_NAMES, get_engine
>>> ENGINE_NAMES[:3]
('mujoco', 'mjx', 'pybullet')
>>> list(get_engine("mujoco").settings)
['Euler', 'implicitfast', 'implicit', 'RK4']
"""

from __future__ import annotations

from ...errors import InvalidInputError
from .base import Engine, EngineRun, EngineUnavailable, SamplePlan, sample_plan
from .basilisk import BasiliskEngine
from .dart import DARTEngine
from .drake import DrakeEngine
from .genesis import GenesisEngine
from .mjx import MJXEngine
from .mujoco import MuJoCoEngine
from .newton import NewtonEngine
from .pybullet import PyBulletEngine
from .sapien import SapienEngine

__all__ = [
    "Engine",
    "EngineRun",
    "EngineUnavailable",
    "SamplePlan",
    "sample_plan",
    "ENGINES",
    "ENGINE_NAMES",
    "get_engine",
    "all_engines",
]

#: the adapters, by name, in the report's order
ENGINES: dict[str, type[Engine]] = {
    cls.name: cls
    for cls in (
        MuJoCoEngine,
        MJXEngine,
        PyBulletEngine,
        DrakeEngine,
        DARTEngine,
        BasiliskEngine,
        NewtonEngine,
        SapienEngine,
        GenesisEngine,
    )
}
#: their names
ENGINE_NAMES = tuple(ENGINES)


def get_engine(name: str) -> Engine:
    """The adapter of engine ``name``.

    Raises
    ------
    InvalidInputError
        An unknown name (the message lists the engines).

    Examples
    --------
    >>> from eulerpoisson.oracle.engines import get_engine
    >>> get_engine("drake").conventions.omega_frame
    'space'
    >>> try:
    ...     get_engine("havok")
    ... except ValueError as err:
    ...     print(err)
    engine: unknown engine 'havok'; engines: mujoco, mjx, pybullet, drake, dart, basilisk, newton, sapien, genesis
    """
    if name not in ENGINES:
        raise InvalidInputError(f"engine: unknown engine {name!r}; engines: {', '.join(ENGINE_NAMES)}")
    return ENGINES[name]()


def all_engines() -> list[Engine]:
    """One adapter of each engine, in the report's order.

    Examples
    --------
    >>> from eulerpoisson.oracle.engines import all_engines
    >>> [e.name for e in all_engines()][-2:]
    ['sapien', 'genesis']
    """
    return [cls() for cls in ENGINES.values()]
