"""One compiled specialization per numba kernel, whatever the memory of the inputs (issue 25).

numba types a read-only array (``np.broadcast_to``, ``flags.writeable =
False``, a NetCDF read) apart from a writeable one, and a non-contiguous
array apart from a C-contiguous one: each is compiled on its own, and
``eulerpoisson warmup`` (the on-disk cache) holds one of them only. The
wrappers that call the kernels hand them C-contiguous writeable float64
arrays (copied only where they are not), so that

* a call with read-only, broadcast or strided inputs adds no signature to a
  kernel that the same call with writeable inputs compiled, and gives the
  same bits;
* no kernel has two signatures that differ only in the read-only flag or the
  layout of some array;
* the warm-up compiles exactly the signatures that the public API uses.
"""

from __future__ import annotations

import importlib

import numpy as np
import pytest

from _markers import needs_numba
from eulerpoisson import solve
from eulerpoisson.estimation.variational import propagate
from eulerpoisson.solvers.exact.lagrange import lagrange_top_motion
from eulerpoisson.solvers.taylor.method import integrate_principal
from eulerpoisson.torques import Gravity
from eulerpoisson.util import jit

pytestmark = needs_numba

T = np.linspace(-0.5, 1.0, 4)
INERTIA = np.array([1.5, 2.0, 3.0])
OMEGA = np.array([1.0, 0.1, 0.5])
BATCH_INERTIA = INERTIA + np.array([[0.0, 0.0, 0.0], [0.1, 0.05, 0.02]])  # two different bodies
BATCH_OMEGA = OMEGA + np.array([[0.0, 0.0, 0.0], [0.2, -0.1, 0.05]])
LANES = 5  # bodies: the SIMD-lane Taylor kernel (LANES_MIN_BODIES)
LANE_INERTIA = INERTIA + 0.01 * np.arange(LANES)[:, None]
LANE_OMEGA = OMEGA + 0.02 * np.arange(LANES)[:, None]
GRAVITY = Gravity(1.0, [0.1, 0.0, 0.3])
TOP = np.array([1.0, 1.0, 0.5])  # a symmetric body: the Lagrange top under gravity
TOP_GRAVITY = Gravity(1.0, [0.0, 0.0, 0.3])


def _ro(x):
    """A read-only copy of ``x``."""
    a = np.array(x, dtype=float)
    a.flags.writeable = False
    return a


def _strided(x):
    """``x`` as a non-contiguous (and writeable) view."""
    a = np.asarray(x, dtype=float)
    return np.repeat(a, 2, axis=-1)[..., ::2]


def _inputs(kind, inertia, omega):
    """(inertia, omega0, t) of one kind of memory: writeable, read-only, broadcast (read-only) or strided."""
    if kind == "writeable":
        return np.array(inertia, dtype=float), np.array(omega, dtype=float), T.copy()
    if kind == "readonly":
        return _ro(inertia), _ro(omega), _ro(T)
    if kind == "broadcast":
        b = lambda x: np.broadcast_to(np.asarray(x, dtype=float), np.shape(x))  # noqa: E731
        return b(inertia), b(omega), b(T)
    return _strided(inertia), _strided(omega), _strided(T)


KINDS = ("writeable", "readonly", "broadcast", "strided")


def _solve(inertia, omega, t, **kw):
    return solve(inertia, t, omega0=omega, workers=1, **kw)


