"""The command line on bad input: one line on stderr, exit status 2, nothing ignored or coerced.

Each test runs the CLI in-process through ``eulerpoisson.cli.main(argv)``.
"""

import errno
import json
import os
import re
import warnings

import numpy as np
import pytest

import eulerpoisson as ep
from eulerpoisson.cli import commands as cli
from eulerpoisson.cli import main
from eulerpoisson.errors import EulerPoissonError, InvalidInputError
from eulerpoisson.io.atomic import atomic_path, atomic_write_text
from eulerpoisson.solvers import engine

BASE = ["simulate", "--inertia", "1,2,3", "--omega", "1,0.1,0.5", "--t-end", "1", "--samples", "3"]


def run(capsys, *argv):
    code = main(list(argv))
    out, err = capsys.readouterr()
    return code, out, err


def one_error(capsys, argv, match):
    """Run ``argv``; assert exit status 2, one stderr line matching ``match``, no traceback, no stdout."""
    code, out, err = run(capsys, *argv)
    lines = err.strip().splitlines()
    assert code == 2, (code, out, err)
    assert len(lines) == 1, err
    assert "Traceback" not in err
    assert lines[0].startswith("eulerpoisson: error: "), lines[0]  # every error line starts the same way
    msg = lines[0][len("eulerpoisson: error: ") :]
    assert re.search(match, lines[0]) or re.search(match, msg), lines[0]
    assert out == ""
    return lines[0]


def ok_json(capsys, *argv):
    code, out, err = run(capsys, *argv)
    assert code == 0, err
    assert err == ""
    return json.loads(out)


def toml(tmp_path, text, name="run.toml"):
    p = tmp_path / name
    p.write_text(text)
    return str(p)


GOOD = "[body]\ninertia = [1, 2, 3]\n[initial]\nomega = [1, 0.1, 0.5]\n[time]\nt_end = 1\nsamples = 3\n"


# ---------------------------------------------------------------------------
# 1. conflicting flags
# ---------------------------------------------------------------------------
@pytest.mark.parametrize(
    "extra, match",
    [
        (["--m", "0,0,1"], r"exactly one of --omega and --m"),
        (["--quaternion", "1,0,0,0", "--gibbs", "0,0,1"], r"at most one of --quaternion and --gibbs"),
    ],
)
def test_conflicting_flags_are_errors(capsys, extra, match):
    one_error(capsys, BASE + extra, match)


@pytest.mark.parametrize(
    "initial, match",
    [
        ("omega = [1, 0.1, 0.5]\nm = [1, 0, 0]", r"run\.toml: give exactly one of \[initial\] omega and \[initial\] m"),
        (
            "omega = [1, 0.1, 0.5]\nquaternion = [1, 0, 0, 0]\ngibbs = [0, 0, 1]",
            r"run\.toml: give at most one of \[initial\] quaternion and \[initial\] gibbs",
        ),
    ],
)
def test_self_contradicting_file_is_an_error_even_with_a_flag(capsys, tmp_path, initial, match):
    cfg = toml(tmp_path, f"[body]\ninertia = [1, 2, 3]\n[initial]\n{initial}\n[time]\nt_end = 1\n")
    one_error(capsys, ["simulate", cfg], match)
    one_error(capsys, ["simulate", cfg, "--m", "1,0,0", "--gibbs", "0,0,1"], match)


def test_file_and_body_both(capsys, tmp_path):
    cfg = toml(tmp_path, "[body]\ninertia = [1, 2, 3]\nmasses = [1, 1, 1]\npositions = [[0,0,0],[1,0,0],[0,1,0]]\n")
    one_error(capsys, ["simulate", cfg], r"run\.toml: give either \[body\] inertia or \[body\] (masses|positions)")


