"""Nothing lost, nothing damaged (issue 22, items 1, 2, 3, 5 and the output names and write errors of item 12).

- 1: every file a command reads, a file its configuration names included, is an input: never an output;
- 2: the output is claimed (locked) before the work, checked again under the lock and before the rename; a
  second writer is refused with one line and exit 2 (the lock is held by another process, deterministically);
- 3: ``--overwrite`` replaces only a file of the kind the command writes, recognized by content;
- 5: ``plot --out`` and ``animate --out`` follow the same policy as ``simulate``;
- 12: names with a newline, only a suffix or a trailing slash; read-only and full disks named with what to do;
  ``cases`` leaves nothing after a failure and no stale case with ``--only --overwrite``.
"""

from __future__ import annotations

import errno
import json
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import eulerpoisson as ep
from eulerpoisson.cli import main
from eulerpoisson.errors import InvalidInputError, OutputError
from eulerpoisson.io.atomic import atomic_write_text, guard_replace, write_error
from eulerpoisson.io.outputs import (
    KINDS,
    REPLACES,
    OutputLock,
    check_output,
    check_output_name,
    claim_output,
    content_kind,
    mark_text,
)

pytest.importorskip("h5netcdf")

SIM = ["simulate", "--inertia", "1,2,3", "--omega", "1,0.1,0.5", "--t-end", "2", "--samples", "50"]
CSV_HEADER = "t,qw,qx,qy,qz,wx,wy,wz"


def run(capsys, *argv):
    code = main([str(a) for a in argv])
    out, err = capsys.readouterr()
    return code, out, err


def one_line(err: str) -> str:
    lines = err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("eulerpoisson: error: "), err
    return lines[0]


def leftovers(folder: Path) -> list[str]:
    """Hidden files left next to the outputs (temporary files, locks, partial folders)."""
    return sorted(p.name for p in folder.iterdir() if p.name.startswith("."))


@pytest.fixture
def run_nc(tmp_path):
    p = tmp_path / "run.nc"
    ep.solve([1.0, 2.0, 3.0], np.linspace(0.0, 2.0, 40), omega0=[1.0, 0.1, 0.5]).to_netcdf(p)
    return p


@pytest.fixture
def fake_audit(monkeypatch):
    """The audit without its 25 s: a report with the three formats; records whether it ran."""
    calls = []

    class Report:
        def to_markdown(self):
            return "# Audit\n\nall confirmed\n"

        def to_json(self):
            return json.dumps({"summary": {"confirmed": 3}}, indent=2)

        def to_latex(self):
            return "\\section{Audit}\n"

    def run_audit():
        calls.append(1)
        return Report()

    import eulerpoisson.paper.audit as audit

    monkeypatch.setattr(audit, "run_audit", run_audit)
    return calls


@pytest.fixture
def fake_fit(monkeypatch):
    """``fit`` without the optimizer: the CLI's outputs only; records whether it ran."""
    calls = []

    class Result:
        better_reading = None

        def to_json(self, path=None, **units):
            return json.dumps({"chi2": 1.0, "dof": 3}, indent=2) + "\n"

        def as_dict(self, **units):
            return {"chi2": 1.0}

        def summary(self, **units):
            return "fit"

        def save_plots(self, directory):
            return []

    def fit(t, **kwargs):
        calls.append(1)
        return Result()

    import eulerpoisson.estimation as estimation

    monkeypatch.setattr(estimation, "fit", fit)
    return calls


@pytest.fixture
def observations(tmp_path):
    """A CSV of observations and a TOML file naming it (``[observations] file``)."""
    t = np.linspace(0.0, 1.0, 8)
    tr = ep.solve([1.0, 2.0, 3.0], t, omega0=[0.3, 1.0, 0.2])
    rows = np.column_stack([tr.t, tr.quaternion, tr.omega])
    data = tmp_path / "toss.csv"
    data.write_text(CSV_HEADER + "\n" + "\n".join(",".join(f"{x:.17g}" for x in r) for r in rows) + "\n")
    cfg = tmp_path / "toss.toml"
    cfg.write_text('[observations]\nfile = "toss.csv"\nomega_frame = "body"\n')
    return cfg, data


