r"""The report of the paper audit and its writers: Markdown, LaTeX, JSON (part of :mod:`.audit`).

An :class:`AuditReport` holds the results of every entry and the
integrability summary; it renders itself as Markdown
(:meth:`AuditReport.to_markdown`), a standalone LaTeX document
(:meth:`AuditReport.to_latex`) or JSON, and :func:`write_report` writes one
of them atomically. Re-exported by :mod:`eulerpoisson.paper.audit`.

Examples
--------
>>> sorted(set(FORMATS.values()))
['json', 'md', 'tex']
"""

from __future__ import annotations

import json
import os
from dataclasses import dataclass

import numpy as np

from ..errors import InvalidInputError
from ..io.atomic import atomic_write_text
from ..io.outputs import mark_text
from .audit_checks import EntryResult
from .symbolic import sympy_module as _sp

__all__ = [
    "STATUSES",
    "FORMATS",
    "AuditReport",
    "write_report",
]

STATUSES = ("confirmed", "misprint", "not-checkable")
#: Report formats accepted by :func:`write_report` (and aliases).
FORMATS = {"md": "md", "markdown": "md", "json": "json", "tex": "tex", "latex": "tex"}


# ---------------------------------------------------------------------------
# report
# ---------------------------------------------------------------------------


@dataclass
class AuditReport:
    """The result of :func:`run_audit`.

    Attributes
    ----------
    entries : list of EntryResult
    integrability : dict
        Pairwise brackets of :math:`(H, \\mathbf m^2, m_3)`, Jacobian rank,
        Pfaffians/determinants of the Poisson tensors in :math:`(\\mathbf n,
        \\mathbf m)`, :math:`(\\mathbf n, \\boldsymbol\\Omega)`,
        :math:`(\\mathbf n, \\mathbf M)` and the linearised comparison with
        :math:`e(3)`.
    elapsed_s : float
        Wall-clock seconds of the run.
    meta : dict
        Versions, seed, points per comparison.
    """

    entries: list
    integrability: dict
    elapsed_s: float
    meta: dict

    def summary(self) -> dict:
        """Counts per status and the list of misprints (equation, what differs, corrected)."""
        counts = {s: 0 for s in STATUSES}
        for e in self.entries:
            counts[e.status] += 1
        return {
            "counts": counts,
            "total": len(self.entries),
            "misprints": [
                {
                    "equation": e.equation,
                    "title": e.spec.title,
                    "summary": e.differs_summary,
                    "differs": e.differs,
                    "corrected": e.corrected,
                }
                for e in self.entries
                if e.status == "misprint"
            ],
        }

    def entry(self, equation: str) -> EntryResult:
        """The result for ``equation`` (e.g. ``"1.16"``).

        Raises
        ------
        InvalidInputError
            If no entry has that label.
        """
        for e in self.entries:
            if e.equation == equation:
                return e
        raise InvalidInputError(f"no audit entry for equation {equation!r}")

    def to_dict(self) -> dict:
        return {
            "paper": "A. A. Deriglazov, Geodesic motion on the symplectic leaf of SO(3) with distorted e(3) algebra and Liouville integrability of a free rigid body",
            "summary": self.summary(),
            "meta": self.meta,
            "elapsed_s": self.elapsed_s,
            "integrability": _jsonable(self.integrability),
            "entries": [e.to_dict() for e in self.entries],
        }

    def to_json(self, indent: int = 2) -> str:
        """JSON text: an object with ``summary``, ``integrability`` and one object per entry in ``entries``."""
        return json.dumps(self.to_dict(), indent=indent, ensure_ascii=True)

    def to_markdown(self) -> str:
        """A Markdown report (GitHub flavoured, math in ``$...$``)."""
        return _to_markdown(self)

    def to_latex(self) -> str:
        """A complete standalone LaTeX document (article, longtable)."""
        return _to_latex(self)

    def _repr_html_(self) -> str:
        """A compact HTML table for notebooks: :func:`eulerpoisson.util.htmlrepr.audit_html`."""
        from ..util.htmlrepr import audit_html

        return audit_html(self)