#: (kernel "module:name", warm-up group, [(what, run(inertia, omega, t)) with the body inputs of each call])
CASES = {
    "taylor": (
        "eulerpoisson.solvers.taylor.kernels:nb_integrate",
        "taylor",
        [
            ((INERTIA, OMEGA), lambda i, w, t: _solve(i, w, t, method="taylor")),
            ((BATCH_INERTIA, BATCH_OMEGA), lambda i, w, t: _solve(i, w, t, method="taylor")),
            ((INERTIA, BATCH_OMEGA), lambda i, w, t: _solve(i, w, t, method="taylor")),
            ((INERTIA, OMEGA), lambda i, w, t: integrate_principal(i, w, t, lanes=False)),
        ],
    ),
    "taylor-lanes": (
        "eulerpoisson.solvers.taylor.kernels:nb_integrate_lanes",
        "taylor",
        [
            ((LANE_INERTIA, LANE_OMEGA), lambda i, w, t: _solve(i, w, t, method="taylor")),
            ((INERTIA, LANE_OMEGA), lambda i, w, t: _solve(i, w, t, method="taylor")),
            ((LANE_INERTIA, LANE_OMEGA), lambda i, w, t: integrate_principal(i, w, t, lanes=True)),
        ],
    ),
    "taylor-torque": (
        "eulerpoisson.solvers.taylor.torque:integrate_body",
        "taylor-torque",
        [
            ((INERTIA, OMEGA), lambda i, w, t: _solve(i, w, t, method="taylor", torque=GRAVITY)),
            ((BATCH_INERTIA, BATCH_OMEGA), lambda i, w, t: _solve(i, w, t, method="taylor", torque=GRAVITY)),
        ],
    ),
    "exact-splitting": (
        "eulerpoisson.solvers.symplectic.exact_splitting:split_body",
        "exact-splitting",
        [
            (
                (INERTIA, OMEGA),
                lambda i, w, t: _solve(i, w, t, method="symplectic", scheme="exact_splitting", torque=GRAVITY),
            ),
            (
                (BATCH_INERTIA, BATCH_OMEGA),
                lambda i, w, t: _solve(i, w, t, method="symplectic", scheme="exact_splitting4", torque=GRAVITY),
            ),
        ],
    ),
    "splitting": (
        "eulerpoisson.solvers.symplectic.kernels:nb_splitting",
        "symplectic",
        [
            ((INERTIA, OMEGA), lambda i, w, t: _solve(i, w, t, method="symplectic", scheme="splitting")),
            ((BATCH_INERTIA, BATCH_OMEGA), lambda i, w, t: _solve(i, w, t, method="symplectic", scheme="splitting")),
        ],
    ),
    "gauss": (
        "eulerpoisson.solvers.symplectic.kernels:nb_gauss",
        "symplectic",
        [
            ((INERTIA, OMEGA), lambda i, w, t: _solve(i, w, t, method="symplectic", scheme="gauss2")),
            ((BATCH_INERTIA, BATCH_OMEGA), lambda i, w, t: _solve(i, w, t, method="symplectic", scheme="gauss2")),
        ],
    ),
    "fit-variational": (
        "eulerpoisson.estimation.variational:propagate_numba",
        "fit",
        [
            (
                (np.diag(INERTIA), OMEGA),
                lambda i, w, t: propagate(i, w, np.zeros((2, 3, 3)), t[1:]),  # times 0, 0.5, 1
            ),
        ],
    ),
    "lagrange": (
        "eulerpoisson.solvers.exact.lagrange_kernels:heavy_top_kernel",
        "lagrange",
        [
            ((TOP, OMEGA), lambda i, w, t: _solve(i, w, t, method="exact", torque=TOP_GRAVITY)),
            (
                (TOP, [0.0, 0.0, 10.0]),
                lambda i, w, t: lagrange_top_motion(
                    1.0, 0.5, 1.0, 0.25, [0.0, 0.0, -9.81], [0.96592583, 0.25881905, 0.0, 0.0], w, t, compiled=True
                ),
            ),
        ],
    ),
}


@pytest.fixture(autouse=True)
def _compiled_kernels(monkeypatch):
    """The compiled kernels for every problem, however small (no NumPy twin)."""
    monkeypatch.setenv(jit.ENV_NUMPY_BELOW, "0")


def _kernel(spec):
    module, name = spec.split(":")
    return getattr(importlib.import_module(module), name)


def _arrays(result):
    """The arrays of a result (a Trajectory or a tuple of arrays), to compare bit for bit."""
    if isinstance(result, tuple):
        return [np.asarray(x) for x in result if isinstance(x, np.ndarray)]
    return [np.asarray(result.quaternion), np.asarray(result.omega)]


def _memory_blind(signature):
    """The signature with every array reduced to its dtype and rank (read-only flag and layout dropped)."""
    from numba import types

    return tuple((a.dtype, a.ndim) if isinstance(a, types.Array) else a for a in signature)


def _check_arrays(signatures):
    """Every array argument is C-contiguous and writeable, and no two signatures differ in memory only."""
    from numba import types

    for sig in signatures:
        for a in sig:
            if isinstance(a, types.Array):
                assert a.layout == "C" and a.mutable, f"an array {a} in the signature {sig}"
    blind = [_memory_blind(s) for s in signatures]
    assert len(set(blind)) == len(blind), f"signatures differing in memory only: {signatures}"


@pytest.mark.parametrize("case", list(CASES))
def test_read_only_inputs_reuse_the_writeable_signature(case):
    spec, _, calls = CASES[case]
    for (inertia, omega), run in calls:
        reference = _arrays(run(*_inputs("writeable", inertia, omega)))
        kernel = _kernel(spec)
        compiled = set(kernel.signatures)
        assert compiled, f"{spec} did not run"
        for kind in KINDS[1:]:
            got = _arrays(run(*_inputs(kind, inertia, omega)))
            assert set(kernel.signatures) == compiled, f"{kind} inputs compiled {spec} again"
            for a, b in zip(got, reference, strict=True):
                np.testing.assert_array_equal(a, b, strict=True)
    _check_arrays(_kernel(spec).signatures)


@pytest.mark.parametrize("case", list(CASES))
def test_the_warmup_compiles_what_the_calls_use(case):
    from eulerpoisson.util.warmup import GROUPS

    spec, group, calls = CASES[case]
    next(g for g in GROUPS if g.name == group).run()
    kernel = _kernel(spec)
    warm = set(kernel.signatures)
    for (inertia, omega), run in calls:
        for kind in KINDS:
            run(*_inputs(kind, inertia, omega))
            new = set(kernel.signatures) - warm
            assert not new, f"{case} ({kind} inputs) compiled a signature that the warm-up does not: {new}"
    # (whatever ran before in this process: one signature per role, the warm-up's and the calls' alike)
    _check_arrays(kernel.signatures)