def test_a_flag_replaces_the_files_initial_condition(capsys, tmp_path):
    # the file gives omega, the flag gives m: the run uses m (and only m), as documented ("flags override the file")
    cfg = toml(tmp_path, GOOD)
    d = ok_json(capsys, "simulate", cfg, "--m", "0.5,1,0.2", "--json")
    np.testing.assert_allclose(d["m"], [0.5, 1.0, 0.2], atol=1e-13)
    # and the file's quaternion is replaced by --gibbs
    cfg2 = toml(tmp_path, GOOD.replace("[time]", "quaternion = [0, 1, 0, 0]\n[time]"), name="q.toml")
    d = ok_json(capsys, "simulate", cfg2, "--gibbs", "0.1,0.2,0.3", "--t-end", "0", "--json")
    q = np.array(d["quaternion"])
    np.testing.assert_allclose(q[1:] / q[0], [0.1, 0.2, 0.3], rtol=1e-13)


# ---------------------------------------------------------------------------
# 2. TOML values: honoured, never coerced
# ---------------------------------------------------------------------------
def test_toml_output_json_is_honoured(capsys, tmp_path):
    cfg = toml(tmp_path, GOOD + "[output]\njson = true\n")
    d = ok_json(capsys, "simulate", cfg)
    ref = ep.solve([1, 2, 3], [0.0, 1.0], omega0=[1, 0.1, 0.5])
    np.testing.assert_allclose(d["omega"], ref.omega[-1], atol=1e-13)
    cfg = toml(tmp_path, GOOD + "[output]\njson = false\n", name="nojson.toml")
    code, out, err = run(capsys, "simulate", cfg)
    assert code == 0 and out.startswith("exact:")
    one_error(
        capsys,
        ["simulate", toml(tmp_path, GOOD + "[output]\njson = 1\n", name="j.toml")],
        r"j\.toml: \[output\] json must be true or false, got 1",
    )


def test_toml_3x3_inertia_table_equals_nine_numbers(capsys, tmp_path):
    table = GOOD.replace("inertia = [1, 2, 3]", "inertia = [[2, 0.1, 0], [0.1, 3, 0], [0, 0, 4]]")
    a = ok_json(capsys, "simulate", toml(tmp_path, table), "--json")
    b = ok_json(
        capsys,
        "simulate",
        "--inertia",
        "2,0.1,0,0.1,3,0,0,0,4",
        "--omega",
        "1,0.1,0.5",
        "--t-end",
        "1",
        "--samples",
        "3",
        "--json",
    )
    assert a["quaternion"] == b["quaternion"] and a["omega"] == b["omega"]


def test_toml_integer_order_is_used(capsys, tmp_path):
    cfg = toml(tmp_path, GOOD + '[method]\nname = "taylor"\norder = 12\n')
    d = ok_json(capsys, "simulate", cfg, "--json")
    ref = ep.solve([1, 2, 3], [0.0, 1.0], omega0=[1, 0.1, 0.5])
    np.testing.assert_allclose(d["omega"], ref.omega[-1], atol=1e-10)


