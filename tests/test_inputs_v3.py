"""Issue 22, the inputs and the error lines: strict JSON, torques that float64 cannot hold, nested TOML,
the words of the command line, internal errors (exit 3) and the tests' own waits.

Each test runs the CLI in-process through ``eulerpoisson.cli.main(argv)`` unless it says otherwise.
"""

from __future__ import annotations

import dataclasses
import json
import math
import re
import warnings
from pathlib import Path

import numpy as np
import pytest

import eulerpoisson as ep
from _limits import HANG_GUARD_S
from eulerpoisson.cli import main
from eulerpoisson.cli.common import check_run_scales, json_text
from eulerpoisson.cli.config import build_torques, namer
from eulerpoisson.cli.main import is_bad_input
from eulerpoisson.errors import AuditError, InvalidInputError, UsageError
from eulerpoisson.solvers import engine

BASE = ["simulate", "--inertia", "1,2,3", "--omega", "1,0.1,0.5", "--t-end", "1", "--samples", "3"]


def run(capsys, *argv):
    code = main([str(a) for a in argv])
    out, err = capsys.readouterr()
    return code, out, err


def one_error(capsys, argv, match, code=2):
    """Run ``argv``: exit ``code``, one stderr line matching ``match``, nothing on stdout."""
    got, out, err = run(capsys, *argv)
    lines = err.strip().splitlines()
    assert got == code, (got, out, err)
    assert len(lines) == 1 and "Traceback" not in err, err
    assert re.search(match, lines[0]), lines[0]
    assert out == ""
    return lines[0]


def strict_loads(text: str):
    """``json.loads`` that refuses NaN and Infinity (RFC 8259 JSON, what other languages' parsers accept)."""

    def refuse(name):
        raise ValueError(f"not JSON: {name}")

    return json.loads(text, parse_constant=refuse)


def no_solve(monkeypatch):
    """Make any solve fail loudly: the checks under test must refuse the run before it starts."""

    def boom(*a, **k):
        raise AssertionError("the run was started; it should have been refused up front")

    monkeypatch.setattr(engine, "prepare_run", boom)


# ---------------------------------------------------------------------------
# item 10: --json is strict JSON; invariants that overflow are refused up front, with the range
# ---------------------------------------------------------------------------
@pytest.mark.parametrize(
    "inertia, omega",
    [("1e308,1e308,1e308", "1,0.1,0.5"), ("1,2,3", "1e160,0.1,0.5"), ("1e300,2e300,2.5e300", "1e10,1,1")],
)
def test_invariants_that_overflow_are_refused_with_the_range(capsys, monkeypatch, inertia, omega):
    # before: I = 1e308 printed {"m_norm": Infinity, ...} and exit 0 (invalid JSON)
    no_solve(monkeypatch)
    line = one_error(
        capsys,
        ["simulate", "--inertia", inertia, "--omega", omega, "--t-end", "1", "--json"],
        r"^eulerpoisson: error: the angular momentum \|m\| = \|I omega\| = .* of --inertia and --omega overflows "
        r"float64 .* keep \|I omega\| below 1\.3e\+154 and the energy below 1\.8e\+308",
    )
    assert "Infinity" not in line


def test_invariants_from_m_and_a_file_name_their_source(capsys, monkeypatch, tmp_path):
    no_solve(monkeypatch)
    cfg = tmp_path / "big.toml"
    cfg.write_text("[body]\ninertia = [1e-300, 2e-300, 2.5e-300]\n[initial]\nm = [1e300, 0, 0]\n[time]\nt_end = 1\n")
    one_error(capsys, ["simulate", str(cfg)], r"big\.toml: \[body\] inertia and .*big\.toml: \[initial\] m overflows")


def test_largest_invariants_that_fit_still_run(capsys):
    code, out, err = run(
        capsys, "simulate", "--inertia", "1,2,3", "--omega", "1e153,0,0", "--t-end", "1e-160", "--json"
    )
    assert code == 0, err
    d = strict_loads(out)
    assert d["m"][0] == 1e153


