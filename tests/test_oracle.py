"""The reference oracle: `eulerpoisson validate`, `eulerpoisson cases`, `eulerpoisson.testing` (issue 14)."""

import json
import re
import shlex

import numpy as np
import pytest

import eulerpoisson as ep
from eulerpoisson.attitude.core import matrix_from_unit_quaternion
from eulerpoisson.cli import main
from eulerpoisson.cli.oracle import CASES_EXAMPLES, VALIDATE_EXAMPLES
from eulerpoisson.errors import InvalidInputError
from eulerpoisson.oracle import CASE_NAMES, reference_case, run_from_arrays, validate
from eulerpoisson.testing import assert_free_motion, reference_cases

HEADER = "t,qw,qx,qy,qz,wx,wy,wz"


def run(capsys, *argv):
    code = main([str(a) for a in argv])
    out, err = capsys.readouterr()
    return code, out, err


def write_csv(path, t, q, w, header=HEADER):
    np.savetxt(path, np.column_stack([t, q, w]), delimiter=",", header=header, comments="", fmt="%.17g")
    return path


@pytest.fixture(scope="module")
def cases_dir(tmp_path_factory):
    d = tmp_path_factory.mktemp("cases")
    assert main(["cases", "--out", str(d), "--quiet"]) == 0
    return d


@pytest.fixture(scope="module")
def racket():
    """A racket run with a tilted start (body and space frames differ), sampled at 601 times."""
    t = np.linspace(0.0, 120.0, 601)
    tr = ep.solve([3.0, 5.0, 8.0], t, omega0=[0.004, 0.4, 0.0], attitude0=[0.8, 0.36, -0.48, 0.0])
    return tr.t, tr.quaternion, tr.omega


# --------------------------------------------------------------------------- cases round-trip
def test_cases_folder_has_csv_netcdf_readme(cases_dir):
    for name in CASE_NAMES:
        assert (cases_dir / f"{name}.csv").exists() and (cases_dir / f"{name}.nc").exists()
        assert (cases_dir / f"{name}.csv").read_text().splitlines()[0] == HEADER
    readme = (cases_dir / "README.md").read_text()
    assert all(f"`{n}`" in readme for n in CASE_NAMES) and "body** angular velocity" in readme
    index = json.loads((cases_dir / "cases.json").read_text())
    assert [c["name"] for c in index] == list(CASE_NAMES)
    sep = reference_case("tennis_racket_separatrix")
    k2c = ep.analysis.elliptic_parameters(sep.inertia, np.multiply(sep.inertia, sep.omega0))["k2c"]
    assert k2c == pytest.approx(1e-6, rel=1e-12)
    assert reference_case("long_run").t[-1] == 1e4


@pytest.mark.parametrize("ext", ["csv", "nc"])
def test_cases_round_trip_through_validate_at_round_off(capsys, cases_dir, ext):
    cases = reference_cases()
    for name in CASE_NAMES:
        c = cases[name]
        argv = ["validate", cases_dir / f"{name}.{ext}", "--json", "--tolerance", "1e-12"]
        if ext == "csv":
            argv += ["--inertia", c.inertia_flag()]
        code, out, err = run(capsys, *argv)
        assert code == 0, (name, err)
        rep = json.loads(out)
        assert rep["verdict"] == "pass" and rep["warnings"] == [] and rep["convention_hint"] is None, name
        assert rep["max_attitude_error"] < 1e-12 and rep["max_omega_error"] < 1e-12, (name, rep)
        assert rep["energy_drift"] < 1e-13 and rep["momentum_drift"] < 1e-12, (name, rep)
        if c.flips:
            assert len(rep["flip_times"]) >= 2, name
            assert max(abs(e) for e in rep["flip_time_errors"]) < 1e-9 * max(1.0, c.t_end), name
        if name in ("principal_axis_1", "principal_axis_3", "sphere", "symmetric_top", "fast_spin"):
            assert rep["flip_times"] is None, name  # not spun near an intermediate axis
        if name == "principal_axis_2":
            assert rep["flip_times"] == [] and rep["flip_times_run"] == [], name  # exactly on it: no flip


def test_reference_flips_are_the_closed_form_half_period():
    c = reference_case("tennis_racket_separatrix")
    rep = validate(run_from_arrays(c.t, c.quaternion, c.omega), c.inertia)
    half = ep.analysis.tennis_racket_half_period(c.inertia, np.multiply(c.inertia, c.omega0))
    assert np.allclose(np.diff(rep.flip_times), half, rtol=1e-10)
    assert rep.verdict == "round-off" and rep.passed