@pytest.mark.parametrize(
    "old, new, match",
    [
        (
            "samples = 3",
            'samples = 3\n[method]\nname = "taylor"\norder = true',
            r"\[method\] order must be an integer, got true",
        ),
        (
            "samples = 3",
            'samples = 3\n[method]\nname = "taylor"\norder = 7.9',
            r"\[method\] order must be an integer, got 7\.9",
        ),
        (
            "samples = 3",
            'samples = 3\n[method]\nname = "taylor"\norder = "abc"',
            r"\[method\] order must be an integer, got \"abc\"",
        ),
        ("samples = 3", "samples = 3.9", r"\[time\] samples must be an integer, got 3\.9"),
        ("samples = 3", "samples = 8.0", r"\[time\] samples must be an integer, got 8\.0"),
        ("samples = 3", 'samples = "7"', r"\[time\] samples must be an integer"),
        ("samples = 3", "samples = 1", r"\[time\] samples must be an integer >= 2, got 1"),
        ("t_end = 1", "t_end = true", r"\[time\] t_end must be a number, got true"),
        ("t_end = 1", 't_end = "1e3"', r"\[time\] t_end must be a number, got \"1e3\""),
        ("t_end = 1", "t_end = nan", r"\[time\] t_end must be a finite number \(negative: backwards in time\)"),
        ("t_end = 1", "t_end = inf", r"\[time\] t_end must be a finite number \(negative: backwards in time\)"),
        ("inertia = [1, 2, 3]", "inertia = [[1, 2], [3]]", r"\[body\] inertia must be 3 numbers .*3x3 table"),
        ("inertia = [1, 2, 3]", 'inertia = [1, "2", 3]', r"\[body\] inertia must be 3 numbers"),
        ("inertia = [1, 2, 3]", "inertia = [1, true, 3]", r"\[body\] inertia must be 3 numbers"),
        ("inertia = [1, 2, 3]", "inertia = 5", r"\[body\] inertia must be 3 numbers"),
        ("inertia = [1, 2, 3]", "inertia = [1, 2]", r"\[body\] inertia: expected 3 or 9 numbers, got 2"),
        ("omega = [1, 0.1, 0.5]", "omega = [[1, 0.1, 0.5]]", r"\[initial\] omega must be a list of numbers"),
        ("omega = [1, 0.1, 0.5]", "omega = [1, 0.1, nan]", r"\[initial\] omega: values must be finite"),
        ("[time]", "name = [1, 2]\n[time]", r"unknown key\(s\) name in \[initial\]"),
        ("inertia = [1, 2, 3]", "inertia = [1, 2, 3]\nname = [1, 2]", r"\[body\] name must be a string, got \[1, 2\]"),
        ("samples = 3", "samples = 3\n[method]\nname = 5", r"\[method\] name must be a string, got 5"),
        (
            "samples = 3",
            'samples = 3\n[method]\nname = "rk"\nintegrator = 5',
            r"\[method\] integrator must be a string",
        ),
        ("samples = 3", 'samples = 3\n[method]\nname = "rk"\nrtol = -1', r"\[method\] rtol must be a positive number"),
        (
            "samples = 3",
            'samples = 3\n[method]\nname = "rk"\ntol = false',
            r"\[method\] tol must be a number, got false",
        ),
        ("samples = 3", "samples = 3\n[output]\nfile = 5", r"\[output\] file must be a string, got 5"),
        ("samples = 3", 'samples = 3\n[output]\nfile = ""', r"\[output\] file: empty file name"),
    ],
)
def test_toml_values_are_checked_and_named(capsys, tmp_path, old, new, match):
    assert old in GOOD
    cfg = toml(tmp_path, GOOD.replace(old, new, 1))
    line = one_error(capsys, ["simulate", cfg], match)
    assert "run.toml" in line


@pytest.mark.parametrize(
    "body, match",
    [
        ('masses = "abc"\npositions = [[0,0,0],[1,0,0],[0,1,0]]', r"\[body\] masses must be a list of numbers"),
        ("masses = [1, 1, 1]\npositions = [[0,0,0],[1,0],[0,1,0]]", r"\[body\] positions must be a list of points"),
        (
            "masses = [1, 1, 1]\npositions = [[0,0,0],[1,0,0]]",
            r"run\.toml: \[body\] masses has 3 entries but \[body\] positions has 2 points",
        ),
    ],
)
def test_toml_point_masses_are_checked(capsys, tmp_path, body, match):
    cfg = toml(tmp_path, f"[body]\n{body}\n[initial]\nomega = [1, 0.1, 0.5]\n[time]\nt_end = 1\n")
    one_error(capsys, ["simulate", cfg], match)


def test_non_utf8_toml_names_the_file(capsys, tmp_path):
    p = tmp_path / "binary.toml"
    p.write_bytes(b"\xff\xfe[body]\n")
    one_error(capsys, ["simulate", str(p)], r"binary\.toml: not UTF-8 text \(byte 0xff at position 0\)")
    one_error(capsys, ["sweep", str(p)], r"binary\.toml: not UTF-8 text")