def test_json_text_is_strict_and_says_why_a_value_is_null():
    text = json_text({"a": float("nan"), "b": [1.0, np.float64(np.inf)], "c": {"d": -math.inf}, "n": np.int64(3)})
    d = strict_loads(text)
    assert d["a"] is None and d["b"] == [1.0, None] and d["c"] == {"d": None} and d["n"] == 3
    assert d["non_finite"] == {
        "a": "NaN: undefined in float64",
        "b[1]": "inf: overflows float64",
        "c.d": "-inf: overflows float64",
    }
    assert "non_finite" not in strict_loads(json_text({"x": 1.0}))


def test_simulate_json_is_strict_when_a_value_is_not_finite(capsys, monkeypatch):
    from eulerpoisson.cli import simulate

    real = simulate._state_json

    def with_nan(traj, drift):
        d = real(traj, drift)
        d["drift"]["m_norm"] = float("nan")
        d["integrals"]["m_norm"] = float("inf")
        return d

    monkeypatch.setattr(simulate, "_state_json", with_nan)
    code, out, err = run(capsys, *BASE, "--json")
    assert code == 0, err
    d = strict_loads(out)  # before: NaN and Infinity in the text
    assert d["drift"]["m_norm"] is None and d["integrals"]["m_norm"] is None
    assert set(d["non_finite"]) == {"drift.m_norm", "integrals.m_norm"}


def test_validate_json_is_strict_when_a_value_is_not_finite(capsys, monkeypatch, tmp_path):
    import eulerpoisson.oracle as oracle

    run_file = tmp_path / "r.nc"
    assert run(capsys, *BASE, "--out", run_file, "--quiet")[0] == 0
    real = oracle.validate

    def nan_drift(*a, **k):
        return dataclasses.replace(real(*a, **k), energy_drift=float("nan"))

    monkeypatch.setattr(oracle, "validate", nan_drift)
    code, out, err = run(capsys, "validate", run_file, "--json")
    assert code == 0, err
    d = strict_loads(out)
    assert d["energy_drift"] is None and d["non_finite"] == {"energy_drift": "NaN: undefined in float64"}


def test_fit_json_is_strict(capsys):
    root = Path(__file__).resolve().parents[1]
    data = root / "examples" / "tumbling_data" / "phone_toss_1.csv"
    code, out, err = run(capsys, "fit", data, "--sigma-omega", "0.2", "--json")
    assert code in (0, 1), err  # the verdict on the fit is not under test here: its JSON is
    strict_loads(out)


# ---------------------------------------------------------------------------
# item 12: torques that are not what they must be; a torque float64 cannot follow; nested TOML
# ---------------------------------------------------------------------------
@pytest.mark.parametrize(
    "func, match",
    [
        (lambda t, q, w: 0.1, r"returned shape \(\); expected \(3,\)"),  # before: 0.1 on every axis
        (lambda t, q, w: [0.1], r"returned shape \(1,\); expected \(3,\)"),
        (lambda t, q, w: (0.1 + 1j) * w, r"returned complex128 values; expected real numbers"),  # before: truncated
        (lambda t, q, w: w > 0, r"returned bool values; expected real numbers"),
    ],
)
def test_a_callable_torque_must_return_real_vectors(func, match):
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # no ComplexWarning on the way: refused before any cast
        with pytest.raises(InvalidInputError, match=r"the torque function CallableTorque\('<lambda>'\) " + match):
            ep.solve([1.0, 2.0, 2.5], [0.0, 1.0], omega0=[1.0, 0.1, 0.5], torque=func, method="rk")


