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