# ---------------------------------------------------------------------------
# a lock held by another process, deterministically (no timing)
# ---------------------------------------------------------------------------
HOLDER = (
    "import sys\n"
    "from eulerpoisson.io.outputs import OutputLock\n"
    "with OutputLock(sys.argv[1]):\n"
    "    print('locked', flush=True)\n"
    "    sys.stdin.read()\n"
)


class HeldLock:
    """Another process holds the lock of ``path`` until :meth:`release`."""

    def __init__(self, path):
        self.proc = subprocess.Popen(
            [sys.executable, "-c", HOLDER, str(path)],
            stdin=subprocess.PIPE,
            stdout=subprocess.PIPE,
            stderr=subprocess.PIPE,
            text=True,
        )
        line = self.proc.stdout.readline()  # blocks until the lock is held (or the holder failed)
        assert line.strip() == "locked", self.proc.stderr.read()

    def release(self):
        if self.proc.poll() is None:
            self.proc.stdin.close()
            self.proc.wait(timeout=600)
        assert self.proc.returncode == 0, self.proc.stderr.read()


@pytest.fixture
def held_lock():
    holders = []

    def hold(path):
        h = HeldLock(path)
        holders.append(h)
        return h

    yield hold
    for h in holders:
        h.release()


def _writers(tmp_path, run_nc, observations):
    cfg, _ = observations
    return {
        "simulate .nc": (tmp_path / "r.nc", [*SIM, "--out", tmp_path / "r.nc"]),
        "simulate .zarr": (tmp_path / "r.zarr", [*SIM, "--out", tmp_path / "r.zarr"]),
        "audit --out": (tmp_path / "a.md", ["audit", "--out", tmp_path / "a.md"]),
        "fit --out": (tmp_path / "f.json", ["fit", cfg, "--out", tmp_path / "f.json"]),
        "validate --plot": (tmp_path / "v.png", ["validate", run_nc, "--plot", tmp_path / "v.png"]),
        "plot --out": (tmp_path / "p.png", ["plot", run_nc, "--kind", "omega", "--out", tmp_path / "p.png"]),
        "animate --out": (tmp_path / "m.html", ["animate", run_nc, "--out", tmp_path / "m.html"]),
        "cases --out": (tmp_path / "cases", ["cases", "--out", tmp_path / "cases", "--only", "sphere", "--csv-only"]),
    }


WRITERS = [
    "simulate .nc",
    "simulate .zarr",
    "audit --out",
    "fit --out",
    "validate --plot",
    "plot --out",
    "animate --out",
    "cases --out",
]


# ---------------------------------------------------------------------------
# item 2: one writer at a time, the output claimed before the work
# ---------------------------------------------------------------------------
@pytest.mark.parametrize("which", WRITERS)
def test_a_second_writer_is_refused_while_another_process_holds_the_output(
    capsys, tmp_path, run_nc, observations, held_lock, fake_audit, fake_fit, which
):
    out, argv = _writers(tmp_path, run_nc, observations)[which]
    holder = held_lock(out)
    code, _, err = run(capsys, *argv)
    assert code == 2
    assert "is being written by another process" in one_line(err) and str(out) in err
    assert not out.exists() and fake_audit == [] and fake_fit == []  # refused before the work
    holder.release()
    code, _, err = run(capsys, *argv)
    assert code == 0, err
    assert out.exists() and leftovers(tmp_path) == []


def test_the_netcdf_output_is_locked_during_the_computation(capsys, tmp_path, monkeypatch):
    """The lock of a .nc is taken before the solve (it used to be taken only around the write)."""
    import eulerpoisson.cli.simulate as simulate

    out = tmp_path / "r.nc"
    seen = []
    solve_run = simulate.solve_run

    def watched(*args, **kwargs):
        seen.append((tmp_path / ".r.nc.lock").exists())
        return solve_run(*args, **kwargs)

    monkeypatch.setattr(simulate, "solve_run", watched)
    code, _, err = run(capsys, *SIM, "--out", out, "--quiet")
    assert code == 0, err
    assert seen == [True] and out.exists() and leftovers(tmp_path) == []