def _jsonable(x):
    sp = _sp()
    if isinstance(x, dict):
        return {str(k): _jsonable(v) for k, v in x.items()}
    if isinstance(x, (list, tuple)):
        return [_jsonable(v) for v in x]
    if isinstance(x, (bool, int, float, str)) or x is None:
        return x
    if isinstance(x, np.generic):
        return x.item()
    if isinstance(x, sp.Basic):
        return str(x)
    return str(x)


# ---------------------------------------------------------------------------
# rendering
# ---------------------------------------------------------------------------


def _clean_paper_latex(s: str) -> str:
    """Make a snippet of the paper's source usable in a standalone document."""
    import re

    s = re.sub(r"\\ref\{u([0-9.]+)\}", r"\1", s)
    s = re.sub(r"\\cite\{([^}]*)\}", r"[\1]", s)
    s = re.sub(r"\\label\{[^}]*\}", "", s)
    s = s.replace("\\cr", "\\\\")
    return s


def _md_math(s: str) -> str:
    s = _clean_paper_latex(s).replace("\n", " ").strip()
    if "$" in s or (" " in s and not any(ch in s for ch in "\\^_{}=")):
        return "> " + s  # a prose claim (possibly with inline math)
    return "$$" + s + "$$"


def _md_text(s: str | None) -> str:
    if not s:
        return ""
    return _clean_paper_latex(s).replace("|", "\\|").replace("\n", " ")


def _to_markdown(rep: AuditReport) -> str:
    summ = rep.summary()
    out = ["# Audit of the paper (machine-checked)", ""]
    out.append(
        f"Entries: {summ['total']}; confirmed: {summ['counts']['confirmed']}, misprint: {summ['counts']['misprint']}, "
        f"not-checkable: {summ['counts']['not-checkable']}. Run time: {rep.elapsed_s:.1f} s. "
        f"SymPy {rep.meta.get('sympy')}, seed {rep.meta.get('seed')}, {rep.meta.get('points_per_comparison')} random points per comparison."
    )
    out.append("")
    out.append("| Equation | Status | Method | Inertia | Title |")
    out.append("|---|---|---|---|---|")
    for e in rep.entries:
        out.append(f"| {e.equation} | **{e.status}** | {e.method} | {e.inertia} | {_md_text(e.spec.title)} |")
    out.append("")
    if summ["misprints"]:
        out.append("## Misprints")
        out.append("")
        for m in summ["misprints"]:
            out.append(f"- **{m['equation']}** ({_md_text(m['title'])}): {_md_text(m['summary'])}")
            if m["corrected"]:
                out.append(f"  - corrected: {_md_math(m['corrected'])}")
        out.append("")
    out.append("## Entries")
    for e in rep.entries:
        out.append("")
        out.append(f"### {e.equation} — {_md_text(e.spec.title)}")
        out.append("")
        out.append(
            f"*Status:* **{e.status}** · *method:* {e.method} · *inertia:* {e.inertia} · *section:* {_md_text(e.spec.section)}"
        )
        out.append("")
        out.append(f"*Context:* {_md_text(e.spec.context)}")
        out.append("")
        out.append("*Printed:*")
        out.append("")
        out.append(_md_math(e.printed))
        out.append("")
        out.append("*Derived:*")
        out.append("")
        out.append(_md_math(e.derived))
        if e.corrected:
            out.append("")
            out.append("*Corrected:*")
            out.append("")
            out.append(_md_math(e.corrected))
        if e.differs:
            out.append("")
            out.append(f"*What differs:* {_md_text(e.differs)}")
        if e.simpler:
            out.append("")
            out.append("*Simpler equivalent form:*")
            out.append("")
            out.append(_md_math(e.simpler))
        out.append("")
        out.append(f"*Note:* {_md_text(e.note)}")
        out.append("")
        out.append("| Check | Result | Method | Transcription |")
        out.append("|---|---|---|---|")
        for c in e.checks:
            res = "ok" if c.ok else "FAILS"
            extra = ("; " + "; ".join(c.details)) if c.details else ""
            out.append(
                f"| {_md_text(c.label)} | {res}{_md_text(extra)} | {c.method} | `{c.transcription.replace('|', '/')}` |"
            )
    out.append("")
    out.append("## Integrability (computed)")
    out.append("")
    integ = rep.integrability
    if integ:
        for k, v in integ["involution"].items():
            kk = k.replace("{", r"\{").replace("}", r"\}").replace("m^2", r"\mathbf m^2")
            out.append(f"- ${kk}$ = {v}")
        out.append(
            f"- rank of the Jacobian of $(H, \\mathbf m^2, m_3)$ w.r.t. $(\\mathbf n, \\boldsymbol\\pi)$: {integ['jacobian_rank']} (random rational points: {integ['jacobian_ranks_at_random_points']})"
        )
        for chart, name in (("nm", "(n, m)"), ("nOmega", "(n, Omega)"), ("nM", "(n, M)")):
            out.append(
                f"- Poisson tensor in {name}: Pfaffian ${integ['pfaffian_' + chart + '_latex']}$, determinant ${integ['det_' + chart + '_latex']}$"
            )
            e3 = integ[f"e3_{chart}"]
            out.append(
                f"  - linearised at 0 vs $e(3)$ ({e3['identification']}); difference: $${e3['difference_latex']}$$"
            )
    out.append("")
    return "\n".join(out)


