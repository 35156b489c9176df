r"""HTML views for notebooks: the ``_repr_html_`` of bodies, models, trajectories, fits and the audit.

Jupyter shows an object by its ``_repr_html_``. These are compact tables,
every text escaped with :func:`html.escape`; a batch is summarized (its
shape, the range of each quantity, the first few bodies), never dumped. A
trajectory adds a small inline SVG picture of :math:`\boldsymbol\Omega(t)`
and of the relative change of the energy, drawn from the data with plain
string building (no matplotlib): long runs are decimated to a min/max
envelope per pixel column (:class:`~eulerpoisson.viz.decimate.MinMaxEnvelope`),
so the page stays small at any length (about 14 kB for :math:`10^6`
samples), and a stored trajectory
(:class:`~eulerpoisson.io.read.LazyTrajectory`) is drawn from a few samples
spread over the run, so that showing it reads a few chunks, not the file.

Examples
--------
>>> import eulerpoisson as ep
>>> page = ep.RigidBody([1.0, 2.0, 3.0], name="<box>")._repr_html_()
>>> page.startswith("<div"), "&lt;box&gt;" in page, "<box>" in page
(True, True, False)
"""

from __future__ import annotations

import html
from collections import Counter

import numpy as np

__all__ = ["table", "sparkline_svg", "body_html", "model_html", "trajectory_html", "fit_html", "audit_html"]

#: bodies listed one by one in the view of a batch
MAX_BODIES = 5
#: columns of the inline pictures (two points per column: the min/max envelope)
SPARK_COLUMNS = 150
#: size of each inline picture, pixels
SPARK_WIDTH, SPARK_HEIGHT = 300, 48
#: the drift in a view is the maximum over at most this many samples times bodies (evenly spread, the
#: first and the last included): about 0.1 s
DRIFT_LIMIT = 100_000
#: samples of a stored trajectory read for its picture: at most this many (and those of at most
#: ``STORED_BUDGET`` decoded samples: a sample costs the decoding of its whole chunk)
STORED_POINTS = 64
STORED_BUDGET = 1_000_000
#: series colours (matplotlib's first four)
COLORS = ("#1f77b4", "#ff7f0e", "#2ca02c", "#d62728")

#: one style sheet per view, scoped by its class (cells carry no style of their own: smaller pages)
_STYLE = (
    "<style>.eulerpoisson-repr table{border-collapse:collapse;font-size:12px;margin:2px 0}"
    ".eulerpoisson-repr th,.eulerpoisson-repr td{padding:1px 8px;text-align:left;vertical-align:top;"
    "border-bottom:1px solid #ddd}.eulerpoisson-repr caption{text-align:left;font-weight:bold}"
    ".eulerpoisson-repr .note{font-size:11px;color:#555}</style>"
)


class Raw(str):
    """Markup already built (and escaped) here: :func:`table` inserts it as it is."""


def esc(x) -> str:
    """``html.escape(str(x))``, the text of any value made safe to put into a page."""
    return html.escape(str(x), quote=True)


def num(x) -> str:
    """A number in six significant digits (``nan``, ``inf`` as they are)."""
    try:
        return f"{float(x):.6g}"
    except (TypeError, ValueError):
        return str(x)


def vec(a) -> str:
    """A short vector ``[1, 2, 3]`` in six significant digits."""
    return "[" + ", ".join(num(x) for x in np.asarray(a, dtype=float).reshape(-1)) + "]"


def span(a) -> str:
    """``min … max`` of an array (``value`` when they are equal, ``empty`` without values)."""
    a = np.asarray(a, dtype=float)
    if a.size == 0:
        return "empty"
    lo, hi = float(np.nanmin(a)), float(np.nanmax(a))
    return num(lo) if lo == hi else f"{num(lo)} … {num(hi)}"


def _cell(v) -> str:
    return v if isinstance(v, Raw) else esc(v)


def table(title, rows, extra: str = "") -> Raw:
    """A two-column table ``<th>key</th><td>value</td>`` under a caption ``title``, in a ``<div>``.

    ``rows`` are ``(key, value)`` pairs; values are escaped unless they are
    :class:`Raw` (markup built here). ``extra`` (markup) follows the table.
    """
    body = "".join(f"<tr><th>{_cell(k)}</th><td>{_cell(v)}</td></tr>" for k, v in rows)
    return Raw(
        f'<div class="eulerpoisson-repr">{_STYLE}<table><caption>{_cell(title)}</caption>'
        f"<tbody>{body}</tbody></table>{extra}</div>"
    )


def grid(header, rows) -> Raw:
    """A table with a header row (``header``: column names) and ``rows`` of cells (escaped unless :class:`Raw`)."""
    head = "".join(f"<th>{_cell(h)}</th>" for h in header)
    body = "".join("<tr>" + "".join(f"<td>{_cell(c)}</td>" for c in r) + "</tr>" for r in rows)
    return Raw(f"<table><thead><tr>{head}</tr></thead><tbody>{body}</tbody></table>")


