r"""The checks of one entry of the paper audit and their results (part of :mod:`.audit`).

:func:`audit_entry` runs every check of an entry of
:data:`eulerpoisson.paper.entries.ENTRIES` in its frame and returns an
:class:`EntryResult` (one :class:`CheckResult` per check) whose status is
computed: ``confirmed``, ``misprint`` (with what differs) or
``not-checkable``. Re-exported by :mod:`eulerpoisson.paper.audit`.

Examples
--------
>>> import dataclasses
>>> [f.name for f in dataclasses.fields(CheckResult)][:2]
['label', 'kind']
"""

from __future__ import annotations

import dataclasses
import random
from dataclasses import dataclass, field

from ..errors import InvalidInputError
from .audit_compare import N_POINTS
from .audit_compare import compare as _compare
from .audit_compare import constant_ratio as _constant_ratio
from .audit_compare import display_object as _display_obj
from .audit_compare import display_values as _display
from .audit_compare import prepare as _prepare
from .audit_compare import safe_text as _safe_text
from .audit_compare import short_difference as _short_difference
from .audit_frames import Session as _Session
from .audit_frames import derived_value as _derived
from .audit_language import as_object as _as_object
from .audit_language import compile_source as _compile
from .audit_language import eval_indexed as _eval_indexed
from .audit_language import eval_source as _eval
from .audit_language import resolve as _resolve
from .audit_language import split_chain as _split_chain
from .entries import CheckSpec, EntrySpec
from .symbolic import sympy_module as _sp

__all__ = [
    "CheckResult",
    "EntryResult",
    "audit_entry",
]

# ---------------------------------------------------------------------------
# results
# ---------------------------------------------------------------------------


@dataclass
class CheckResult:
    """Outcome of one :class:`CheckSpec`.

    Attributes
    ----------
    label, kind : str
    ok : bool
        The printed formula agrees with the derivation (claim holds).
    method : str
        ``simplify``, ``random-points``, ``claim`` (or combinations).
    inertia : str
        ``"general"``, ``"diagonal"`` or ``"none"`` (no inertia symbol involved).
    printed_latex, derived_latex : str
    transcription : str
    corrected_ok : bool or None
        Whether the transcribed correction verifies (``None``: no correction
        needed or none given).
    simpler_ok : bool or None
    differs : str or None
        Computed difference (components and expression) plus the
        transcriber's description.
    witness : dict or None
        A random rational point where printed and derived differ.
    details : list of str
    """

    label: str
    kind: str
    ok: bool
    method: str
    inertia: str
    printed_latex: str
    derived_latex: str
    transcription: str
    corrected_ok: bool | None = None
    corrected_latex: str | None = None
    simpler_ok: bool | None = None
    simpler_latex: str | None = None
    differs: str | None = None
    witness: dict | None = None
    details: list = field(default_factory=list)
    summary: str | None = None

    def to_dict(self) -> dict:
        return dataclasses.asdict(self)


@dataclass
class EntryResult:
    """Audit outcome of one :class:`EntrySpec` (see ``to_dict()`` for the JSON fields)."""

    spec: EntrySpec
    status: str
    checks: list
    inertia: str
    method: str
    printed: str
    derived: str
    corrected: str | None
    simpler: str | None
    differs: str | None
    note: str
    differs_summary: str | None = None

    @property
    def equation(self) -> str:
        return self.spec.equation

    def to_dict(self) -> dict:
        s = self.spec
        return {
            "equation": s.equation,
            "title": s.title,
            "section": s.section,
            "status": self.status,
            "printed": self.printed,
            "derived": self.derived,
            "corrected": self.corrected,
            "simpler": self.simpler,
            "differs": self.differs,
            "differs_summary": self.differs_summary,
            "note": self.note,
            "context": s.context,
            "inertia": self.inertia,
            "method": self.method,
            "definition": s.definition,
            "transcription": [c.transcription for c in self.checks],
            "checks": [c.to_dict() for c in self.checks],
        }