def test_a_callable_torque_may_return_one_vector_for_a_batch():
    one = ep.solve(
        [1.0, 2.0, 2.5], [0.0, 1.0], omega0=[[1.0, 0.1, 0.5]] * 2, torque=lambda t, q, w: [0.0, 0.0, 0.1], method="rk"
    )
    ref = ep.solve([1.0, 2.0, 2.5], [0.0, 1.0], omega0=[1.0, 0.1, 0.5], torque=ep.torques.BodyTorque([0, 0, 0.1]))
    np.testing.assert_allclose(one.omega[0, -1], ref.omega[-1], atol=1e-7)


@pytest.mark.parametrize(
    "make, exc, match",
    [
        (lambda: ep.torques.BodyTorque(0.1), InvalidInputError, r"BodyTorque: tau must have shape \(\.\.\., 3\)"),
        (lambda: ep.torques.SpaceTorque([1j, 0, 0]), TypeError, r"SpaceTorque: tau must be real, got complex"),
        (lambda: ep.torques.Gravity(1.0, [0, 0, 0.1], 9.81), InvalidInputError, r"Gravity: g must have shape"),
        (lambda: ep.torques.GravityGradient(1j), TypeError, r"GravityGradient: mean_motion must be real"),
        (
            lambda: ep.torques.MagneticDipoleTorque(1.0, [0, 0, 1e-5]),
            InvalidInputError,
            r"MagneticDipoleTorque: dipole must have shape",
        ),
    ],
)
def test_torque_parameters_are_never_broadcast_from_a_scalar_nor_truncated(make, exc, match):
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        with pytest.raises(exc, match=match):
            make()


@pytest.mark.parametrize(
    "field, match",
    [(lambda t: [1j, 0.0, 0.0], r"returned complex128 values"), (lambda t: [True, False, False], r"returned bool")],
)
def test_a_callable_magnetic_field_must_return_real_vectors(field, match):
    tq = ep.torques.MagneticDipoleTorque([0.0, 0.0, 1.0], field)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        with pytest.raises(InvalidInputError, match=r"the magnetic field function .* " + match):
            tq.field_at(0.0)


@pytest.mark.parametrize(
    "flags, match",
    [
        # before: 10 s of integration, then "quaternion contains NaN or infinite values"
        (
            ["--gravity", "1e300,0,0", "--com", "0,0,0.1"],
            r"the torque gravity \(--com, --mass, --gravity\) is too strong for float64: .* by \|t\| = 1 the body "
            r"would turn through 7\.52e\+149 rad, beyond the 2\^48 .* use a weaker torque or a shorter --t-end",
        ),
        (
            ["--gravity", "1e300,0,0", "--com", "1e300,0,0.1"],
            r"the torque gravity \(--com, --mass, --gravity\) overflows float64",
        ),
        (["--gravity-gradient", "1e150"], r"the torque gravity gradient \(--gravity-gradient\) is too strong"),
        (
            ["--magnetic-dipole", "1e200,0,0", "--magnetic-field", "0,1e200,0"],
            r"the torque magnetic dipole \(--magnetic-dipole, --magnetic-field\) overflows float64",
        ),
        (["--body-torque", "1e10,0,0", "--t-end", "1e3"], r"the torque body torque \(--body-torque\) is too strong"),
    ],
)
def test_a_torque_float64_cannot_follow_is_refused_up_front(capsys, monkeypatch, flags, match):
    no_solve(monkeypatch)
    one_error(capsys, ["simulate", "--inertia", "1,2,3", "--omega", "1,0.1,0.5", "--t-end", "1", *flags], match)


def test_a_strong_torque_from_a_file_names_its_keys(capsys, monkeypatch, tmp_path):
    no_solve(monkeypatch)
    cfg = tmp_path / "top.toml"
    cfg.write_text(
        "[body]\ninertia = [1, 2, 3]\n[initial]\nomega = [1, 0.1, 0.5]\n[time]\nt_end = 1\n"
        "[torque]\ngravity = [1e300, 0, 0]\ncenter_of_mass = [0, 0, 0.1]\n"
    )
    one_error(capsys, ["simulate", str(cfg)], r"top\.toml: \[torque\] gravity.*is too strong for float64")