# --------------------------------------------------------------------------- conventions
def test_scalar_last_file_read_as_scalar_first_is_named(capsys, tmp_path, racket):
    t, q, w = racket
    bad = write_csv(tmp_path / "xyzw.csv", t, np.roll(q, -1, axis=1), w)  # labelled qw,qx,qy,qz, written x,y,z,w
    code, out, err = run(capsys, "validate", bad, "--inertia", "3,5,8", "--tolerance", "1e-6")
    assert code == 1
    assert re.search(r"the quaternions look scalar-last \(x, y, z, w\): rerun with --quaternion-order xyzw", out)
    code, out, err = run(
        capsys, "validate", bad, "--inertia", "3,5,8", "--tolerance", "1e-9", "--quaternion-order", "xyzw"
    )
    assert code == 0 and "PASS" in out
    # the column names may say the order themselves
    good = write_csv(tmp_path / "named.csv", t, np.roll(q, -1, axis=1), w, header="t,qx,qy,qz,qw,wx,wy,wz")
    code, out, err = run(capsys, "validate", good, "--inertia", "3,5,8", "--tolerance", "1e-9", "--json")
    assert code == 0 and json.loads(out)["conventions"]["quaternion_order"] == "xyzw"


def test_space_frame_rates_read_as_body_frame_are_named(capsys, tmp_path, racket):
    t, q, w = racket
    ws = np.einsum("tij,tj->ti", matrix_from_unit_quaternion(q), w)
    bad = write_csv(tmp_path / "space.csv", t, q, ws)
    code, out, err = run(capsys, "validate", bad, "--inertia", "3,5,8", "--json")
    rep = json.loads(out)
    assert code == 0 and rep["verdict"] == "differs"
    assert rep["convention_hint"] == "the angular velocities look space-frame: rerun with --omega-frame space"
    assert rep["max_attitude_error"] > 0.1  # O(1) at once
    code, out, err = run(capsys, "validate", bad, "--inertia", "3,5,8", "--omega-frame", "space", "--tolerance", "1e-9")
    assert code == 0


def test_space_to_body_attitudes_are_named(capsys, tmp_path, racket):
    t, q, w = racket
    bad = write_csv(tmp_path / "conj.csv", t, q * [1, -1, -1, -1], w)
    code, out, err = run(capsys, "validate", bad, "--inertia", "3,5,8", "--tolerance", "1e-6")
    assert code == 1 and "rerun with --attitude-convention space-to-body" in out
    code, out, err = run(
        capsys, "validate", bad, "--inertia", "3,5,8", "--tolerance", "1e-9", "--attitude-convention", "space-to-body"
    )
    assert code == 0


def test_two_mismatches_at_once_are_both_named(racket):
    t, q, w = racket
    ws = np.einsum("tij,tj->ti", matrix_from_unit_quaternion(q), w)
    rep = validate(run_from_arrays(t, np.roll(q, -1, axis=1), ws), [3, 5, 8])
    assert rep.convention_hint.endswith("rerun with --quaternion-order xyzw --omega-frame space")


def test_wrong_inertia_is_only_a_warning(capsys, tmp_path, racket):
    t, q, w = racket
    f = write_csv(tmp_path / "r.csv", t, q, w)
    code, out, err = run(capsys, "validate", f, "--inertia", "1,2,2.5")
    assert code == 0
    assert re.search(
        r"warning: the run's energy and angular momentum are conserved as those of an inertia close to "
        r"\[1\.03\d*, 1\.71\d*, 2\.75\].*check --inertia",
        err,
    )


# --------------------------------------------------------------------------- input formats, report, plot
def test_json_records_and_netcdf_and_plot(capsys, tmp_path, racket):
    t, q, w = racket
    recs = [dict(zip(HEADER.split(","), map(float, row))) for row in np.column_stack([t, q, w])]
    (tmp_path / "r.json").write_text(json.dumps(recs))
    code, out, err = run(capsys, "validate", tmp_path / "r.json", "--inertia", "3,5,8", "--json")
    assert code == 0 and json.loads(out)["verdict"] == "round-off"
    (tmp_path / "r2.json").write_text(
        json.dumps([{"t": a, "quaternion": b.tolist(), "omega": c.tolist()} for a, b, c in zip(t, q, w)])
    )
    code, out, err = run(capsys, "validate", tmp_path / "r2.json", "--inertia", "3,5,8", "--plot", tmp_path / "e.png")
    assert code == 0 and "ROUND-OFF" in out and "flips (exact)" in out
    assert (tmp_path / "e.png").stat().st_size > 10_000


