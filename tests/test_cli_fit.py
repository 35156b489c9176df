"""``eulerpoisson fit``: the help examples run, the real phone tosses fit, bad files are one line and exit 2."""

from __future__ import annotations

import json
import re
import shlex
from pathlib import Path

import numpy as np
import pytest

import eulerpoisson as ep
from eulerpoisson.cli.commands import main
from eulerpoisson.cli.fit import FIT_EXAMPLES

ROOT = Path(__file__).resolve().parents[1]


def run(capsys, *argv):
    code = main(list(argv))
    out, err = capsys.readouterr()
    return code, out, err


@pytest.fixture
def in_tmp(tmp_path, monkeypatch):
    (tmp_path / "examples").symlink_to(ROOT / "examples")
    monkeypatch.chdir(tmp_path)
    return tmp_path


def test_help_examples_run(capsys, in_tmp):
    code, out, err = run(capsys, "fit", "--help")
    assert code == 0 and "examples:" in out
    for example in FIT_EXAMPLES:
        argv = shlex.split(example)
        assert argv[0] == "eulerpoisson"
        code, out, err = run(capsys, *argv[1:])
        assert code == 0, (example, err)
        assert out.strip()
    assert json.loads((in_tmp / "toss_fit.json").read_text())["dof"] > 0
    assert sorted(p.name for p in (in_tmp / "toss_plots").iterdir()) == ["fit.png", "polhode.png", "residuals.png"]


def test_the_two_phone_tosses_agree(capsys, in_tmp):
    """Two throws of one phone: the same inertia ratios within their standard errors (3 sigma)."""
    res = []
    for name in ("phone_toss_1.csv", "phone_toss_2.csv"):
        code, out, err = run(capsys, "fit", f"examples/tumbling_data/{name}", "--json")
        assert code == 0, err
        res.append(json.loads(out))
    for key in ("I_xx", "I_yy"):
        a, b = (r["parameters"][key] for r in res)
        sa, sb = (r["stderr"][key] for r in res)
        assert abs(a - b) < 3 * np.hypot(sa, sb), (key, a, b, sa, sb)
    # the phone spins near its intermediate axis x: I_yy < I_xx < I_zz
    for r in res:
        p = r["parameters"]
        assert p["I_yy"] < p["I_xx"] < p["I_zz"]


def test_cli_and_api_agree(capsys, in_tmp):
    from eulerpoisson.io.observations import read_observations

    code, out, err = run(capsys, "fit", "examples/tumbling_data/phone_toss_2.csv", "--sigma-omega", "0.2", "--json")
    assert code == 0, err
    cli = json.loads(out)
    obs = read_observations(ROOT / "examples/tumbling_data/phone_toss_2.csv", sigma_omega=0.2)
    api = ep.fit(**obs.fit_kwargs())
    assert np.allclose(cli["inertia"], api.inertia, rtol=0, atol=1e-12)
    assert cli["sigma_estimated"] == [] and cli["sigma"]["omega"] == 0.2


def _write(path, text):
    path.write_text(text)
    return str(path)


def _csv(rows, header="t,qw,qx,qy,qz,wx,wy,wz"):
    return header + "\n" + "\n".join(",".join(f"{x:.17g}" for x in r) for r in rows) + "\n"


@pytest.fixture
def good_rows():
    t = np.linspace(0, 10, 30)
    tr = ep.solve(ep.RigidBody([0.25, 0.33, 0.42]), t, omega0=[0.2, 0.1, 1.0])
    return np.column_stack([t, tr.quaternion, tr.omega])