def test_config_that_is_a_directory_or_empty_name(capsys, tmp_path):
    one_error(capsys, ["simulate", str(tmp_path)], r"is not a file")
    one_error(capsys, ["simulate", ""], r"empty file name")


# ---------------------------------------------------------------------------
# 3. no traceback, whatever escapes a command
# ---------------------------------------------------------------------------
@pytest.mark.parametrize(
    "exc, match",
    [
        (
            MemoryError("Unable to allocate 745. GiB"),
            r"^eulerpoisson: error: out of memory: Unable to allocate 745\. GiB \(.*fewer samples or bodies.*\.zarr",
        ),
        (OverflowError(34, "Numerical result out of range"), r"^eulerpoisson: error: numerical overflow: "),
        (InvalidInputError("omega0 is odd\nsecond line"), r"^eulerpoisson: error: omega0 is odd$"),
        (FileNotFoundError(2, "No such file or directory", "x.nc"), r"^eulerpoisson: error: .*x\.nc"),
    ],
)
def test_bad_input_and_machine_limits_are_one_line_exit_2(capsys, monkeypatch, exc, match):
    def boom(*a, **k):
        raise exc

    monkeypatch.setattr(engine, "prepare_run", boom)  # the one engine every route runs
    one_error(capsys, BASE, match)
    with pytest.raises(type(exc)):
        main(BASE + ["--debug"])  # --debug shows the traceback


@pytest.mark.parametrize(
    "exc, match",
    [
        (ZeroDivisionError("float division by zero"), r"ZeroDivisionError: float division by zero"),
        (KeyError("no variable named 'inertia'"), r"KeyError: no variable named 'inertia'"),
        (RuntimeError("something odd\nsecond line"), r"RuntimeError: something odd"),
        (AssertionError(), r"AssertionError: AssertionError"),
        (IndexError("index 3 is out of bounds"), r"IndexError: index 3 is out of bounds"),
        (ValueError("not enough values to unpack (expected 3, got 2)"), r"ValueError: not enough values to unpack"),
    ],
)
def test_any_unexpected_exception_is_one_line_internal_error_exit_3(capsys, monkeypatch, tmp_path, exc, match):
    # issue 22 (20): a bug must not look like the user's mistake: "internal error", the traceback saved, exit 3
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "cache"))

    def boom(*a, **k):
        raise exc

    monkeypatch.setattr(engine, "prepare_run", boom)  # the one engine every route runs
    code, out, err = run(capsys, *BASE)
    lines = err.strip().splitlines()
    assert code == 3 and out == "" and len(lines) == 1 and "Traceback" not in err, (code, err)
    m = re.fullmatch(
        r"eulerpoisson: internal error: (.*) \(a bug; the traceback was saved to (.*); please report it\)", lines[0]
    )
    assert m and re.match(match, m.group(1)), lines[0]
    saved = m.group(2)
    assert saved.startswith(str(tmp_path / "cache" / "eulerpoisson")), saved
    text = open(saved, encoding="utf-8").read()
    assert "Traceback (most recent call last)" in text and type(exc).__name__ in text and "simulate" in text
    with pytest.raises(type(exc)):
        main(BASE + ["--debug"])  # --debug shows the traceback


def test_absurd_sample_count_is_one_line(capsys):
    # numpy refuses 1e30 samples before allocating anything (a 1e11 sample run, 745 GiB, raises MemoryError
    # on most machines, but with memory overcommit it could start, so it is not run here)
    one_error(capsys, BASE[:-1] + ["1" + "0" * 30], r"^eulerpoisson: error: ")