def _tex_escape(s: str) -> str:
    parts = s.split("->")
    if len(parts) > 1:
        return r"$\rightarrow$".join(_tex_escape(p) for p in parts)
    rep = {
        "\\": r"\textbackslash{}",
        "&": r"\&",
        "%": r"\%",
        "#": r"\#",
        "_": r"\_",
        "{": r"\{",
        "}": r"\}",
        "~": r"\textasciitilde{}",
        "^": r"\textasciicircum{}",
        "$": r"\$",
        "<": r"\textless{}",
        ">": r"\textgreater{}",
        "|": r"\textbar{}",
    }
    out = "".join(rep.get(c, c) for c in s)
    return "".join(c if ord(c) < 128 else "?" for c in out)


def _tex_text(s: str | None) -> str:
    """Text with inline $math$: escape the text parts, keep the math."""
    if not s:
        return ""
    parts = s.split("$")
    out = []
    for i, p in enumerate(parts):
        if i % 2 == 0:
            out.append(_tex_escape(p))
        elif len(p) > 180:
            out.append(r"\par\noindent\resizebox{\linewidth}{!}{$\displaystyle " + _clean_paper_latex(p) + r"$}\par ")
        else:
            out.append("$" + _clean_paper_latex(p) + "$")
    if len(parts) % 2 == 0:  # unbalanced: escape the rest
        return _tex_escape(s)
    return "".join(out)


def _tex_context(s: str) -> str:
    """A sentence of the paper's source: keep its LaTeX, drop footnote wrappers."""
    s = _clean_paper_latex(s)
    s = s.replace("\\footnote{", "{")
    return "".join(c if ord(c) < 128 else "?" for c in s)


def _tex_display(s: str) -> str:
    s = _clean_paper_latex(s).strip()
    if s.startswith("$") and s.endswith("$"):
        s = s[1:-1]
    if "$" in s:
        # a prose claim with inline math: typeset as text
        return r"\begin{quote}" + _tex_text(s) + r"\end{quote}"
    if not any(ch in s for ch in "\\^_{}=") and " " in s:
        return r"\begin{quote}" + _tex_escape(s) + r"\end{quote}"
    return r"\begin{gather*}" + "\n" + s + "\n" + r"\end{gather*}"