def test_report_keys_and_perturbed_run(racket):
    t, q, w = racket
    q2 = q.copy()
    q2[300:] = ep.attitude.quaternion_multiply(q[300:], [np.cos(5e-4), np.sin(5e-4), 0.0, 0.0])  # 1e-3 rad
    rep = validate(run_from_arrays(t, q2, w), [3, 5, 8], tolerance=1e-4)
    d = rep.to_dict()
    for key in (
        "max_attitude_error",
        "max_omega_error",
        "energy_drift",
        "momentum_drift",
        "flip_times",
        "flip_time_errors",
        "exceeded_at",
        "verdict",
        "convention_hint",
        "warnings",
    ):
        assert key in d
    assert d["max_attitude_error"] == pytest.approx(1e-3, rel=1e-9)
    assert d["exceeded_at"] == t[300] and d["verdict"] == "fail" and not rep.passed
    json.dumps(d)


@pytest.mark.parametrize(
    "content, match",
    [
        ("t,qw,qx,qy,wx,wy,wz\n0,1,0,0,0,0,0\n1,1,0,0,0,0,0\n", r"missing column\(s\) qz"),
        ("t,qw,qx,qy,qz,wx,wy\n0,1,0,0,0,0,0\n", r"missing column\(s\) wz"),
        (
            HEADER + "\n0,1,0,0,0,0,0.1,0\n2,1,0,0,0,0,0.1,0\n1,1,0,0,0,0,0.1,0\n",
            r"times must increase strictly; sample 2 has t = 1.0 after t = 2.0",
        ),
        (HEADER + "\n0,1,0,0,0,0,0.1,0\n1,1.1,0,0,0,0,0.1,0\n", r"sample 1 \(t = 1\) has norm 1.1, far from 1"),
        (HEADER + "\n0,1,0,0,0,0,0.1,0\n1,1,0,x,0,0,0.1,0\n", r"row 3, column qy: 'x' is not a number"),
        (HEADER + "\n0,1,0,0,0,0,0.1,0\n", r"at least 2 samples"),
        (HEADER + "\n0,1,0,0,0,0,0.1,0\n1,1,0,0,0,0,nan,0\n", r"not finite"),
    ],
)
def test_bad_runs_are_one_line_exit_2(capsys, tmp_path, content, match):
    f = tmp_path / "bad.csv"
    f.write_text(content)
    code, out, err = run(capsys, "validate", f, "--inertia", "3,5,8")
    assert code == 2 and len(err.strip().splitlines()) == 1 and "Traceback" not in err
    assert re.search(match, err), err


@pytest.mark.parametrize(
    "argv, match",
    [
        (["validate", "nope.csv", "--inertia", "3,5,8"], "nope.csv: no such file"),
        (["validate", "{csv}"], r"give the body's inertia with --inertia"),
        (["validate", "{csv}", "--inertia", "3,5"], "expected 3 or 9 numbers"),
        (["validate", "{csv}", "--inertia", "1,1,3"], "triangle inequality"),
        (["validate", "{csv}", "--inertia", "3,5,8", "--tolerance", "-1"], "--tolerance must be a positive number"),
        (["validate", "{csv}", "--inertia", "3,5,8", "--quaternion-order", "zyxw"], "invalid choice: 'zyxw'"),
        (["validate", "{txt}", "--inertia", "3,5,8"], r"unknown file type '.dat'"),
        (["cases", "--out", "{dir}", "--only", "sphere,cube"], r"--only: unknown case\(s\) cube"),
        (["cases"], "the following arguments are required: --out"),
        (["cases", "--out", "{csv}"], "is a file; give a folder"),
    ],
)
def test_usage_errors_are_one_line_exit_2(capsys, tmp_path, racket, argv, match):
    csv = write_csv(tmp_path / "r.csv", *racket)
    (tmp_path / "r.dat").write_text("x")
    argv = [a.format(csv=csv, txt=tmp_path / "r.dat", dir=tmp_path / "c") for a in argv]
    code, out, err = run(capsys, *argv)
    assert code == 2 and len(err.strip().splitlines()) == 1, err
    assert re.search(match, err), err


def test_validate_and_cases_help_show_the_oracle_examples(capsys):
    """``validate --help`` and ``cases --help`` show the examples of eulerpoisson.cli.oracle, which
    tests/test_issue12_help_examples.py runs (with every other help example, once per test run) and whose files
    it checks (``racket_error.png``; ``cases_csv/sphere.csv``, no ``sphere.nc``)."""
    from test_issue12_help_examples import EXAMPLES

    for cmd, listed in (("validate", VALIDATE_EXAMPLES), ("cases", CASES_EXAMPLES)):
        code, out, err = run(capsys, cmd, "--help")
        assert code == 0 and "examples:" in out
        assert EXAMPLES[cmd] == list(listed)
    for example in CASES_EXAMPLES + VALIDATE_EXAMPLES:
        assert shlex.split(example)[0] == "eulerpoisson"