@pytest.mark.parametrize("which", ["simulate .nc", "audit --out", "fit --out", "plot --out", "animate --out"])
def test_an_output_that_appears_during_the_work_is_not_replaced(
    capsys, tmp_path, run_nc, observations, monkeypatch, fake_audit, fake_fit, which
):
    """Checked again under the lock, just before the rename: a file written meanwhile (by a process that did not
    ask for the lock) is kept, and the command fails with one line."""
    out, argv = _writers(tmp_path, run_nc, observations)[which]
    import eulerpoisson.io.atomic as atomic

    # the file appears at the last moment: after the work, before the rename (the check runs in between)
    real_check = atomic.check_guard

    def late(path):
        if os.path.abspath(path) == os.path.abspath(out) and not out.exists():
            out.write_text("written meanwhile")
        return real_check(path)

    monkeypatch.setattr(atomic, "check_guard", late)
    code, _, err = run(capsys, *argv)
    assert code == 2
    assert f"{out} exists; run again with --overwrite" in one_line(err) or "refusing to replace" in err
    assert out.read_text() == "written meanwhile"
    assert leftovers(tmp_path) == []


def test_the_claim_is_checked_again_under_the_lock(tmp_path):
    out = tmp_path / "x.json"
    with pytest.raises(OutputError, match=r"x\.json exists; run again with --overwrite"):
        with claim_output(out, "fit-result"):
            out.write_text(mark_text("{}", "fit-result", "json"))  # another writer finished meanwhile
            atomic_write_text(out, mark_text('{"a": 1}', "fit-result", "json"))
    assert set(json.loads(out.read_text())) == {"eulerpoisson"}  # the other writer's file, untouched
    assert leftovers(tmp_path) == []


def test_guard_replace_stops_the_rename_and_cleans_up(tmp_path):
    out = tmp_path / "g.txt"

    def refuse():
        raise OutputError("no")

    with guard_replace(out, refuse):
        with pytest.raises(OutputError, match="no"):
            atomic_write_text(out, "x")
    assert list(tmp_path.iterdir()) == []
    atomic_write_text(out, "y")  # the guard is gone
    assert out.read_text() == "y"


# ---------------------------------------------------------------------------
# item 1: every path a configuration names is an input
# ---------------------------------------------------------------------------
def test_fit_never_overwrites_the_observation_file_its_toml_names(capsys, tmp_path, observations, fake_fit):
    cfg, data = observations
    before = data.read_bytes()
    for target in (data, cfg):
        code, _, err = run(capsys, "fit", cfg, "--out", target, "--overwrite")
        assert code == 2 and "it is an input of this command" in one_line(err)
    assert data.read_bytes() == before and fake_fit == []
    # the same file named another way (a relative path from elsewhere)
    code, _, err = run(capsys, "fit", cfg, "--out", os.path.relpath(data), "--overwrite")
    assert code == 2 and "it is an input of this command" in err and data.read_bytes() == before


def test_read_observations_lists_every_file_it_read(observations):
    from eulerpoisson.io.observations import read_observations

    cfg, data = observations
    obs = read_observations(cfg)
    assert [Path(f).resolve() for f in obs.files] == [cfg.resolve(), data.resolve()]
    assert [Path(f).resolve() for f in read_observations(data).files] == [data.resolve()]


def test_simulate_and_plot_never_write_over_their_inputs(capsys, tmp_path):
    cfg = tmp_path / "run.nc"  # a TOML file, whatever its name
    text = "[body]\ninertia = [1, 2, 3]\n[initial]\nomega = [1, 0.1, 0.5]\n[time]\nt_end = 1\nsamples = 5\n"
    cfg.write_text(text)
    code, _, err = run(capsys, "simulate", cfg, "--out", cfg, "--overwrite")
    assert code == 2 and "it is an input of this command" in one_line(err) and cfg.read_text() == text
    run_nc = tmp_path / "r.nc"
    ep.solve([1.0, 2.0, 3.0], np.linspace(0.0, 2.0, 40), omega0=[1.0, 0.1, 0.5]).to_netcdf(run_nc)
    before = run_nc.read_bytes()
    code, _, err = run(capsys, "plot", run_nc, "--kind", "omega", "--out", run_nc, "--overwrite")
    assert code == 2 and "it is an input of this command" in one_line(err) and run_nc.read_bytes() == before
    code, _, err = run(capsys, "validate", run_nc, "--plot", run_nc, "--overwrite")
    assert code == 2 and run_nc.read_bytes() == before


