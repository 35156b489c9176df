"""``eulerpoisson demo --out DIR`` follows the output policy of every command (:mod:`eulerpoisson.io.outputs`).

A file already in the folder is replaced only when it holds what the demo
writes there (its NetCDF files, pictures, animation page, fit result and audit
report, recognized by content), so that ``make demo`` reruns into ``out/``; a
user's file under one of those names (a text ``omega.png``, a Python
``top.nc``, foreign ``audit.md`` / ``fit.json``) is never replaced, and the demo
stops before any work. ``--out`` naming a file is one clear line, exit 2.
"""

import json

import numpy as np
import pytest

import eulerpoisson as ep
from eulerpoisson.cli import demo
from eulerpoisson.cli.commands import main
from eulerpoisson.errors import OutputError
from eulerpoisson.io.outputs import content_kind, mark_text

FOREIGN = {
    "omega.png": "my notes\n",
    "audit.md": "# my audit notes\n",
    "top.nc": "print('mine')\n",
    "fit.json": '{"mine": 1}\n',
    "tennis_racket.html": "<html>my page</html>\n",
}


def _no_work(*args, **kwargs):
    raise AssertionError("the demo started its work")


def _cli(capsys, *argv):
    code = main(list(argv))
    _, err = capsys.readouterr()
    return code, err


@pytest.mark.parametrize("name", sorted(FOREIGN))
def test_a_users_file_is_never_replaced(tmp_path, capsys, monkeypatch, name):
    monkeypatch.setattr(demo, "solve", _no_work)  # refused before any work
    d = tmp_path / "uf"
    d.mkdir()
    (d / name).write_text(FOREIGN[name])
    (d / "mine.py").write_text("x = 1\n")  # not a name the demo writes: never looked at
    with pytest.raises(
        OutputError,
        match=rf"refusing to replace .*uf/{name}: it is a file that (eulerpoisson did not write|is not NetCDF)",
    ):
        demo.run_demo(d, quiet=True)
    code, err = _cli(capsys, "demo", "--out", str(d), "--quiet")
    assert code == 2 and err.count("\n") == 1 and "Traceback" not in err
    assert f"refusing to replace {d / name}" in err and "the demo replaces only an output of the same kind" in err
    assert (d / name).read_text() == FOREIGN[name] and (d / "mine.py").read_text() == "x = 1\n"
    assert sorted(p.name for p in d.iterdir()) == sorted([name, "mine.py"])  # no lock or temporary file left


def test_out_naming_a_file_is_one_line(tmp_path, capsys, monkeypatch):
    monkeypatch.setattr(demo, "solve", _no_work)
    notes = tmp_path / "notes.txt"
    notes.write_text("my notes\n")
    code, err = _cli(capsys, "demo", "--out", str(notes))
    assert code == 2 and err.count("\n") == 1 and "Errno" not in err
    assert f"--out '{notes}' is a file, not a folder" in err
    code, err = _cli(capsys, "demo", "--out", str(notes / "sub"))
    assert code == 2 and err.count("\n") == 1 and "Errno" not in err
    assert f"is under a file, not in a folder: {notes} is a file" in err
    assert notes.read_text() == "my notes\n"
    with pytest.raises(OutputError, match=r"is a file, not a folder"):
        demo.run_top(notes)
    with pytest.raises(OutputError, match=r"is a file, not a folder"):
        demo.run_fit(notes)


def test_a_folder_under_an_output_name_is_refused(tmp_path, monkeypatch):
    monkeypatch.setattr(demo, "solve", _no_work)
    (tmp_path / "audit.json").mkdir()
    with pytest.raises(OutputError, match=r"audit\.json: it is an existing directory, not a store of ours"):
        demo.run_demo(tmp_path, quiet=True)


def test_outputs_of_the_demos_kind_pass_the_check(tmp_path, monkeypatch):
    """A folder that holds what the demo writes (a rerun of ``make demo``) is accepted: the work starts."""
    pytest.importorskip("xarray")
    pytest.importorskip("matplotlib")
    from eulerpoisson.viz import plots

    tr = ep.solve(ep.RigidBody([3.0, 5.0, 8.0]), np.linspace(0.0, 1.0, 11), omega0=[0.0, 0.4, 0.01])
    for name, kind in demo.DEMO_FILES.items():
        path = tmp_path / name
        if kind == "netcdf":
            tr.to_netcdf(path)
        elif kind == "figure":
            plots.plot(tr, "omega", out=path)
        elif kind == "movie":
            path.write_text(mark_text("<!doctype html>\n<html></html>\n", "animation", "html"))
        else:
            fmt = path.suffix.lstrip(".")
            path.write_text(mark_text("{}" if fmt == "json" else "# report\n", kind, fmt))
    before = {p.name: p.read_bytes() for p in tmp_path.iterdir()}

    class Started(Exception):
        pass

    def started(*args, **kwargs):
        raise Started

    monkeypatch.setattr(demo, "solve", started)
    with pytest.raises(Started):
        demo.run_demo(tmp_path, quiet=True)
    assert {p.name: p.read_bytes() for p in tmp_path.iterdir()} == before  # nothing touched, no lock left


def test_heavy_top_reruns_into_its_folder_and_guards_the_rename(tmp_path, monkeypatch):
    pytest.importorskip("xarray")
    pytest.importorskip("matplotlib")
    first = demo.run_top(tmp_path, say=lambda s: None, t_end=1.0, samples=101)
    stamp = {f.name: f.stat().st_mtime_ns for f in first}
    again = demo.run_top(tmp_path, say=lambda s: None, t_end=2.0, samples=51)  # its own outputs: replaced
    assert [f.name for f in again] == ["top.nc", "top_apex.png"]
    assert sorted(p.name for p in tmp_path.iterdir()) == ["top.nc", "top_apex.png"]
    assert all(f.stat().st_mtime_ns >= stamp[f.name] for f in again)
    assert len(ep.Trajectory.from_netcdf(tmp_path / "top.nc").t) == 51  # the rerun's file
    assert (content_kind(tmp_path / "top.nc"), content_kind(tmp_path / "top_apex.png")) == ("netcdf", "png")

    real = demo.solve

    def sneaky(*args, **kwargs):  # a user's file appears while the demo works: not replaced at the rename
        (tmp_path / "top.nc").write_text("print('mine')\n")
        return real(*args, **kwargs)

    monkeypatch.setattr(demo, "solve", sneaky)
    with pytest.raises(OutputError, match=r"refusing to replace .*top\.nc: it is a file that is not NetCDF"):
        demo.run_top(tmp_path, say=lambda s: None, t_end=1.0, samples=11)
    assert (tmp_path / "top.nc").read_text() == "print('mine')\n"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["top.nc", "top_apex.png"]


def test_fit_result_is_marked_and_reruns(tmp_path):
    first = demo.run_fit(tmp_path, say=lambda s: None)
    js = tmp_path / "fit.json"
    assert js in first and content_kind(js) == "fit-result"
    doc = json.loads(js.read_text())
    assert doc["eulerpoisson"]["kind"] == "fit-result" and len(doc) > 1  # the result itself follows the marker
    text = js.read_text()
    demo.run_fit(tmp_path, say=lambda s: None)  # its own fit.json: replaced, by the same result
    assert js.read_text() == text
