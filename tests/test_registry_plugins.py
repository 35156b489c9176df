"""Methods registered and removed again (plug-ins, tests): ``register_method`` / ``unregister_method``."""

from __future__ import annotations

import numpy as np
import pytest

import eulerpoisson as ep
from eulerpoisson.errors import InvalidInputError
from eulerpoisson.solvers import get_method, register_method, unregister_method
from eulerpoisson.solvers.exact import Exact


def test_register_solve_and_unregister():
    @register_method
    class Twin(Exact):
        name = "exact-twin"

    try:
        assert get_method("exact-twin") is Twin
        a = ep.solve([1.0, 2.0, 3.0], [0.0, 2.5], omega0=[1.0, 0.1, 0.5], method="exact-twin")
        b = ep.solve([1.0, 2.0, 3.0], [0.0, 2.5], omega0=[1.0, 0.1, 0.5], method="exact")
        np.testing.assert_array_equal(a.quaternion, b.quaternion)
    finally:
        assert unregister_method("exact-twin") is Twin
    assert "exact-twin" not in ep.available_methods()
    with pytest.raises(InvalidInputError, match="unknown method 'exact-twin'"):
        ep.solve([1.0, 2.0, 3.0], [1.0], omega0=[1.0, 0.1, 0.5], method="exact-twin")


@pytest.mark.parametrize("name", ["nope", 3, None])
def test_unregister_unknown_names_fail(name):
    with pytest.raises(InvalidInputError, match="unknown method"):
        unregister_method(name)
    assert ep.available_methods() == ["exact", "rk", "rk4", "symplectic", "taylor"]


@pytest.mark.parametrize("base", ["exact", "taylor"])
@pytest.mark.parametrize("hook", ["run", "for_batch"])
def test_a_plug_in_that_runs_otherwise_is_run_through_its_own_methods(base, hook):
    """One body at a few times (the quick lane): a subclass that redefines how it runs is not replaced by the
    base class's one-body shortcut (``Method.run_one``)."""
    parent = get_method(base)
    calls = []

    def run(self, problem):
        calls.append("run")
        res = parent.run(self, problem)
        res.q = -res.q  # the same rotations, the other sign: visible in the result
        return res

    def for_batch(self, problem):
        calls.append("for_batch")
        return parent.for_batch(self, problem)

    cls = type("Plugged", (parent,), {"name": f"{base}-plugged", hook: run if hook == "run" else for_batch})
    register_method(cls)
    try:
        got = ep.solve([1.0, 2.0, 3.0], [0.0, 2.5], omega0=[1.0, 0.1, 0.5], method=f"{base}-plugged")
        ref = ep.solve([1.0, 2.0, 3.0], [0.0, 2.5], omega0=[1.0, 0.1, 0.5], method=base)
    finally:
        unregister_method(f"{base}-plugged")
    assert calls and calls[0] == hook
    if hook == "run":  # the subclass's result (its sign made continuous from t[0] by the trajectory: -q0 = -1)
        np.testing.assert_array_equal(got.quaternion, -ref.quaternion)
    else:
        np.testing.assert_array_equal(got.quaternion, ref.quaternion)