# ---------------------------------------------------------------------------
# item 3: --overwrite replaces only what the command writes, recognized by content
# ---------------------------------------------------------------------------
FOREIGN = {
    "run.toml": "[body]\ninertia = [1, 2, 3]\n",
    "data.csv": "t,qw,qx,qy,qz\n0,1,0,0,0\n",
    "tool.py": "print('hello')\n",
    "notes.md": "# my notes\n",
    "page.html": "<!DOCTYPE html>\n<html></html>\n",
    "other.json": '{"mine": true}\n',
    "empty.txt": "",
}


@pytest.mark.parametrize("name", sorted(FOREIGN))
def test_audit_overwrite_never_replaces_a_file_that_is_not_an_audit_report(capsys, tmp_path, fake_audit, name):
    target = tmp_path / name
    target.write_text(FOREIGN[name])
    code, _, err = run(capsys, "audit", "--out", target, "--overwrite")
    assert code == 2 and "refusing to replace" in one_line(err) and "eulerpoisson did not write" in err
    assert target.read_text() == FOREIGN[name] and fake_audit == []


@pytest.mark.parametrize("fmt", ["md", "json", "tex"])
def test_audit_overwrite_replaces_its_own_report(capsys, tmp_path, fake_audit, fmt):
    out = tmp_path / f"audit.{fmt}"
    assert run(capsys, "audit", "--format", fmt, "--out", out, "--quiet")[0] == 0
    assert content_kind(out) == "audit-report"
    if fmt == "json":
        assert json.loads(out.read_text())["summary"] == {"confirmed": 3}
    code, _, err = run(capsys, "audit", "--format", fmt, "--out", out)
    assert code == 2 and "run again with --overwrite" in one_line(err)
    assert run(capsys, "audit", "--format", fmt, "--out", out, "--overwrite", "--quiet")[0] == 0
    assert fake_audit == [1, 1]


def test_fit_overwrite_replaces_only_a_fit_result(capsys, tmp_path, observations, fake_fit):
    cfg, _ = observations
    out = tmp_path / "fit.json"
    assert run(capsys, "fit", cfg, "--out", out)[0] == 0
    doc = json.loads(out.read_text())
    assert doc["eulerpoisson"]["kind"] == "fit-result" and doc["chi2"] == 1.0
    assert run(capsys, "fit", cfg, "--out", out, "--overwrite")[0] == 0
    other = tmp_path / "other.json"
    other.write_text('{"chi2": 5}')
    code, _, err = run(capsys, "fit", cfg, "--out", other, "--overwrite")
    assert code == 2 and "refusing to replace" in one_line(err) and other.read_text() == '{"chi2": 5}'
    # figures: only pictures are replaced in --plot
    figs = tmp_path / "figs"
    figs.mkdir()
    (figs / "fit.png").write_text("not a picture")
    code, _, err = run(capsys, "fit", cfg, "--plot", figs, "--overwrite")
    assert code == 2 and "refusing to replace" in one_line(err) and (figs / "fit.png").read_text() == "not a picture"


def test_simulate_overwrite_refuses_a_configuration_named_like_its_output(capsys, tmp_path):
    cfg = tmp_path / "x.nc"
    cfg.write_text("[body]\ninertia = [1, 2, 3]\n")
    code, _, err = run(capsys, *SIM, "--out", cfg, "--overwrite")
    assert code == 2 and "refusing to replace" in one_line(err) and "not NetCDF" in err
    assert cfg.read_text() == "[body]\ninertia = [1, 2, 3]\n"