# --------------------------------------------------------------------------- eulerpoisson.testing
def test_assert_free_motion_passes_and_fails_with_the_first_time(racket):
    t, q, w = racket
    rep = assert_free_motion(t, q, w, [3, 5, 8], atol=1e-12)
    assert rep.verdict == "pass"
    assert_free_motion(t, np.roll(q, -1, axis=1), w, [3, 5, 8], atol=1e-12, quaternion_order="xyzw")
    ws = np.einsum("tij,tj->ti", matrix_from_unit_quaternion(q), w)
    assert_free_motion(t, q, ws, [3, 5, 8], atol=1e-12, omega_frame="space", omega_rtol=1e-12)
    q2 = q.copy()
    q2[200:] = ep.attitude.quaternion_multiply(q[200:], [np.cos(1e-3), 0.0, np.sin(1e-3), 0.0])
    with pytest.raises(
        AssertionError,
        match=rf"attitude error is 0.002 rad > atol = 0.0001 first at t = {t[200]:.9g} "
        r"\(sample 200\)",
    ):
        assert_free_motion(t, q2, w, [3, 5, 8], atol=1e-4)
    with pytest.raises(AssertionError, match=r"rerun with --omega-frame space"):
        assert_free_motion(t, q, ws, [3, 5, 8], atol=1e-4)
    w2 = w.copy()
    w2[100:] *= [1.0, 1.01, 1.0]
    with pytest.raises(
        AssertionError,
        match=r"relative angular velocity error is 0.0\d+ > omega_rtol = 0.001 first at "
        rf"t = {t[100]:.9g} \(sample 100\)",
    ):
        assert_free_motion(t, q, w2, [3, 5, 8], atol=10.0, omega_rtol=1e-3)


def test_assert_free_motion_bad_input_is_not_an_assertion(racket):
    t, q, w = racket
    with pytest.raises(InvalidInputError, match="times must increase strictly"):
        assert_free_motion(t[::-1], q, w, [3, 5, 8], atol=1e-6)
    with pytest.raises(InvalidInputError, match="far from 1"):
        assert_free_motion(t, 2 * q, w, [3, 5, 8], atol=1e-6)
    with pytest.raises(InvalidInputError, match="tolerance must be a positive number"):
        assert_free_motion(t, q, w, [3, 5, 8], atol=0.0)
    with pytest.raises(InvalidInputError, match="omega_frame must be one of 'body', 'space'"):
        assert_free_motion(t, q, w, [3, 5, 8], atol=1e-6, omega_frame="world")


def test_reference_cases_as_python_objects():
    cases = reference_cases()
    assert tuple(cases) == CASE_NAMES and len(CASE_NAMES) == 11
    c = cases["full_tensor"]
    assert np.asarray(c.inertia).shape == (3, 3) and c.quaternion.shape == (2001, 4)
    assert_free_motion(c.t, c.quaternion, c.omega, c.inertia, atol=1e-12)
    with pytest.raises(InvalidInputError, match="unknown reference case 'cube'"):
        reference_case("cube")
    assert ep.testing.assert_free_motion is assert_free_motion


def test_a_run_that_starts_later_is_compared_from_its_first_sample(racket):
    t, q, w = racket
    later = validate(run_from_arrays(t[100:] + 1000.0, q[100:], w[100:]), [3, 5, 8], tolerance=1e-12)
    whole = validate(run_from_arrays(t, q, w), [3, 5, 8])
    assert later.verdict == "pass" and later.t_start == t[100] + 1000.0
    kept = [f for f in whole.flip_times if f > t[100]]
    assert np.allclose(np.array(later.flip_times) - 1000.0, kept, rtol=0, atol=1e-9)


def test_oracle_outputs_follow_the_output_policy(tmp_path, capsys):
    from eulerpoisson.cli import main

    out = tmp_path / "cases"
    assert main(["cases", "--out", str(out), "--only", "sphere", "--csv-only", "--quiet"]) == 0
    assert main(["cases", "--out", str(out), "--only", "sphere", "--csv-only", "--quiet"]) == 2
    assert "run again with --overwrite" in capsys.readouterr().err
    assert main(["cases", "--out", str(out), "--only", "sphere", "--csv-only", "--quiet", "--overwrite"]) == 0
    other = tmp_path / "mine"
    other.mkdir()
    (other / "notes.txt").write_text("keep")
    assert main(["cases", "--out", str(other), "--only", "sphere", "--overwrite"]) == 2
    assert "not a folder of cases" in capsys.readouterr().err and (other / "notes.txt").read_text() == "keep"
    run = next(out.glob("*.csv"))
    assert main(["validate", str(run), "--inertia", "1,1,1", "--plot", str(run), "--overwrite"]) == 2
    assert "it is an input of this command" in capsys.readouterr().err