# ---------------------------------------------------------------------------
# 4. warnings are silenced (unless --debug), and the filters are restored
# ---------------------------------------------------------------------------
def test_warnings_do_not_reach_stderr(capsys, monkeypatch):
    def noisy(*a, **k):
        for _ in range(5):
            warnings.warn("overflow encountered in multiply", RuntimeWarning, stacklevel=1)
        np.float64(1e308) * 10  # a real numpy warning too
        raise InvalidInputError("omega0 is too large")

    monkeypatch.setattr(engine, "prepare_run", noisy)  # the one engine every route runs
    before = list(warnings.filters)
    env_before = os.environ.get("PYTHONWARNINGS")
    one_error(capsys, BASE, r"^eulerpoisson: error: omega0 is too large$")
    assert warnings.filters == before
    assert os.environ.get("PYTHONWARNINGS") == env_before


def test_real_overflow_is_one_line(capsys):
    one_error(
        capsys,
        ["simulate", "--inertia", "1,2,3", "--omega", "1e200,0.1,0.5", "--t-end", "1"],
        r"^eulerpoisson: error: ",
    )


def test_debug_shows_warnings(capsys, monkeypatch):
    def noisy(*a, **k):
        warnings.warn("look at me", RuntimeWarning, stacklevel=1)
        raise InvalidInputError("bad")

    monkeypatch.setattr(engine, "prepare_run", noisy)  # the one engine every route runs
    with warnings.catch_warnings(record=True) as rec:
        warnings.simplefilter("always")
        with pytest.raises(InvalidInputError):
            main(BASE + ["--debug"])
    assert any("look at me" in str(w.message) for w in rec)


# ---------------------------------------------------------------------------
# 5. --debug anywhere
# ---------------------------------------------------------------------------
@pytest.mark.parametrize("where", [0, 1, len(BASE)])
def test_debug_is_accepted_anywhere(capsys, where):
    argv = BASE[:where] + ["--debug"] + BASE[where:] + ["--json"]
    d = ok_json(capsys, *argv)
    assert d["t"] == 1.0


def test_debug_after_subcommand_raises_the_error():
    with pytest.raises(cli.UsageError, match="t-end must be a finite number"):
        main(["simulate", "--inertia", "1,2,3", "--omega", "1,0,0", "--t-end", "-inf", "--debug"])


# ---------------------------------------------------------------------------
# 6. values that begin with '-'
# ---------------------------------------------------------------------------
def test_negative_vectors_are_values(capsys):
    d = ok_json(
        capsys,
        "simulate",
        "--inertia",
        "1,2,3",
        "--omega",
        "-1,0.1,0.5",
        "--quaternion",
        "-0.6,0,0.8,0",
        "--t-end",
        "2",
        "--samples",
        "3",
        "--json",
    )
    ref = ep.solve([1, 2, 3], [0.0, 2.0], omega0=[-1, 0.1, 0.5], attitude0=[-0.6, 0, 0.8, 0])
    np.testing.assert_allclose(d["omega"], ref.omega[-1], atol=1e-13)
    np.testing.assert_allclose(abs(np.dot(d["quaternion"], ref.quaternion[-1])), 1.0, atol=1e-13)
    d = ok_json(
        capsys,
        "simulate",
        "--inertia",
        "1,2,3",
        "--m",
        "-0.5,1,-0.2",
        "--gibbs",
        "-0.1,0.2,-0.3",
        "--t-end",
        "0",
        "--samples",
        "2",
        "--json",
    )
    np.testing.assert_allclose(d["m"], [-0.5, 1.0, -0.2], atol=1e-13)
    q = np.array(d["quaternion"])
    np.testing.assert_allclose(q[1:] / q[0], [-0.1, 0.2, -0.3], rtol=1e-13)
    # an abbreviated option works too (argparse allows unique prefixes)
    d2 = ok_json(
        capsys, "simulate", "--inertia", "1,2,3", "--ome", "-1,0.1,0.5", "--t-end", "2", "--samples", "3", "--json"
    )
    np.testing.assert_allclose(d2["omega"], ref.omega[-1], atol=1e-13)