def _run_check(session: _Session, entry: EntrySpec, spec: CheckSpec) -> CheckResult:
    sp = _sp()
    D = session.derivation(spec.inertia)
    ns = session.namespace(spec.frame, spec.inertia)
    ns["_points"] = session.points
    rng = random.Random(f"{session.seed}/{entry.equation}/{spec.label}")
    for name, idx, src in spec.let:
        ns[name] = _as_object(_eval_indexed(src, idx, ns), idx)
    printed_latex = spec.latex or entry.latex
    involved = set()

    def note_syms(vals):
        for v in vals:
            if isinstance(v, sp.Basic):
                involved.update(v.free_symbols)

    if spec.kind == "claim":
        v = _eval(_compile(spec.printed), ns, spec.printed)
        ok = bool(v)
        shown = [(t, _display_obj(o, D) if o is not None else None) for t, o in ns["_log"]]
        details = [t if l is None else f"{t}: ${l}$" for t, l in shown]
        derived_latex = r" \\ ".join(l for _, l in shown if l) or (
            r"\text{" + _safe_text("; ".join(t for t, _ in shown), 160) + "}"
        )
        inertia = spec.inertia if _derived_with_inertia(spec) else "none"
        return CheckResult(
            label=spec.label,
            kind="claim",
            ok=ok,
            method="claim",
            inertia=inertia,
            printed_latex=printed_latex,
            derived_latex=derived_latex,
            transcription=spec.printed,
            details=details,
        )

    sides = _split_chain(spec.printed)
    side_vals = [_eval_indexed(s, spec.index, ns) for s in sides]
    for vals in side_vals:
        note_syms(vals)
    if spec.derived is not None:
        d_vals = _derived(spec.derived, ns, D, spec.index)
        note_syms(d_vals)
        refs = [(i, vals, d_vals) for i, vals in enumerate(side_vals)]
    else:
        d_vals = side_vals[0]
        refs = [(i, vals, side_vals[0]) for i, vals in enumerate(side_vals[1:], start=1)]
    methods = set()
    ok = True
    witness = None
    diff_text = []
    for i, vals, ref in refs:
        c = _compare(vals, ref, ns, rng, symbolic=spec.symbolic)
        methods.add(c.method)
        if not c.equal:
            ok = False
            witness = witness or c.witness
            diff_text.append(_describe_difference(sides[i], vals, ref, c.differing, spec.index, i, len(sides), D, ns))
    details = []
    corrected_ok = corrected_latex = None
    simpler_ok = simpler_latex = None
    differs = None
    summary = None
    if not ok:
        ratio = _constant_ratio(side_vals, d_vals, refs)
        ratio_text = f"printed $= {sp.latex(ratio)}\\times$ derived (a constant factor)" if ratio is not None else None
        if ratio_text:
            diff_text.insert(0, ratio_text)
        differs = "; ".join(diff_text)
        if spec.differs:
            differs = spec.differs + ". Computed: " + differs
        summary = spec.differs or ratio_text or diff_text[-1][:300]
        if ratio_text and spec.differs:
            summary = spec.differs + f" (computed: {ratio_text})"
        if spec.corrected:
            c_sides = _split_chain(spec.corrected)
            c_ok = True
            for s in c_sides:
                cv = _eval_indexed(s, spec.index, ns)
                cc = _compare(cv, d_vals, ns, rng, symbolic=spec.symbolic)
                c_ok = c_ok and cc.equal
            corrected_ok = c_ok
            corrected_latex = spec.corrected_latex if c_ok else None
            details.append("transcribed correction verified" if c_ok else "transcribed correction does NOT verify")
        if corrected_latex is None:
            corrected_latex = _display(d_vals, spec.index, D)
            details.append("corrected formula shown as derived")
    if spec.simpler:
        sv = _eval_indexed(spec.simpler, spec.index, ns)
        sc = _compare(sv, d_vals, ns, rng, symbolic=spec.symbolic)
        simpler_ok = sc.equal
        simpler_latex = spec.simpler_latex if sc.equal else None
        details.append("simpler form verified" if sc.equal else "transcribed simpler form does NOT verify")
    derived_latex = _display(d_vals, spec.index, D)
    inertia = spec.inertia if (_derived_with_inertia(spec) or involved & set(D.inertia_symbols)) else "none"
    return CheckResult(
        label=spec.label,
        kind="equal",
        ok=ok,
        method="+".join(sorted(methods)),
        inertia=inertia,
        printed_latex=printed_latex,
        derived_latex=derived_latex,
        transcription=spec.printed,
        corrected_ok=corrected_ok,
        corrected_latex=corrected_latex if not ok else None,
        simpler_ok=simpler_ok,
        simpler_latex=simpler_latex,
        differs=differs,
        witness=witness,
        details=details,
        summary=summary,
    )


_INERTIA_NAMES = {
    "I",
    "Iinv",
    "G",
    "Ginv",
    "H",
    "m",
    "Omega",
    "M",
    "omega",
    "ndot",
    "pidot",
    "Omegadot",
    "mdot",
    "Mdot",
    "L_of_pi",
    "ndot_of_pi",
    "EL",
    "Gamma2",
    "on_shell",
    "lie_symbolic_check",
    "lie_exact_check",
    "lie_numeric_check",
}
_INERTIA_DERIVED = {
    "H",
    "ndot_c",
    "pidot_c",
    "Omega_c",
    "m_c",
    "H_at_origin",
    "L",
    "G",
    "Ginv",
    "momenta",
    "hamilton_pi_residual",
    "hamilton_n_residual",
    "G_at_origin",
    "n2G_at_infinity",
    "G_at_infinity",
    "G_radial",
}