# ---------------------------------------------------------------------------
# inline pictures
# ---------------------------------------------------------------------------
def sparkline_svg(
    t,
    series,
    labels=(),
    *,
    title: str = "",
    columns: int = SPARK_COLUMNS,
    width: int = SPARK_WIDTH,
    height: int = SPARK_HEIGHT,
    colors=COLORS,
) -> Raw:
    """A small SVG line picture of ``series`` (k arrays of the times ``t``), one colour each (``colors``).

    Decimated to ``columns`` columns, each drawn through the minimum and the
    maximum of its samples (the picture contains every sample's value), so
    the markup has at most ``2 columns`` points per series whatever the
    length. One vertical scale for all series; its range and the time range
    are written under the picture. Empty (``""``) with fewer than two
    distinct times or no finite value.
    """
    from ..viz.decimate import MinMaxEnvelope

    t = np.asarray(t, dtype=float).reshape(-1)
    ys = [np.asarray(s, dtype=float).reshape(-1) for s in series]
    if t.size < 2 or not ys:
        return Raw("")
    t0, t1 = float(np.min(t)), float(np.max(t))
    if not t1 > t0:
        return Raw("")
    if t.size <= 2 * columns:  # few samples: drawn as they are
        order = np.argsort(t, kind="stable")
        x, y = t[order], np.stack([s[order] for s in ys], axis=-1)
    else:  # the extremes of every column
        env = MinMaxEnvelope(t0, t1, len(ys), nbins=max(1, int(columns)))
        env.add(t, ys)
        x, y = env.points()
    ok = np.isfinite(y)
    if not ok.any():
        return Raw("")
    lo, hi = float(np.min(y[ok])), float(np.max(y[ok]))
    pad = 2.0
    if hi > lo:
        scale = (height - 2 * pad) / (hi - lo)
    else:
        scale = 0.0
    px = (x - t0) / (t1 - t0) * (width - 2 * pad) + pad
    parts = []
    for j in range(len(ys)):
        py = height - pad - (y[:, j] - lo) * scale if hi > lo else np.full(x.shape, height / 2.0)
        keep = np.isfinite(py)
        pts = " ".join(f"{a:.1f},{b:.1f}" for a, b in zip(px[keep], py[keep]))
        parts.append(f'<polyline fill="none" stroke="{colors[j % len(colors)]}" stroke-width="1" points="{pts}"/>')
    tip = f"<title>{esc(title)}</title>" if title else ""
    svg = (
        f'<svg xmlns="http://www.w3.org/2000/svg" width="{width}" height="{height}" '
        f'viewBox="0 0 {width} {height}" role="img" style="background:#fafafa">{tip}{"".join(parts)}</svg>'
    )
    keys = " ".join(f'<span style="color:{colors[j % len(colors)]}">{esc(lab)}</span>' for j, lab in enumerate(labels))
    note = f'<div class="note">{keys} in [{esc(num(lo))}, {esc(num(hi))}], t in [{esc(num(t0))}, {esc(num(t1))}]</div>'
    return Raw(f'<div style="margin:2px 0">{svg}{note}</div>')


# ---------------------------------------------------------------------------
# bodies and models
# ---------------------------------------------------------------------------
def _kinds(body) -> str:
    k = body.kind
    if isinstance(k, str):
        return k
    return ", ".join(f"{name} × {n}" for name, n in Counter(np.asarray(k).reshape(-1).tolist()).most_common())


def body_rows(body) -> list:
    """The rows describing a body or a batch of bodies (used by every view that shows a body)."""
    rows = []
    if body.name:
        rows.append(("name", str(body.name)))
    shape = body.batch_shape
    if shape == ():
        rows.append(("principal moments", vec(body.principal_moments)))
        rows.append(("kind", _kinds(body) + (", planar" if body.is_planar else "")))
        if not body.is_diagonal:
            rows.append(("inertia tensor", "; ".join(vec(r) for r in body.inertia)))
        if body.masses is not None:
            rows.append(("particles", f"{len(body.masses)} point masses, total mass {num(np.sum(body.masses))}"))
        return rows
    n = int(np.prod(shape))
    rows.append(("batch", f"{n} bodies, batch shape {shape}"))
    mom = body.principal_moments.reshape(-1, 3)
    rows.append(("principal moments", "; ".join(f"I{i + 1}: {span(mom[:, i])}" for i in range(3))))
    rows.append(("kinds", _kinds(body)))
    rows.append(("frame", "principal (diagonal tensors)" if body.is_diagonal else "full tensors"))
    first = ", ".join(vec(m) for m in mom[:MAX_BODIES]) + (", …" if n > MAX_BODIES else "")
    rows.append((f"first {min(n, MAX_BODIES)}", first))
    return rows


