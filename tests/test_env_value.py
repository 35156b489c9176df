"""util.env.env_value: os.environ.get without its exception, the same value whatever changed os.environ."""

import os

import pytest

import eulerpoisson as ep
from eulerpoisson.util.env import env_value
from eulerpoisson.util.jit import ENV_NUMPY_BELOW, numpy_below

NAME = "EULERPOISSON_TEST_ENV_VALUE"


def test_set_changed_and_unset_values_are_those_of_os_environ(monkeypatch):
    monkeypatch.delenv(NAME, raising=False)
    assert env_value(NAME) is None and os.environ.get(NAME) is None
    for value in ("1", "", " 2.5 ", "ünï", "x" * 1000):
        monkeypatch.setenv(NAME, value)
        assert env_value(NAME) == os.environ.get(NAME) == value
    os.environ.update({NAME: "via update"})
    assert env_value(NAME) == "via update"
    monkeypatch.delenv(NAME)
    assert env_value(NAME) is None


def test_the_settings_read_on_every_solve_follow_the_environment(monkeypatch):
    monkeypatch.setenv(ENV_NUMPY_BELOW, "0.125")
    assert numpy_below() == 0.125
    monkeypatch.setenv(ENV_NUMPY_BELOW, "-1")
    with pytest.raises(ValueError, match="EULERPOISSON_NUMPY_BELOW must be a number of seconds >= 0"):
        numpy_below()
    # the quick lane of solve (one body, one time) reads EULERPOISSON_WORKERS on every call too
    monkeypatch.delenv(ENV_NUMPY_BELOW)
    monkeypatch.setenv("EULERPOISSON_WORKERS", "many")
    with pytest.raises(ValueError, match="EULERPOISSON_WORKERS"):
        ep.solve([1.0, 2.0, 3.0], [1.0], omega0=[0.1, 0.2, 0.3])
    monkeypatch.delenv("EULERPOISSON_WORKERS")
    assert ep.solve([1.0, 2.0, 3.0], [1.0], omega0=[0.1, 0.2, 0.3]).omega.shape == (1, 3)