def _to_latex(rep: AuditReport) -> str:
    summ = rep.summary()
    L = []
    L.append(r"\documentclass[a4paper,10pt]{article}")
    L.append(r"\usepackage[T1]{fontenc}")
    L.append(r"\usepackage{amsmath,amssymb}")
    L.append(r"\usepackage{longtable,array,graphicx}")
    L.append(r"\setlength{\textwidth}{16.5cm}\setlength{\oddsidemargin}{-0.3cm}\setlength{\evensidemargin}{-0.3cm}")
    L.append(r"\setlength{\textheight}{24cm}\setlength{\topmargin}{-1.5cm}")
    L.append(r"\allowdisplaybreaks")
    L.append(r"\sloppy")
    L.append(
        r"\title{Machine-checked audit of: Geodesic motion on the symplectic leaf of $SO(3)$ with distorted $e(3)$ algebra and Liouville integrability of a free rigid body}"
    )
    L.append(r"\author{eulerpoisson " + _tex_escape(str(rep.meta.get("eulerpoisson", ""))) + r"}")
    L.append(r"\date{}")
    L.append(r"\begin{document}")
    L.append(r"\maketitle")
    c = summ["counts"]
    L.append(
        _tex_escape(
            f"Entries: {summ['total']}; confirmed: {c['confirmed']}, misprint: {c['misprint']}, not-checkable: {c['not-checkable']}. "
            f"Run time {rep.elapsed_s:.1f} s, SymPy {rep.meta.get('sympy')}, seed {rep.meta.get('seed')}, "
            f"{rep.meta.get('points_per_comparison')} random rational points per comparison. "
            "Printed formulas are transcribed literally; derived ones are computed from the Lagrangian with a general symmetric inertia tensor unless stated."
        )
    )
    L.append(r"\section*{Summary}")
    L.append(r"\begin{longtable}{p{3.2cm}p{2.0cm}p{3.2cm}p{1.5cm}p{5.4cm}}")
    L.append(
        r"\textbf{Equation} & \textbf{Status} & \textbf{Method} & \textbf{Inertia} & \textbf{Title}\\ \hline \endhead"
    )
    for e in rep.entries:
        L.append(
            f"{_tex_escape(e.equation)} & {_tex_escape(e.status)} & {_tex_escape(e.method)} & {_tex_escape(e.inertia)} & {_tex_escape(e.spec.title)} \\\\"
        )
    L.append(r"\end{longtable}")
    if summ["misprints"]:
        L.append(r"\section*{Misprints}")
        L.append(r"\begin{itemize}")
        for m in summ["misprints"]:
            L.append(
                r"\item \textbf{"
                + _tex_escape(m["equation"])
                + "} ("
                + _tex_escape(m["title"])
                + "): "
                + _tex_text(m["summary"])
            )
            if m["corrected"]:
                L.append(r"\par\noindent Corrected: " + _tex_math_block(m["corrected"]))
        L.append(r"\end{itemize}")
    L.append(r"\section*{Entries}")
    for e in rep.entries:
        L.append(r"\subsection*{" + _tex_escape(f"{e.equation}: {e.spec.title}") + "}")
        L.append(
            r"\textbf{Status:} "
            + _tex_escape(e.status)
            + r"\quad \textbf{Method:} "
            + _tex_escape(e.method)
            + r"\quad \textbf{Inertia:} "
            + _tex_escape(e.inertia)
            + r"\par"
        )
        L.append(r"\noindent\textbf{Context:} " + _tex_context(e.spec.context) + r"\par")
        L.append(r"\noindent\textbf{Printed:}")
        L.append(_tex_display(e.printed))
        L.append(r"\noindent\textbf{Derived:}")
        L.append(_tex_math_block(e.derived))
        if e.corrected:
            L.append(r"\noindent\textbf{Corrected:}")
            L.append(_tex_math_block(e.corrected))
        if e.differs:
            L.append(r"\noindent\textbf{What differs:} " + _tex_text(e.differs) + r"\par")
        if e.simpler:
            L.append(r"\noindent\textbf{Simpler equivalent form:}")
            L.append(_tex_math_block(e.simpler))
        L.append(r"\noindent\textbf{Note:} " + _tex_text(e.note) + r"\par")
        L.append(r"\begin{longtable}{p{4.2cm}p{1.4cm}p{3.3cm}p{6.3cm}}")
        L.append(r"\textbf{Check} & \textbf{Result} & \textbf{Method} & \textbf{Details}\\ \hline \endhead")
        for ch in e.checks:
            det = "; ".join(d if "$" in d else d for d in ch.details)
            L.append(
                f"{_tex_escape(ch.label)} & {'ok' if ch.ok else 'FAILS'} & {_tex_escape(ch.method)} & {_tex_text(det) if det.count('$') % 2 == 0 else _tex_escape(det)} \\\\"
            )
        L.append(r"\end{longtable}")
    integ = rep.integrability
    if integ:
        L.append(r"\section*{Integrability (computed)}")
        L.append(r"\begin{itemize}")
        for k, v in integ["involution"].items():
            L.append(
                r"\item $"
                + k.replace("{", r"\{").replace("}", r"\}").replace("m^2", r"\mathbf m^2")
                + "$ = "
                + _tex_escape(v)
            )
        L.append(
            r"\item Rank of the Jacobian of $(H,\mathbf m^2,m_3)$ with respect to $(\mathbf n,\boldsymbol\pi)$: "
            + _tex_escape(str(integ["jacobian_rank"]))
        )
        for chart, name in (
            ("nm", r"(\mathbf n,\mathbf m)"),
            ("nOmega", r"(\mathbf n,\boldsymbol\Omega)"),
            ("nM", r"(\mathbf n,\mathbf M)"),
        ):
            L.append(
                r"\item Poisson tensor in $"
                + name
                + r"$: Pfaffian $"
                + integ[f"pfaffian_{chart}_latex"]
                + r"$, determinant $"
                + integ[f"det_{chart}_latex"]
                + "$."
            )
            e3 = integ[f"e3_{chart}"]
            L.append(
                r" Linearised at the origin minus $e(3)$ ("
                + _tex_escape(e3["identification"])
                + r"):"
                + r"\begin{gather*}"
                + e3["difference_latex"]
                + r"\end{gather*}"
            )
        L.append(r"\end{itemize}")
    L.append(r"\end{document}")
    return "\n".join(L) + "\n"