def test_content_kinds(tmp_path, run_nc):
    def put(name, data):
        p = tmp_path / name
        p.write_bytes(data if isinstance(data, bytes) else data.encode())
        return p

    assert content_kind(run_nc) == "netcdf"
    assert content_kind(tmp_path / "none") is None
    assert content_kind(put("a.png", b"\x89PNG\r\n\x1a\n" + b"\0" * 20)) == "png"
    assert content_kind(put("a.gif", b"GIF89a" + b"\0" * 20)) == "gif"
    assert content_kind(put("a.mp4", b"\0\0\0\x20ftypisom" + b"\0" * 20)) == "mp4"
    assert content_kind(put("a.pdf", b"%PDF-1.4\n")) == "pdf"
    assert content_kind(put("a.svg", '<?xml version="1.0"?>\n<svg xmlns="http://www.w3.org/2000/svg"></svg>')) == "svg"
    for fmt, kind in (("json", "fit-result"), ("md", "audit-report"), ("tex", "audit-report"), ("html", "animation")):
        text = "<!DOCTYPE html>\n<html></html>\n" if fmt == "html" else ("{}" if fmt == "json" else "body\n")
        assert content_kind(put(f"m.{fmt}", mark_text(text, kind, fmt))) == kind
    for name, text in FOREIGN.items():
        assert content_kind(put(name, text)) == "file", name
    assert content_kind(tmp_path) == "folder"


def test_mark_text_keeps_the_json_valid():
    for text in ("{}", '{"a": 1}', json.dumps({"a": [1, 2]}, indent=2), '  {\n"a": {}}'):
        doc = json.loads(mark_text(text, "fit-result", "json"))
        assert doc["eulerpoisson"]["kind"] == "fit-result" and list(doc)[0] == "eulerpoisson"
    with pytest.raises(InvalidInputError, match="must be a JSON object"):
        mark_text("[1]", "fit-result", "json")
    with pytest.raises(InvalidInputError, match="fmt must be one of"):
        mark_text("x", "fit-result", "toml")
    with pytest.raises(InvalidInputError, match="kind must be"):
        mark_text("x", "Fit Result", "md")


@pytest.mark.parametrize("writes", KINDS)
def test_check_output_never_replaces_an_unknown_file(tmp_path, writes):
    p = tmp_path / "x.out"
    p.write_text("a = 1\n")
    with pytest.raises(OutputError, match="refusing to replace"):
        check_output(p, writes, overwrite=True)
    assert "file" not in REPLACES[writes]
    with pytest.raises(ValueError, match="writes must be one of"):
        check_output(p, "toml")


# ---------------------------------------------------------------------------
# item 5: plot and animate refuse an existing file without --overwrite
# ---------------------------------------------------------------------------
def test_plot_out_follows_the_output_policy(capsys, tmp_path, run_nc):
    mine = tmp_path / "mine.png"
    mine.write_text("my text")
    code, _, err = run(capsys, "plot", run_nc, "--kind", "omega", "--out", mine)
    assert code == 2 and "refusing to replace" in one_line(err) and mine.read_text() == "my text"
    code, _, err = run(capsys, "plot", run_nc, "--kind", "omega", "--out", mine, "--overwrite")
    assert code == 2 and mine.read_text() == "my text"
    fig = tmp_path / "fig.png"
    assert run(capsys, "plot", run_nc, "--kind", "omega", "--out", fig, "--quiet")[0] == 0
    code, _, err = run(capsys, "plot", run_nc, "--kind", "omega", "--out", fig)
    assert code == 2 and "run again with --overwrite to replace it" in one_line(err)
    assert run(capsys, "plot", run_nc, "--kind", "polhode", "--out", fig, "--overwrite", "--quiet")[0] == 0
    assert content_kind(fig) == "png" and leftovers(tmp_path) == []


def test_plot_default_name_follows_the_output_policy(capsys, tmp_path, run_nc, monkeypatch):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "run_omega.png").write_text("keep")
    code, _, err = run(capsys, "plot", run_nc, "--kind", "omega")
    assert code == 2 and "run_omega.png" in one_line(err) and (tmp_path / "run_omega.png").read_text() == "keep"