@pytest.mark.parametrize(
    "flag, value, match",
    [
        ("--t-end", "-inf", r"^--t-end must be a finite number \(negative: backwards in time\), got '-inf'$"),
        ("--samples", "-3", r"^--samples must be an integer >= 2, got -3$"),
        ("--tol", "-1e-9", r"^--tol must be a positive number, got '-1e-9'$"),
        ("--dt", "-0.1", r"^--dt must be a positive number"),
        ("--inertia", "-1,2,3", r"inertia|principal|positive"),
        ("--omega", "-x,0,0", r"^--omega: '-x' is not a number"),
    ],
)
def test_negative_scalars_reach_their_checks(capsys, flag, value, match):
    opts = {"--inertia": "1,2,3", "--omega": "1,0.1,0.5", "--t-end": "1", "--samples": "3", flag: value}
    argv = ["simulate"] + [x for kv in opts.items() for x in kv]
    line = one_error(capsys, argv, match)
    assert "expected one argument" not in line


def test_prepare_argv_glues_only_value_options():
    parser = cli.build_parser()
    prep = cli._prepare_argv
    assert prep(["simulate", "--omega", "-1,2,3", "--debug", "--json"], parser) == [
        "simulate",
        "--omega=-1,2,3",
        "--json",
    ]
    assert prep(["simulate", "--json", "-1"], parser) == ["simulate", "--json", "-1"]  # a flag takes no value
    assert prep(["simulate", "--omega", "--json"], parser) == ["simulate", "--omega", "--json"]
    assert prep(["simulate", "--omega", "-h"], parser) == ["simulate", "--omega", "-h"]  # a known option
    assert prep(["animate", "r.nc", "--fps", "-3"], parser) == ["animate", "r.nc", "--fps=-3"]


# ---------------------------------------------------------------------------
# 7. write errors name the user's file
# ---------------------------------------------------------------------------
def test_write_error_names_the_target_not_the_temporary(capsys, tmp_path):
    blocker = tmp_path / "file.txt"
    blocker.write_text("x")
    target = blocker / "run.nc"  # its folder is a plain file: cannot be written
    line = one_error(capsys, BASE + ["--out", str(target)], r"cannot write .*file\.txt/run\.nc: ")
    assert ".tmp" not in line and "[Errno" not in line


def test_write_to_existing_directory(capsys, tmp_path):
    d = tmp_path / "d.nc"
    d.mkdir()
    one_error(capsys, BASE + ["--out", str(d)], r"cannot write .*d\.nc: it is an existing directory")
    assert list(d.iterdir()) == []


@pytest.mark.parametrize(
    "argv",
    [
        BASE + ["--out", ""],
        BASE + ["--out", "  "],
        ["audit", "--out", ""],
        ["plot", "run.nc", "--kind", "omega", "--out", ""],
        ["animate", "run.nc", "--out", ""],
        ["sweep", "s.toml", "--out", ""],
        ["demo", "--out", ""],
        ["info", ""],
    ],
)
def test_empty_file_names_are_errors(capsys, argv):
    one_error(capsys, argv, r"empty file name")


def test_atomic_path_errors(tmp_path):
    with pytest.raises(InvalidInputError, match="empty name"):
        atomic_write_text("", "x")
    with pytest.raises(IsADirectoryError, match=r"cannot write .*: it is an existing directory") as ei:
        atomic_write_text(tmp_path, "x")
    assert ei.value.errno == errno.EISDIR
    blocker = tmp_path / "f"
    blocker.write_text("old")
    with pytest.raises(OSError, match=r"^\[Errno \d+\] cannot write .*f/x\.txt: ") as ei:
        atomic_write_text(blocker / "x.txt", "x")
    assert ei.value.errno in (errno.ENOTDIR, errno.EEXIST)
    assert ".tmp" not in str(ei.value)
    # an OSError about the temporary file inside the block is re-worded too; the old content survives
    target = tmp_path / "keep.txt"
    target.write_text("old")
    with pytest.raises(OSError, match=r"cannot write .*keep\.txt: No space left") as ei:
        with atomic_path(target) as tmp:
            raise OSError(errno.ENOSPC, "No space left on device", tmp)
    assert ei.value.errno == errno.ENOSPC and isinstance(ei.value, OSError)
    assert target.read_text() == "old"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["f", "keep.txt"]
    # an unrelated OSError passes through untouched
    with pytest.raises(FileNotFoundError, match="other.dat"):
        with atomic_path(target):
            raise FileNotFoundError(errno.ENOENT, "No such file or directory", "other.dat")
    atomic_write_text(target, "new")
    assert target.read_text() == "new"