def _tex_math_block(s: str) -> str:
    """Display the ';\\quad'-joined members, shrinking those too wide for the line."""
    out = []
    for member in _clean_paper_latex(s).split(r" ;\quad "):
        if len(member) > 220:
            out.append(r"\par\noindent\resizebox{\linewidth}{!}{$\displaystyle " + member + r"$}\par")
        else:
            out.append(r"\begin{gather*}" + "\n" + member + "\n" + r"\end{gather*}")
    return "\n".join(out)


def write_report(report: AuditReport, fmt: str, path: str | os.PathLike[str]) -> str:
    """Write a report atomically (temporary file in the target directory, then :func:`os.replace`), marked as
    written by eulerpoisson (:func:`eulerpoisson.io.outputs.mark_text`).

    Parameters
    ----------
    report : AuditReport
    fmt : {"md", "markdown", "json", "tex", "latex"}
    path : str or os.PathLike
        Target file; its directory must exist.

    Returns
    -------
    str
        The path written.

    Raises
    ------
    InvalidInputError
        Unknown format, wrong report type, or a missing target directory.
    """
    if not isinstance(report, AuditReport):
        raise InvalidInputError(f"report must be an AuditReport, got {type(report).__name__}")
    if not isinstance(fmt, str) or fmt.lower() not in FORMATS:
        raise InvalidInputError(f"unknown format {fmt!r}; expected one of {sorted(FORMATS)}")
    kind = FORMATS[fmt.lower()]
    # marked as ours (io.outputs.content_kind: ``audit --overwrite`` may replace it, never another file)
    text = mark_text(
        {"md": report.to_markdown, "json": report.to_json, "tex": report.to_latex}[kind](), "audit-report", kind
    )
    path = os.fspath(path)
    directory = os.path.dirname(os.path.abspath(path))
    if not os.path.isdir(directory):
        raise InvalidInputError(f"path {path!r}: directory {directory!r} does not exist")
    atomic_write_text(path, text)
    return path