def test_torques_of_ordinary_size_pass_the_scale_check():
    body = ep.RigidBody([1.0, 2.0, 3.0])
    for cfg, t_end in (
        ({"torque.center_of_mass": "0,0,0.1"}, 1e4),
        ({"torque.gravity": "1e6,0,0", "torque.center_of_mass": "0,0,0.1"}, 1e3),
        ({"torque.gravity_gradient": "0.001"}, 6000.0),
        ({"torque.body_torque": "0,0,0.5"}, 1e4),
    ):
        check_run_scales(ep.Model(body, build_torques(cfg)), [1.0, 0.1, 0.5], None, None, t_end, namer({}))


@pytest.mark.parametrize("command", ["simulate", "sweep", "fit"])
def test_deeply_nested_toml_names_the_file(capsys, tmp_path, command):
    deep = tmp_path / "deep.toml"
    deep.write_text("a = " + "[" * 100_000 + "]" * 100_000 + "\n")  # tomllib: RecursionError
    one_error(capsys, [command, deep], r"deep\.toml: invalid TOML: nested too deeply")


def test_deeply_nested_observations_toml_names_the_file(tmp_path):
    from eulerpoisson.io.observations import read_observations

    deep = tmp_path / "obs.toml"
    deep.write_text("a = " + "[" * 100_000 + "]" * 100_000 + "\n")
    with pytest.raises(InvalidInputError, match=r"obs\.toml: invalid TOML: nested too deeply"):
        read_observations(deep)


# ---------------------------------------------------------------------------
# item 14: the command line speaks of flags, and names the program once
# ---------------------------------------------------------------------------
def test_unphysical_moments_name_the_flag(capsys):
    line = one_error(
        capsys,
        ["simulate", "--inertia", "1,2,5", "--omega", "1,1,1", "--t-end", "1"],
        r"triangle inequality .* \(run with --allow-unphysical to study",
    )
    assert "allow_unphysical=True" not in line


@pytest.mark.parametrize(
    "argv, expected",
    [
        (
            [*BASE, "--bogus"],
            "eulerpoisson: error: unrecognized arguments: --bogus (see 'eulerpoisson simulate --help')",
        ),
        (["--bogus"], "eulerpoisson: error: unrecognized arguments: --bogus (see 'eulerpoisson --help')"),
        (
            ["simulate", "--t-end"],
            "eulerpoisson: error: simulate: argument --t-end: expected one argument "
            "(see 'eulerpoisson simulate --help')",
        ),
    ],
)
def test_usage_errors_name_the_program_once(capsys, argv, expected):
    line = one_error(capsys, argv, r"^eulerpoisson: error: ")
    assert line == expected
    assert line.count("eulerpoisson") == 2  # the prefix and the --help hint, never "eulerpoisson: eulerpoisson"


# ---------------------------------------------------------------------------
# item 20: a bug is not the user's mistake: "internal error", the traceback saved, exit 3
# ---------------------------------------------------------------------------
def _raise_in_engine(monkeypatch, exc):
    def boom(*a, **k):
        raise exc

    monkeypatch.setattr(engine, "prepare_run", boom)


@pytest.mark.parametrize(
    "exc",
    [
        ValueError("too many values to unpack (expected 2)"),  # a bare ValueError from deep inside: a bug
        TypeError("unsupported operand type(s) for +: 'NoneType' and 'float'"),
        AttributeError("'NoneType' object has no attribute 'shape'"),
        RecursionError("maximum recursion depth exceeded"),
        AuditError("the exact and the random-point verdicts disagree"),
    ],
)
def test_unexpected_exceptions_are_internal_errors(capsys, monkeypatch, tmp_path, exc):
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "cache"))
    _raise_in_engine(monkeypatch, exc)
    line = one_error(capsys, BASE, r"^eulerpoisson: internal error: ", code=3)
    assert f"{type(exc).__name__}: {exc}" in line and line.endswith("; please report it)")
    saved = re.search(r"the traceback was saved to (.*); please report it\)$", line).group(1)
    assert Path(saved).parent == tmp_path / "cache" / "eulerpoisson" / "crashes"
    assert "Traceback (most recent call last)" in Path(saved).read_text()