def test_animate_out_follows_the_output_policy(capsys, tmp_path, run_nc):
    mine = tmp_path / "movie.html"
    mine.write_text("<!DOCTYPE html>\n<p>my page</p>\n")
    for extra in ([], ["--overwrite"]):
        code, _, err = run(capsys, "animate", run_nc, "--out", mine, *extra)
        assert code == 2 and "refusing to replace" in one_line(err)
    assert mine.read_text() == "<!DOCTYPE html>\n<p>my page</p>\n"
    page = tmp_path / "ours.html"
    assert run(capsys, "animate", run_nc, "--out", page, "--quiet")[0] == 0
    assert content_kind(page) == "animation" and page.read_text().startswith("<!DOCTYPE html>\n<!-- written by")
    code, _, err = run(capsys, "animate", run_nc, "--out", page)
    assert code == 2 and "run again with --overwrite" in one_line(err)
    assert run(capsys, "animate", run_nc, "--out", page, "--overwrite", "--quiet")[0] == 0
    assert leftovers(tmp_path) == []


# ---------------------------------------------------------------------------
# item 12: output names
# ---------------------------------------------------------------------------
@pytest.mark.parametrize(
    "argv,match",
    [
        ([*SIM, "--out", "a\nb.nc"], r"control character"),
        ([*SIM, "--out", ".nc"], r"'\.nc' is only a suffix"),
        ([*SIM, "--out", "sub/.nc"], r"is only a suffix"),
        ([*SIM, "--out", ".zarr"], r"is only a suffix"),
        (["plot", "RUN", "--kind", "omega", "--out", "x.png/"], r"ends with '/'"),
        (["plot", "RUN", "--kind", "omega", "--out", ".png"], r"only a suffix"),
        (["plot", "RUN", "--kind", "omega", "--out", "x\ty.png"], r"control character"),
        (["animate", "RUN", "--out", "m.html/"], r"ends with '/'"),
        (["animate", "RUN", "--out", ".html"], r"only a suffix"),
        (["audit", "--out", "a\n.md"], r"control character"),
        (["audit", "--out", "."], r"names a folder"),
        (["validate", "RUN", "--plot", "v.png/"], r"ends with '/'"),
        (["cases", "--out", "c\nd"], r"control character"),
        (["fit", "OBS", "--out", "f.json\n"], r"control character"),
    ],
)
def test_output_names_that_cannot_be_meant_are_refused(
    capsys, tmp_path, monkeypatch, run_nc, observations, argv, match
):
    import re

    monkeypatch.chdir(tmp_path)
    argv = [run_nc if a == "RUN" else observations[0] if a == "OBS" else a for a in argv]
    code, _, err = run(capsys, *argv)
    assert code == 2 and re.search(match, one_line(err)), err
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted(["run.nc", "toss.csv", "toss.toml"])


def test_check_output_name_unit():
    check_output_name("run.nc")
    check_output_name(".hidden.nc")
    check_output_name("cases/", folder=True)
    with pytest.raises(InvalidInputError, match=r"--plot 'x\\n': a file name with a control character"):
        check_output_name("x\n", "--plot")
    with pytest.raises(InvalidInputError, match="ends with '/'"):
        check_output_name("x.png/")
    with pytest.raises(InvalidInputError, match="empty file name"):
        check_output_name("  ")


# ---------------------------------------------------------------------------
# item 12: read-only folder, full disk: the file named, and what to do
# ---------------------------------------------------------------------------
def _mount(path: Path, options: str) -> bool:
    path.mkdir()
    res = subprocess.run(["mount", "-t", "tmpfs", "-o", options, "tmpfs", str(path)], capture_output=True, text=True)
    return res.returncode == 0


@pytest.fixture
def read_only(tmp_path):
    ro = tmp_path / "ro"
    if not _mount(ro, "ro,size=64k"):
        pytest.skip("cannot mount a read-only tmpfs here (needs root)")
    try:
        yield ro
    finally:
        subprocess.run(["umount", str(ro)], capture_output=True)


@pytest.fixture
def small_disk(tmp_path):
    d = tmp_path / "small"
    if not _mount(d, "size=128k"):
        pytest.skip("cannot mount a small tmpfs here (needs root)")
    try:
        yield d
    finally:
        subprocess.run(["umount", str(d)], capture_output=True)