def test_zarr_helper_file_error_names_the_store(capsys, tmp_path):
    blocker = tmp_path / "file.txt"
    blocker.write_text("x")
    line = one_error(capsys, BASE + ["--out", str(blocker / "r.zarr")], r"r\.zarr")
    assert ".partial" not in line


# ---------------------------------------------------------------------------
# 8. animate --fps
# ---------------------------------------------------------------------------
@pytest.fixture(scope="module")
def run_nc(tmp_path_factory):
    path = tmp_path_factory.mktemp("anim") / "run.nc"
    ep.solve([1, 2, 3], np.linspace(0, 30, 61), omega0=[0.1, 1, 0.05]).to_netcdf(path)
    return str(path)


@pytest.mark.parametrize(
    "fps, out, match",
    [
        ("100000000", "m.gif", r"^--fps must be between 1 and 240 frames per second, got '100000000'$"),
        ("10000", "m.gif", r"^--fps must be between 1 and 240"),
        ("0", "m.gif", r"^--fps must be between 1 and 240"),
        ("-3", "m.gif", r"^--fps must be between 1 and 240"),
        ("nan", "m.gif", r"^--fps must be between 1 and 240"),
        ("abc", "m.gif", r"^--fps: 'abc' is not a number"),
        ("100", "m.gif", r"^--fps 100: a 20 s movie would have 2000 frames, more than 1200; use --fps 60 or less$"),
        ("100", "m.mp4", r"^--fps 100: a 20 s movie would have 2000 frames"),
        ("30", "m.html", r"^--fps applies to \.gif and \.mp4 movies only"),
        ("30", "m.avi", r"unsupported file extension"),
    ],
)
def test_animate_fps_is_bounded(capsys, tmp_path, run_nc, fps, out, match):
    one_error(capsys, ["animate", run_nc, "--out", str(tmp_path / out), "--fps", fps], match)
    assert not (tmp_path / out).exists()


def test_animate_small_gif(capsys, tmp_path):
    path = tmp_path / "short.nc"
    ep.solve([1, 2, 3], np.linspace(0, 1, 11), omega0=[0.1, 1, 0.05]).to_netcdf(path)
    gif = tmp_path / "m.gif"
    code, out, err = run(capsys, "animate", str(path), "--out", str(gif), "--fps", "1.5", "--quiet")
    assert code == 0, err
    from PIL import Image

    with Image.open(gif) as im:
        assert im.n_frames == 3  # round(1.5 fps * 2 s)


# ---------------------------------------------------------------------------
# 9. sweep messages
# ---------------------------------------------------------------------------
SWEEP = (
    "[sweep]\nkind = 'grid'\n[inertia]\nI1 = 1.0\nI2 = 2.0\nI3 = 3.0\n"
    "[momentum]\npolar = {start = 10.0, stop = 170.0, num = 2}\nazimuth = {start = 0.0, stop = 90.0, num = 2}\n"
    "[output]\npath = 'x.zarr'\nchunk = 8\n[compute]\nT = 5.0\nscheduler = 'serial'\n"
)