def body_html(body) -> Raw:
    """The view of a :class:`~eulerpoisson.RigidBody` (one or a batch)."""
    return table("RigidBody", body_rows(body))


def _torque_rows(model) -> list:
    if model.is_free:
        return [("torque", "none (free body)")]
    rows = [("torque" if i == 0 else "", repr(t)) for i, t in enumerate(model.torques)]
    flags = [w for w, on in (("conservative", model.is_conservative), ("autonomous", model.is_autonomous)) if on]
    if flags:
        rows.append(("", ", ".join(flags)))
    return rows


def model_html(model) -> Raw:
    """The view of a :class:`~eulerpoisson.Model`: the body and the torques."""
    rows = body_rows(model.body) + _torque_rows(model)
    if model.batch_shape != model.body.batch_shape:
        rows.append(("batch shape", str(model.batch_shape)))
    return table("Model", rows)


# ---------------------------------------------------------------------------
# trajectories
# ---------------------------------------------------------------------------
def _first_body(a, bshape):
    """The first body of a batch: ``a[(0,) * len(bshape)]`` of an array (*batch, T, ...)."""
    return a[(0,) * len(bshape)] if bshape else a


def _pictures(tr, label: str) -> Raw:
    """Ω(t) and the relative change of the energy of the first body of ``tr`` (an in-memory trajectory)."""
    bshape = tr.batch_shape
    t = tr.t
    w = _first_body(tr.omega, bshape)
    pics = [sparkline_svg(t, [w[:, 0], w[:, 1], w[:, 2]], ("Ω1", "Ω2", "Ω3"), title=f"body angular velocity{label}")]
    try:
        E = _first_body(tr.energy, bshape)
    except Exception:  # noqa: BLE001 - a torque whose potential cannot be evaluated here: no energy picture
        E = None
    if E is not None and E.size:
        E0 = float(E[0])
        rel = (E - E0) / abs(E0) if E0 != 0 else E - E0
        pics.append(
            sparkline_svg(
                t, [rel], ("(E − E0)/|E0|" if E0 != 0 else "E − E0",), title=f"energy change{label}", colors=COLORS[3:]
            )
        )
    return Raw("".join(pics))


def _drift_text(d: dict) -> str:
    parts = []
    for k, v in d.items():
        v = np.asarray(v, dtype=float)
        parts.append(f"{k} {num(np.max(v)) if v.size else 'n/a'}")
    return ", ".join(parts) if parts else "no known integral"


def _options_text(options: dict) -> str:
    items = list(options.items())
    text = ", ".join(f"{k}={v!r}" for k, v in items[:6]) + (", …" if len(items) > 6 else "")
    return text[:300]