@pytest.mark.parametrize("which", ["simulate .nc", "cases", "validate --plot", "plot --out", "audit --out"])
def test_a_read_only_folder_is_named_with_what_to_do(capsys, read_only, run_nc, fake_audit, which):
    argv = {
        "simulate .nc": [*SIM, "--out", read_only / "r.nc"],
        "cases": ["cases", "--out", read_only / "cases", "--only", "sphere"],
        "validate --plot": ["validate", run_nc, "--plot", read_only / "v.png"],
        "plot --out": ["plot", run_nc, "--kind", "omega", "--out", read_only / "p.png"],
        "audit --out": ["audit", "--out", read_only / "a.md"],
    }[which]
    code, _, err = run(capsys, *argv)
    line = one_line(err)
    assert code == 2 and f"cannot write {read_only}/" in line and "Read-only file system" in line
    assert "write to a folder on a writable disk" in line and "[Errno" not in line


def test_a_full_disk_is_named_with_what_to_do_and_cases_leave_nothing(capsys, small_disk):
    out = small_disk / "cases"
    code, _, err = run(capsys, "cases", "--out", out, "--only", "long_run,symmetric_top")
    line = one_line(err)
    assert code == 2 and f"cannot write {out}: No space left on device" in line
    assert "free some space" in line and "[Errno" not in line
    assert list(small_disk.iterdir()) == []  # no empty folder, no partial folder, no lock


def test_write_error_says_what_to_do():
    for code, advice in (
        (errno.ENOSPC, "free some space"),
        (errno.EROFS, "read-only"),
        (errno.EACCES, "write to another folder"),
    ):
        exc = write_error("out/r.nc", OSError(code, os.strerror(code), "out/.r.nc.123.tmp"))
        assert exc.errno == code and str(exc).startswith(f"[Errno {code}] cannot write out/r.nc: {os.strerror(code)}; ")
        assert advice in str(exc) and ".tmp" not in str(exc)


# ---------------------------------------------------------------------------
# item 12: cases leave nothing after a failure, no stale case after --only --overwrite
# ---------------------------------------------------------------------------
def test_cases_leave_no_folder_after_a_failure(capsys, tmp_path, monkeypatch):
    from eulerpoisson.oracle import cases as cases_module

    written = []
    to_csv = cases_module.ReferenceCase.to_csv

    def failing(self, path):
        if written:
            raise OSError(errno.ENOSPC, "No space left on device", str(path))
        written.append(path)
        return to_csv(self, path)

    monkeypatch.setattr(cases_module.ReferenceCase, "to_csv", failing)
    out = tmp_path / "cases"
    code, _, err = run(capsys, "cases", "--out", out, "--only", "sphere,symmetric_top", "--csv-only")
    assert code == 2 and f"cannot write {out}: No space left on device" in one_line(err)
    assert list(tmp_path.iterdir()) == []


def test_cases_only_overwrite_leaves_no_stale_case_and_keeps_other_files(capsys, tmp_path):
    out = tmp_path / "cases"
    assert run(capsys, "cases", "--out", out, "--only", "sphere,symmetric_top", "--csv-only", "--quiet")[0] == 0
    (out / "my_run.csv").write_text("mine")
    assert run(capsys, "cases", "--out", out, "--only", "symmetric_top", "--csv-only", "--overwrite", "--quiet")[0] == 0
    assert sorted(p.name for p in out.iterdir()) == ["README.md", "cases.json", "my_run.csv", "symmetric_top.csv"]
    assert [c["name"] for c in json.loads((out / "cases.json").read_text())] == ["symmetric_top"]
    assert content_kind(out) == "cases" and leftovers(tmp_path) == []
    assert (out / "README.md").read_text().startswith("<!-- written by eulerpoisson")


def test_output_lock_refuses_a_live_holder(tmp_path, held_lock):
    out = tmp_path / "x.nc"
    held_lock(out)
    with pytest.raises(OutputError, match=r"is being written by another process \(pid \d+\)"):
        with OutputLock(out):
            pass