def test_sweep_collision_says_overwrite_flag(capsys, tmp_path):
    cfg = toml(tmp_path, SWEEP, name="s.toml")
    store = tmp_path / "other.zarr"
    store.mkdir()
    (store / "keep").write_text("mine")
    line = one_error(capsys, ["sweep", cfg, "--out", str(store)], r"--overwrite")
    assert "overwrite=True" not in line
    assert (store / "keep").read_text() == "mine"


def test_sweep_write_error_names_the_store(capsys, tmp_path):
    blocker = tmp_path / "file.txt"
    blocker.write_text("x")
    cfg = toml(tmp_path, SWEEP, name="s.toml")
    line = one_error(capsys, ["sweep", cfg, "--out", str(blocker / "a.zarr")], r"a\.zarr")
    assert ".partial" not in line


# ---------------------------------------------------------------------------
# 10. malformed trajectory files
# ---------------------------------------------------------------------------
@pytest.fixture(scope="module")
def bad_files(tmp_path_factory):
    import xarray as xr

    d = tmp_path_factory.mktemp("bad")
    good = d / "ok.nc"
    ep.solve([1, 2, 3], np.linspace(0, 10, 11), omega0=[0.1, 1, 0.05]).to_netcdf(good)
    ds = xr.load_dataset(good)
    files = {}
    files["noinertia"] = ds.drop_vars("inertia")
    b = ds.copy()
    b.attrs["batch_shape"] = "[7]"
    files["badbatch"] = b
    b = ds.copy()
    b.attrs["eulerpoisson_format_version"] = "abc"
    files["badver"] = b
    b = ds.copy()
    b.attrs["method_options"] = "{not json"
    files["badjson"] = b
    out = {}
    for k, v in files.items():
        p = d / f"{k}.nc"
        v.to_netcdf(p, engine="h5netcdf")
        out[k] = str(p)
    junk = d / "junk.nc"
    junk.write_text("hello")
    out["junk"] = str(junk)
    return out


@pytest.mark.parametrize("kind", ["noinertia", "badbatch", "badver", "badjson", "junk"])
@pytest.mark.parametrize("command", ["info", "plot", "animate"])
def test_malformed_trajectory_is_one_line_naming_the_file(capsys, tmp_path, bad_files, kind, command):
    path = bad_files[kind]
    argv = {
        "info": ["info", path],
        "plot": ["plot", path, "--kind", "omega", "--out", str(tmp_path / "p.png")],
        "animate": ["animate", path, "--out", str(tmp_path / "m.html")],
    }[command]
    one_error(capsys, argv, re.escape(f"{kind}.nc"))
    assert list(tmp_path.iterdir()) == []


def test_reader_errors_get_the_file_name(capsys, tmp_path, monkeypatch):
    path = tmp_path / "t.nc"
    path.write_text("x")

    def broken(p):
        raise KeyError("No variable named 'inertia'")

    monkeypatch.setattr(ep.Trajectory, "from_netcdf", staticmethod(broken))
    one_error(
        capsys,
        ["info", str(path)],
        r"^eulerpoisson: error: .*t\.nc: not a valid eulerpoisson trajectory file: No variable named 'inertia'$",
    )

    def named(p):
        raise EulerPoissonError(f"{p}: attribute x is wrong")

    monkeypatch.setattr(ep.Trajectory, "from_netcdf", staticmethod(named))
    line = one_error(capsys, ["info", str(path)], r"t\.nc: attribute x is wrong$")
    assert "not a valid" not in line  # not said twice


def test_info_on_a_directory(capsys, tmp_path):
    one_error(capsys, ["info", str(tmp_path)], r"is a directory, not a trajectory file")


def test_info_on_a_trajectory_without_output_times(tmp_path, capsys):
    path = tmp_path / "empty.nc"
    ep.solve([1.0, 2.0, 3.0], [], omega0=[1.0, 0.0, 0.0]).to_netcdf(path)
    code, out, err = run(capsys, "info", str(path))
    assert code == 0 and err == ""
    assert "samples     0 (no output times)" in out
