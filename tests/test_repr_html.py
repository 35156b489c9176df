"""Notebook views (``_repr_html_``): well-formed, escaped, batches summarized, small at any length, lazy for stores."""

import re
import subprocess
import sys
from html.parser import HTMLParser

import numpy as np
import pytest

import eulerpoisson as ep
from _limits import HANG_GUARD_S
from eulerpoisson.util import htmlrepr

#: elements that never have an end tag
VOID = {"area", "base", "br", "col", "embed", "hr", "img", "input", "link", "meta", "source", "track", "wbr"}


class _Balance(HTMLParser):
    def __init__(self):
        super().__init__(convert_charrefs=True)
        self.stack, self.errors, self.tags, self.text = [], [], [], []

    def handle_starttag(self, tag, attrs):
        self.tags.append(tag)
        if tag not in VOID:
            self.stack.append(tag)

    def handle_startendtag(self, tag, attrs):
        self.tags.append(tag)

    def handle_endtag(self, tag):
        if not self.stack or self.stack[-1] != tag:
            self.errors.append(f"</{tag}> closes {self.stack[-1] if self.stack else 'nothing'}")
        else:
            self.stack.pop()

    def handle_data(self, data):
        self.text.append(data)


def well_formed(page: str) -> _Balance:
    """Parse ``page``; every tag closed in order, one top-level ``<div>``."""
    assert isinstance(page, str) and page.startswith("<div") and page.endswith("</div>")
    p = _Balance()
    p.feed(page)
    p.close()
    assert not p.errors, p.errors
    assert not p.stack, f"unclosed: {p.stack}"
    assert "script" not in p.tags
    return p


def polylines(page: str) -> list[int]:
    """Number of points of every SVG polyline of ``page``."""
    return [len(m.split()) for m in re.findall(r'<polyline[^>]* points="([^"]*)"', page)]


EVIL = '<script>alert("x")</script>&'


# ---------------------------------------------------------------------------
# bodies and models
# ---------------------------------------------------------------------------
def test_body_scalar():
    page = ep.RigidBody([1.0, 2.0, 2.5], name=EVIL)._repr_html_()
    p = well_formed(page)
    text = "".join(p.text)
    assert EVIL in text  # shown as text...
    assert "<script>" not in page and "&lt;script&gt;" in page  # ...never as markup
    assert "[1, 2, 2.5]" in text and "asymmetric" in text


def test_body_full_tensor_and_particles():
    body = ep.RigidBody.from_particles([1.0, 2.0, 3.0, 1.0], [[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]])
    text = "".join(well_formed(body._repr_html_()).text)
    assert "4 point masses" in text and "inertia tensor" in text


def test_body_batch_is_summarized():
    rng = np.random.default_rng(0)
    moments = np.sort(rng.uniform(1.0, 1.5, (40, 25, 3)), -1)
    page = ep.RigidBody(moments)._repr_html_()
    text = "".join(well_formed(page).text)
    assert "1000 bodies" in text and "(40, 25)" in text and "first 5" in text
    assert len(page) < 4000  # five bodies listed, not a thousand
    assert f"{moments[..., 0].min():.6g}" in text and f"{moments[..., 2].max():.6g}" in text


def test_model():
    top = ep.Model([2.0, 2.0, 1.0], ep.torques.Gravity(1.0, [0.0, 0.0, 0.5]))
    text = "".join(well_formed(top._repr_html_()).text)
    assert "Gravity(" in text and "conservative" in text
    assert "free body" in "".join(well_formed(ep.Model([1.0, 2.0, 2.5])._repr_html_()).text)


# ---------------------------------------------------------------------------
# trajectories in memory
# ---------------------------------------------------------------------------
def test_trajectory_scalar():
    tr = ep.solve(ep.RigidBody([1.0, 2.0, 2.5], name=EVIL), np.linspace(0.0, 20.0, 401), omega0=[1.0, 0.1, 0.5])
    page = tr._repr_html_()
    p = well_formed(page)
    text = "".join(p.text)
    assert "&lt;script&gt;" in page and "<script>" not in page
    assert "exact" in text and "401" in text and "drift (max over t)" in text and "energy" in text
    assert p.tags.count("svg") == 2  # Omega(t) and the energy
    assert len(polylines(page)) == 4 and max(polylines(page)) <= 2 * htmlrepr.SPARK_COLUMNS


def test_trajectory_batch_and_torque():
    bodies = ep.RigidBody.from_moments([[1.0, 2.0, 2.5], [1.0, 1.5, 2.0], [2.0, 2.0, 1.0]])
    tr = ep.solve(bodies, np.linspace(0.0, 5.0, 51), omega0=[1.0, 0.1, 0.5])
    text = "".join(well_formed(tr._repr_html_()).text)
    assert "51 × 3 bodies" in text and "first body" in "".join(tr._repr_html_()) and "kinds" in text
    top = ep.solve(
        [1.0, 1.0, 0.5],
        np.linspace(0.0, 1.0, 21),
        omega0=[0.0, 0.0, 20.0],
        attitude0=ep.Attitude.from_rotvec([0.3, 0.0, 0.0]),
        torque=ep.torques.Gravity(1.0, [0, 0, 0.1]),
        method="rk",
    )
    text = "".join(well_formed(top._repr_html_()).text)
    assert "Gravity(" in text and "m_vertical" in text


@pytest.mark.parametrize("T", [0, 1, 2])
def test_trajectory_short(T):
    tr = ep.Trajectory(
        np.arange(T, dtype=float),
        np.tile([1.0, 0, 0, 0], (T, 1)),
        np.tile([0.0, 0, 1], (T, 1)),
        ep.RigidBody([1.0, 2.0, 2.5]),
    )
    p = well_formed(tr._repr_html_())
    assert p.tags.count("svg") == (2 if T == 2 else 0)