def _code_names(src: str) -> set:
    names = set()
    stack = [_compile(src)]
    while stack:
        code = stack.pop()
        names.update(code.co_names)
        stack.extend(c for c in code.co_consts if hasattr(c, "co_names"))
    return names


def _derived_with_inertia(spec: CheckSpec) -> bool:
    """Whether the check uses objects derived with the inertia tensor (even if it drops out)."""
    if spec.frame in ("nm", "nOmega", "nM"):
        return True  # the chart pi(n, X) comes from m, Omega or M, derived through H
    srcs = [spec.printed] + [src for _, _, src in spec.let]
    names = set().union(*[_code_names(x) for x in srcs])
    if spec.frame in ("canonical", "phase-velocity"):
        if names & _INERTIA_NAMES:
            return True
    elif names & {"I", "Iinv", "G", "Ginv", "EL", "Gamma2", "on_shell", "L"}:
        return True
    return spec.derived in _INERTIA_DERIVED


def _describe_difference(src, vals, ref, differing, index, side, nsides, D, ns) -> str:
    sp = _sp()
    parts = []
    for comp in differing[:3]:
        dv = sp.sympify(_resolve(vals[comp])) - sp.sympify(_resolve(ref[comp]))
        if "alpha" in ns and dv.has(ns["alpha"]):
            dv = _prepare(dv, ns).xreplace({sp.Symbol("tau", real=True): sp.Symbol(r"\tau")})
        parts.append(_component_label(comp, index) + "printed $-$ derived $= " + _short_difference(dv, D) + "$")
    more = len(differing) - 3
    where = f"member {side + 1} of {nsides}: " if nsides > 1 else ""
    if "alpha" in ns and any(
        sp.sympify(vals[c]).has(ns["alpha"]) or sp.sympify(ref[c]).has(ns["alpha"]) for c in differing[:3]
    ):
        where += r"with $\tau=\tan(\alpha/2)$: "
    text = where + f"{len(differing)} of {len(vals)} components differ" + (": " if parts else "") + "; ".join(parts)
    if more > 0:
        text += f" (and {more} more)"
    return text


def _component_label(comp, index) -> str:
    if not index:
        return ""
    digits = []
    c = comp
    for _ in index:
        digits.append(c % 3 + 1)
        c //= 3
    digits.reverse()
    return "component (" + ",".join(f"{n}={d}" for n, d in zip(index, digits)) + "): "


def audit_entry(
    spec: EntrySpec, *, session: _Session | None = None, seed: int = 20240607, points: int = N_POINTS
) -> EntryResult:
    """Audit one entry: evaluate its checks and compute its status.

    Parameters
    ----------
    spec : EntrySpec
        Typically an element of :data:`ENTRIES`, possibly modified with
        :func:`dataclasses.replace` (e.g. to perturb a transcription).
    session : optional
        Internal cache shared by :func:`run_audit`.
    seed : int
        Seed of the random rational points.
    points : int
        Random points per comparison.

    Returns
    -------
    EntryResult

    Raises
    ------
    InvalidInputError
        A transcription cannot be evaluated, or names an unknown frame or
        derived quantity.
    """
    if not isinstance(spec, EntrySpec):
        raise InvalidInputError(f"spec must be an EntrySpec, got {type(spec).__name__}")
    session = session or _Session(seed, points)
    checks = [_run_check(session, spec, c) for c in spec.checks]
    failed = [c for c in checks if not c.ok]
    if failed:
        status = "misprint"
    elif spec.definition or not checks:
        status = "not-checkable"
    else:
        status = "confirmed"
    inert = {c.inertia for c in checks} - {"none"}
    inertia = "diagonal" if "diagonal" in inert else ("general" if inert else "none")
    methods = []
    for c in checks:
        for m in c.method.split("+"):
            if m not in methods:
                methods.append(m)
    derived = " ;\\quad ".join(
        (r"\text{" + _safe_text(c.label, 80) + ": }" if len(checks) > 1 else "") + c.derived_latex for c in checks
    )
    corrected = None
    differs = summary = None
    if failed:
        corrected = " ;\\quad ".join(c.corrected_latex for c in failed if c.corrected_latex)
        differs = " | ".join(f"{c.label}: {c.differs}" for c in failed)
        summary = " | ".join(f"{c.label}: {c.summary}" for c in failed)
    simpler = " ;\\quad ".join(c.simpler_latex for c in checks if c.simpler_ok and c.simpler_latex) or None
    note = spec.note
    if spec.definition:
        note = f"Not checkable as such: {spec.definition}. " + note
    return EntryResult(
        spec=spec,
        status=status,
        checks=checks,
        inertia=inertia,
        method="+".join(methods) or "none",
        printed=spec.latex,
        derived=derived,
        corrected=corrected,
        simpler=simpler,
        differs=differs,
        note=note,
        differs_summary=summary,
    )