def trajectory_html(tr) -> Raw:
    """The view of a :class:`~eulerpoisson.Trajectory` (in memory) or of a stored one (read on demand)."""
    if getattr(tr, "lazy", False):
        return _stored_html(tr)
    T = len(tr.t)
    bshape = tr.batch_shape
    nb = int(np.prod(bshape)) if bshape else 1
    rows = [("method", tr.method or "?")]
    if tr.options:
        rows.append(("options", _options_text(tr.options)))
    rows.append(("samples", f"{T}" + (f" × {nb} bodies (batch shape {bshape})" if bshape else "")))
    if T:
        rows.append(("t", f"{num(tr.t[0])} → {num(tr.t[-1])}"))
        rows.append(("|Ω|", span(np.sqrt(np.sum(tr.omega**2, -1)))))
    rows += body_rows(tr.body) + _torque_rows(tr.model)
    extra = ""
    if T:
        try:
            over = ", bodies)" if bshape else ")"
            if T * nb <= DRIFT_LIMIT:
                rows.append(("drift (max over t" + over, _drift_text(tr.drift())))
            else:  # a long run: the maximum over evenly spread samples (first and last included)
                k = max(2, DRIFT_LIMIT // nb)
                idx = np.unique(np.linspace(0, T - 1, k).round().astype(np.int64))
                rows.append((f"drift (max over {len(idx)} of {T} samples" + over, _drift_text(tr[idx].drift())))
        except Exception as exc:  # noqa: BLE001 - a view never fails: it says why
            rows.append(("drift", f"not computed ({exc})"))
        if T >= 2:
            try:
                extra = _pictures(tr, " (first body)" if bshape else "")
            except Exception as exc:  # noqa: BLE001
                extra = Raw(f"<div>{esc(f'no picture: {exc}')}</div>")
    if "wall_time" in tr.stats:
        rows.append(("wall time", f"{num(tr.stats['wall_time'])} s"))
    return table("Trajectory", rows, extra)


def stored_samples(lz) -> np.ndarray:
    """Indices of the samples of a stored trajectory drawn in its view: evenly spread, first and last included.

    At most :data:`STORED_POINTS`, and at most ``STORED_BUDGET / chunk`` of
    them (reading one sample decodes its whole chunk), never fewer than 2.
    """
    T = len(lz)
    k = min(T, STORED_POINTS, max(2, STORED_BUDGET // max(1, int(lz.chunk))))
    return np.unique(np.linspace(0, T - 1, max(k, min(T, 2))).round().astype(np.int64))


def _stored_html(lz) -> Raw:
    T = len(lz)
    bshape = lz.batch_shape
    rows = [("file", str(lz.path)), ("format", "Zarr store, read on demand"), ("method", lz.method or "?")]
    if lz.options:
        rows.append(("options", _options_text(lz.options)))
    rows.append(
        (
            "samples",
            f"{T}"
            + (f" × {int(np.prod(bshape))} bodies (batch shape {bshape})" if bshape else "")
            + f", chunks of {lz.chunk}",
        )
    )
    part, extra, drift = None, "", []
    if T:
        try:
            idx = stored_samples(lz)
            part = lz.gather(idx)
            rows.append(("t", f"{num(part.t[0])} → {num(part.t[-1])}"))
            drift = [(f"drift (max over {len(idx)} samples read)", _drift_text(part.drift()))]
            if len(idx) >= 2:
                extra = _pictures(part, f" ({len(idx)} of {T} samples" + (", first body)" if bshape else ")"))
        except Exception as exc:  # noqa: BLE001 - an unfinished store, an unreadable chunk: said, not raised
            drift = [("samples read", f"not readable ({exc})")]
    rows += body_rows(lz.body) + _torque_rows(lz.model) + drift
    return table("Trajectory (stored)", rows, extra)


# ---------------------------------------------------------------------------
# fits and the audit
# ---------------------------------------------------------------------------
def fit_html(res) -> Raw:
    """The view of a :class:`~eulerpoisson.FitResult`: the quality of the fit and the parameters with their errors."""
    kinds = ", ".join(f"{k} {len(v)}" for k, v in res.residuals.items() if not k.endswith("_t"))
    rows = [
        ("observations", kinds or "none"),
        ("epoch", num(res.epoch)),
        (
            "chi2 / dof",
            f"{num(res.chi2)} / {res.dof} = {num(res.reduced_chi2)}" + ("" if res.converged else " (NOT converged)"),
        ),
        ("principal moments (trace 1)", vec(res.principal_moments)),
        ("motion", res.mode),
        ("attitude0 (w, x, y, z)", vec(res.attitude0.as_quaternion())),
        ("omega0", vec(res.omega0)),
    ]
    if res.sigma_estimated:
        rows.append(("sigma estimated", ", ".join(f"{k} {num(res.sigma[k])}" for k in res.sigma_estimated)))
    if not res.determined:
        rows.append(("warning", "the data do not determine every unknown (singular normal matrix)"))
    rows.append(("optima", f"{len(res.local_optima)} distinct from {res.n_starts} starts"))
    names = list(res.parameter_names) + [k for k in ("I_zz", "I_1", "I_2", "I_3") if k in res.parameters]
    params = grid(("parameter", "value", "stderr"), [(n, num(res.parameters[n]), num(res.stderr[n])) for n in names])
    return table("FitResult", rows, params)


def audit_html(rep) -> Raw:
    """The view of an :class:`~eulerpoisson.paper.audit.AuditReport`: counts, misprints, then every entry."""
    summ = rep.summary()
    counts = ", ".join(f"{k} {v}" for k, v in summ["counts"].items())
    rows = [
        ("entries", f"{summ['total']}: {counts}"),
        ("run time", f"{num(rep.elapsed_s)} s"),
        ("SymPy", rep.meta.get("sympy", "?")),
        ("seed", rep.meta.get("seed", "?")),
    ]
    for m in summ["misprints"]:
        rows.append((f"misprint {m['equation']}", m["summary"] or m["title"] or ""))
    colour = {"confirmed": "#2ca02c", "misprint": "#d62728"}
    entries = grid(
        ("equation", "status", "method", "title"),
        [
            (
                e.equation,
                Raw(f'<span style="color:{colour.get(e.status, "#555")}">{esc(e.status)}</span>'),
                e.method,
                e.spec.title,
            )
            for e in rep.entries
        ],
    )
    integ = ""
    if rep.integrability:
        integ = esc(f"integrability: Jacobian rank {rep.integrability.get('jacobian_rank', '?')}")
        integ = f'<div class="note">{integ}</div>'
    return table("AuditReport", rows, Raw(f"<details><summary>entries</summary>{entries}</details>{integ}"))