@pytest.mark.parametrize(
    "kind,match",
    [
        ("missing", r"no such file"),
        ("no_t", r"\bt\b"),
        ("unsorted", r"(?i)increasing|sorted"),
        ("duplicate", r"(?i)duplicate"),
        ("nonunit", r"(?i)unit"),
        ("few", r"(?i)too few observations"),
        ("text", r"(?i)not a number|numeric|row"),
    ],
)
def test_bad_files_are_one_line_and_exit_2(capsys, tmp_path, good_rows, kind, match):
    rows = good_rows.copy()
    header = "t,qw,qx,qy,qz,wx,wy,wz"
    text = None
    if kind == "no_t":
        header = "time,qw,qx,qy,qz,wx,wy,wz"
    elif kind == "unsorted":
        rows[[3, 4]] = rows[[4, 3]]
    elif kind == "duplicate":
        rows[5, 0] = rows[4, 0]
    elif kind == "nonunit":
        rows[7, 1:5] *= 1.5
    elif kind == "few":
        rows = rows[:2, [0, 5, 6, 7]]
        header = "t,wx,wy,wz"
    elif kind == "text":
        text = _csv(rows, header).replace(f"{rows[3, 5]:.17g}", "abc", 1)
    path = tmp_path / "obs.csv"
    if kind != "missing":
        _write(path, text if text is not None else _csv(rows, header))
    extra = ["--principal-axes", "fit"] if kind == "few" else []  # 6 residuals for 8 unknowns
    code, out, err = run(capsys, "fit", str(path), *extra)
    assert code == 2, (kind, out, err)
    assert len(err.strip().splitlines()) == 1 and err.startswith("eulerpoisson: error:"), err
    assert re.search(match, err), err


def test_existing_outputs_need_overwrite(capsys, tmp_path, good_rows):
    obs = _write(tmp_path / "obs.csv", _csv(good_rows))
    out_json = tmp_path / "fit.json"
    code, out, err = run(  # a first fit result (--overwrite replaces only a file of the kind fit writes)
        capsys, "fit", obs, "--out", str(out_json), "--sigma-attitude", "0.01", "--sigma-omega", "1e-5"
    )
    assert code == 0, err
    first = out_json.read_text()
    code, out, err = run(capsys, "fit", obs, "--out", str(out_json))
    assert code == 2 and "--overwrite" in err
    assert out_json.read_text() == first
    code, out, err = run(
        capsys, "fit", obs, "--out", str(out_json), "--overwrite", "--sigma-attitude", "0.01", "--sigma-omega", "1e-5"
    )
    assert code == 0, err
    d = json.loads(out_json.read_text())
    assert np.allclose(np.diag(d["inertia"]), np.array([0.25, 0.33, 0.42]) / 1.0, atol=1e-8)
    # never over its own input
    code, out, err = run(capsys, "fit", obs, "--out", obs, "--overwrite")
    assert code == 2
    (tmp_path / "figs").mkdir()
    (tmp_path / "figs" / "fit.png").write_bytes(b"x")
    code, out, err = run(capsys, "fit", obs, "--plot", str(tmp_path / "figs"))
    assert code == 2 and "--overwrite" in err and "fit.png" in err


@pytest.mark.parametrize(
    "argv,match",
    [
        (["--sigma-omega", "-1"], r"--sigma-omega must be a positive"),
        (["--sigma-attitude", "x"], r"--sigma-attitude: 'x' is not a number"),
        (["--principal-axes", "free"], r"invalid choice"),
        (["--inertia", "1,2"], r"--inertia must be three"),
        (["--axis", "1,0"], r"--axis must be three"),
    ],
)
def test_bad_options(capsys, tmp_path, good_rows, argv, match):
    obs = _write(tmp_path / "obs.csv", _csv(good_rows))
    code, out, err = run(capsys, "fit", obs, *argv)
    assert code == 2 and len(err.strip().splitlines()) == 1
    assert re.search(match, err), err


def test_fixed_inertia_fits_the_state_only(capsys, tmp_path, good_rows):
    obs = _write(tmp_path / "obs.csv", _csv(good_rows))
    code, out, err = run(capsys, "fit", obs, "--inertia", "25,33,42", "--json")
    assert code == 0, err
    d = json.loads(out)
    assert not any(n.startswith("I_") for n in d["parameter_names"])
    assert np.allclose(d["omega0"], [0.2, 0.1, 1.0], atol=1e-9)


def test_example_script_fits_and_predicts(tmp_path, capsys):
    """examples/fit_phone_toss.py runs: both tosses fitted, figures and the prediction written."""
    import runpy

    mod = runpy.run_path(str(ROOT / "examples" / "fit_phone_toss.py"))
    results = mod["main"](tmp_path / "phone_fit")
    out = capsys.readouterr().out
    assert "prediction from t <= 0.3 s" in out and "sigma apart" in out
    assert (tmp_path / "phone_fit" / "prediction.png").stat().st_size > 0
    for name in ("phone_toss_1", "phone_toss_2"):
        assert sorted(p.name for p in (tmp_path / "phone_fit" / name).iterdir()) == [
            "fit.png",
            "polhode.png",
            "residuals.png",
        ]
        assert results[name].converged