@pytest.mark.parametrize(
    "exc",
    [
        InvalidInputError("omega0 must be finite"),
        UsageError("--t-end must be a finite number"),
        PermissionError(13, "Permission denied", "/x/out.nc"),
        NotImplementedError("the torque CallableTorque('f') was a Python function and was not saved in the file"),
    ],
)
def test_bad_input_stays_exit_2(capsys, monkeypatch, exc):
    _raise_in_engine(monkeypatch, exc)
    one_error(capsys, BASE, r"^eulerpoisson: error: ")
    assert is_bad_input(exc)


def test_out_of_memory_is_exit_2_with_advice(capsys, monkeypatch):
    # chosen: running out of memory is a limit of the machine, not a bug: exit 2 and what to do
    _raise_in_engine(monkeypatch, MemoryError())
    one_error(capsys, BASE, r"^eulerpoisson: error: out of memory \(.*fewer samples or bodies.*--out")


def test_the_traceback_goes_to_the_temporary_folder_when_the_cache_is_not_writable(capsys, monkeypatch, tmp_path):
    blocked = tmp_path / "file"
    blocked.write_text("not a folder")
    monkeypatch.setenv("XDG_CACHE_HOME", str(blocked))  # $XDG_CACHE_HOME/eulerpoisson cannot be made
    monkeypatch.setattr("tempfile.tempdir", str(tmp_path / "tmp"))
    (tmp_path / "tmp").mkdir()
    _raise_in_engine(monkeypatch, KeyError("x"))
    line = one_error(capsys, BASE, r"^eulerpoisson: internal error: KeyError: x \(a bug; the traceback", code=3)
    assert str(tmp_path / "tmp" / "eulerpoisson-crashes") in line


def test_debug_still_shows_the_traceback(monkeypatch):
    _raise_in_engine(monkeypatch, IndexError("index 3 is out of bounds"))
    with pytest.raises(IndexError):
        main([*BASE, "--debug"])


# ---------------------------------------------------------------------------
# item 19: no test fails because the machine is busy: every wait of the tests is a guard far above its quiet time
# ---------------------------------------------------------------------------
def test_every_wait_in_the_tests_is_a_guard_against_a_hang():
    """A literal limit of a subprocess or a wait in the tests is at least 600 s (HANG_GUARD_S is 1800 s).

    Before: ``timeout=120`` on a command that took longer on a loaded two-core machine
    (``test_a_closed_pipe_is_not_an_error`` failed with ``subprocess.TimeoutExpired``).
    """
    assert HANG_GUARD_S >= 600
    allowed = {"test_animate.py", Path(__file__).name}  # Chromium: a timeout skips the test; this file: its words
    short = []
    pattern = re.compile(r"\b(?:timeout\s*=\s*|time\.monotonic\(\)\s*\+\s*|for _ in range\()(\d+(?:\.\d*)?)")
    for path in sorted(Path(__file__).parent.glob("*.py")):
        if path.name in allowed:
            continue
        lines = path.read_text().splitlines()
        for n, line in enumerate(lines):
            for m in pattern.finditer(line):
                value = float(m.group(1))
                if "range(" in m.group(0):
                    if not any("time.sleep(" in after for after in lines[n + 1 : n + 5]):
                        continue  # a loop, not a poll
                    value *= 0.05  # the polls sleep 0.05 s a turn
                if value < 600:
                    short.append(f"{path.name}:{n + 1}: {line.strip()}")
    assert not short, "waits that a busy machine can exceed:\n" + "\n".join(short)
