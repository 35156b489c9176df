"""Text that reaches matplotlib is drawn as typed (issue 12, item 15).

A time unit (the option ``time_unit``), a body name, a method name, a run's
file name, a label or a title with ``$...$`` was parsed as mathtext: drawing
failed (``$x^{$`` is no valid TeX) or showed something else than the text.
Every text of every figure is checked, not only the title.
"""

import re

import numpy as np
import pytest

pytest.importorskip("matplotlib")

import eulerpoisson as ep  # noqa: E402
from eulerpoisson.viz import plots  # noqa: E402

BAD_TEX = r"$x^{$ u $\frac$"  # not valid mathtext: matplotlib raised ValueError while drawing
TEX = r"$\tau$"  # valid mathtext: it was drawn as a Greek letter


def _texts(fig):
    from matplotlib.text import Text

    return [t for t in fig.findobj(Text) if t.get_text()]


def _assert_literal(fig, *needles):
    """No text of ``fig`` is mathtext, and every needle is drawn somewhere, literally."""
    drawn = []
    for t in _texts(fig):
        if re.fullmatch(r"\$\\mathdefault\{.*\}\$", t.get_text()):
            continue  # a tick label of a log axis: matplotlib's own mathtext
        text, math = t._preprocess_math(t.get_text())
        assert math is False, f"mathtext in {t.get_text()!r}"
        drawn.append(text)
    for needle in needles:
        # what the renderer draws: \$ becomes $
        assert any(needle in d.replace(r"\$", "$") for d in drawn), (needle, drawn)


@pytest.fixture(scope="module", params=[BAD_TEX, TEX])
def unit_run(request):
    body = ep.RigidBody([3.0, 5.0, 8.0], name=f"rod {request.param}")
    tr = ep.solve(body, np.linspace(0.0, 20.0, 201), omega0=[0.0, 0.4, 0.00125])
    tr.options["time_unit"] = request.param
    return tr


@pytest.mark.parametrize("kind", plots.KINDS)
def test_every_picture_draws_a_dollar_time_unit_as_typed(unit_run, kind, tmp_path):
    out = tmp_path / f"{kind}.png"
    fig = plots.plot(unit_run, kind, out=out)  # drawing raised for BAD_TEX
    assert out.stat().st_size > 1000
    unit = unit_run.options["time_unit"]
    needles = [unit_run.body.name]
    if kind in ("omega", "invariants", "polhode", "gibbs", "apex"):  # the pictures whose axes have a time unit
        needles.append(f"[{unit}]" if kind != "polhode" else f"/{unit}]")
    _assert_literal(fig, *needles)


def test_long_run_and_store_pictures_draw_a_dollar_time_unit_as_typed(tmp_path):
    pytest.importorskip("zarr")
    from eulerpoisson.io.stream import solve_to_file

    tr = ep.solve([1.0, 2.0, 3.0], np.linspace(0.0, 300.0, 30_001), omega0=[1.0, 0.1, 0.5])  # decimated
    tr.options["time_unit"] = BAD_TEX
    for kind in ("omega", "invariants"):
        _assert_literal(plots.plot(tr, kind, out=tmp_path / f"m_{kind}.png"), f"[{BAD_TEX}]")
    path = tmp_path / "s.zarr"
    solve_to_file(
        ep.RigidBody([1.0, 2.0, 3.0], name=BAD_TEX),
        (0.0, 30.0, 3001),
        path,
        omega0=[1.0, 0.1, 0.5],
        progress=False,
        chunk=1000,
    )
    lz = ep.Trajectory.open(path)
    lz.options["time_unit"] = TEX
    for kind in ("omega", "invariants"):
        _assert_literal(plots.plot(lz, kind, out=tmp_path / f"s_{kind}.png"), BAD_TEX, f"[{TEX}]")


def test_gif_frames_draw_a_dollar_time_unit_as_typed(unit_run, tmp_path):
    from eulerpoisson.viz import animate as an

    out = an.animate(unit_run, tmp_path / "u.gif", fps=4, duration=1, size=(160, 120))
    assert out.stat().st_size > 0


def test_the_validation_figure_draws_file_names_labels_and_titles_as_typed(tmp_path):
    from eulerpoisson.oracle import plot_report, run_from_arrays, validate

    t = np.linspace(0.0, 60.0, 301)
    tr = ep.solve([3.0, 5.0, 8.0], t, omega0=[0.004, 0.4, 0.0])
    rep = validate(run_from_arrays(tr.t, tr.quaternion, tr.omega, source=f"run {BAD_TEX}.csv"), [3.0, 5.0, 8.0])
    fig = plot_report(rep, tmp_path / "a.png")
    _assert_literal(fig, f"run {BAD_TEX}.csv")
    fig = plot_report([(BAD_TEX, rep), (TEX, rep)], tmp_path / "b.png", title=f"{TEX} against {BAD_TEX}")
    _assert_literal(fig, f"{TEX} against {BAD_TEX}", f"{BAD_TEX} (max", f"{TEX}: energy")
    assert (tmp_path / "b.png").stat().st_size > 1000


def test_validate_command_with_a_dollar_file_name(capsys, tmp_path):
    from eulerpoisson.cli import main

    t = np.linspace(0.0, 60.0, 301)
    tr = ep.solve([3.0, 5.0, 8.0], t, omega0=[0.004, 0.4, 0.0])
    run = tmp_path / f"run {BAD_TEX}.csv"
    rows = np.column_stack([tr.t, tr.quaternion, tr.omega])
    np.savetxt(run, rows, delimiter=",", header="t,qw,qx,qy,qz,wx,wy,wz", comments="")
    code = main(["validate", str(run), "--inertia", "3,5,8", "--plot", str(tmp_path / "v.png")])
    out, err = capsys.readouterr()
    assert code == 0, err
    assert (tmp_path / "v.png").stat().st_size > 1000