def test_large_trajectory_is_small_and_decimated():
    T = 10**6
    t = np.linspace(0.0, 1000.0, T)
    w = np.stack([np.sin(t), np.cos(3 * t), 0.1 * np.sin(t / 7)], -1)
    q = np.tile([0.6, 0.0, 0.8, 0.0], (T, 1))
    w[123_457, 1] = 50.0  # one spike: the min/max envelope keeps it
    tr = ep.Trajectory(t, q, w, ep.RigidBody([1.0, 2.0, 2.5]), method="synthetic")
    page = tr._repr_html_()
    well_formed(page)
    assert len(page.encode()) < 30_000
    assert max(polylines(page)) <= 2 * htmlrepr.SPARK_COLUMNS
    assert "in [-1, 50]" in page  # the spike is in the picture's range
    assert f"of {T} samples" in page  # the drift of a long run is a maximum over spread samples


def test_no_matplotlib():
    code = (
        "import sys, numpy as np, eulerpoisson as ep\n"
        "tr = ep.solve([1.0, 2.0, 2.5], np.linspace(0, 10, 5001), omega0=[1, 0.1, 0.5])\n"
        "assert '<svg' in tr._repr_html_()\n"
        "ep.RigidBody([1.0, 2.0, 2.5])._repr_html_(); ep.Model([1, 2, 2.5])._repr_html_()\n"
        "assert 'matplotlib' not in sys.modules, 'matplotlib imported'\n"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=HANG_GUARD_S)
    assert out.returncode == 0, out.stderr


# ---------------------------------------------------------------------------
# trajectories read back from files
# ---------------------------------------------------------------------------
def test_netcdf_read_back(tmp_path):
    pytest.importorskip("h5netcdf")
    tr = ep.solve(ep.RigidBody([1.0, 2.0, 2.5], name=EVIL), np.linspace(0.0, 10.0, 101), omega0=[1.0, 0.1, 0.5])
    tr.to_netcdf(tmp_path / "run.nc")
    back = ep.Trajectory.open(tmp_path / "run.nc")
    page = back._repr_html_()
    well_formed(page)
    assert "&lt;script&gt;" in page and "<script>" not in page and "101" in page


def test_zarr_store_is_read_lazily(tmp_path, monkeypatch):
    pytest.importorskip("zarr")
    from eulerpoisson.io import read as rd
    from eulerpoisson.io.stream import solve_to_file

    T, chunk = 400, 20  # 20 chunks
    path = solve_to_file(
        ep.RigidBody([1.0, 2.0, 2.5], name=EVIL),
        (0.0, 40.0, T),
        tmp_path / "run.zarr",
        omega0=[1.0, 0.1, 0.5],
        chunk=chunk,
        progress=False,
    )
    lz = ep.Trajectory.open(path)
    assert isinstance(lz, rd.LazyTrajectory)

    decoded = []
    direct = rd._DirectChunks._chunk

    def counting(self, k, out=None):
        decoded.append((str(self.root), k))
        return direct(self, k, out)

    def refuse(*args, **kwargs):
        raise AssertionError("the view read the whole store")

    monkeypatch.setattr(rd._DirectChunks, "_chunk", counting)
    monkeypatch.setattr(rd.LazyTrajectory, "load", refuse)
    monkeypatch.setattr(rd.StoredArray, "__array__", refuse)
    monkeypatch.setattr(htmlrepr, "STORED_POINTS", 4)
    page = lz._repr_html_()
    p = well_formed(page)
    text = "".join(p.text)
    assert "&lt;script&gt;" in page and "<script>" not in page
    assert f"4 of {T} samples" in page and "Zarr store" in text and "drift (max over 4 samples read)" in text
    assert p.tags.count("svg") == 2
    chunks = {k for _, k in decoded}
    assert 0 < len(chunks) <= 4 < T // chunk  # four chunks of twenty
    assert chunks == {0, 6, 13, 19}  # the samples 0, 133, 266, 399

    monkeypatch.setattr(htmlrepr, "STORED_POINTS", 64)
    monkeypatch.setattr(htmlrepr, "STORED_BUDGET", 3 * chunk)  # each sample costs a chunk
    decoded.clear()
    well_formed(lz._repr_html_())
    assert len({k for _, k in decoded}) == 3


# ---------------------------------------------------------------------------
# the fit and the audit
# ---------------------------------------------------------------------------
def test_fit_result():
    body = ep.RigidBody([0.25, 0.33, 0.42])
    t = np.linspace(0.0, 10.0, 21)
    tr = ep.solve(body, t, omega0=[0.1, 0.2, 1.0])
    res = ep.fit(t, omega=tr.omega, omega_sigma=1e-3, inertia=[0.25, 0.33, 0.42])
    page = res._repr_html_()
    text = "".join(well_formed(page).text)
    for word in ("FitResult", "chi2 / dof", "omega0_x", "stderr", "principal moments"):
        assert word in text


def test_audit_report():
    pytest.importorskip("sympy")
    from eulerpoisson.paper.audit import ENTRIES, run_audit

    rep = run_audit(entries=[e for e in ENTRIES if e.equation == "1.12"], integrability=False)
    page = rep._repr_html_()
    text = "".join(well_formed(page).text)
    assert "misprint 1" in text and "1.12" in text
    assert htmlrepr.esc(rep.entries[0].spec.title) in page
