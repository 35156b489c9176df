r"""Machine check of the paper: every equation and checkable claim, printed vs derived.

Each entry of :data:`eulerpoisson.paper.entries.ENTRIES` holds a formula or
claim of the paper *as printed* (the LaTeX source and a faithful SymPy
transcription, typos included).  :func:`run_audit` evaluates the transcription,
computes the corresponding quantity from the derivation of
:mod:`eulerpoisson.paper.symbolic` (which starts from the Lagrangian, never from
the printed formulas) and compares them:

* exactly, on polynomial numerators over the known denominators
  (:math:`1+\mathbf n^2`, :math:`\det I`), i.e. "difference is zero after
  clearing denominators and expanding" (``simplify``), and
* by exact evaluation at random rational points (fixed seed per check,
  ``random-points``); a nonzero value is a proof of a mismatch and gives a
  witness point.

The status of an entry is computed, never stored: ``confirmed`` when every
check passes, ``misprint`` when one fails (the entry then shows a corrected
formula, itself verified, and what differs), ``not-checkable`` for
definitions and starting points (whose consistency checks still run).

Frames
------
The transcriptions are evaluated in a *frame* that fixes the variables and
the meaning of names such as ``m`` or ``Omega``:

``plain``
    :math:`\mathbf n` only.
``velocity``
    :math:`(\mathbf n, \dot{\mathbf n})`; ``Omega``, ``omega``
    from :math:`R^T\dot R`, :math:`\dot RR^T`; ``EL``,
    ``Gamma2``, ``ddt``, ``on_shell`` for the geodesic footnote.
``canonical``
    :math:`(\mathbf n, \boldsymbol\pi)`; ``H``, ``m``,
    ``Omega``, ``M``, ``ndot``, ``Omegadot`` derived; ``PB``.
``nm``, ``nOmega``, ``nM``
    the non-canonical charts; ``pi`` is
    :math:`\boldsymbol\pi(\mathbf n, X)`, ``PBnX``, ``PBXX``, ``P``
    the brackets and Poisson tensor.
``phase-velocity``
    :math:`(\mathbf n,\boldsymbol\pi,\dot{\mathbf n},\dot{\boldsymbol\pi})`.
``kinematic``
    :math:`(\mathbf n, \boldsymbol\Omega)` with
    :math:`\dot{\mathbf n}` solving :math:`\boldsymbol\Omega = 2A^T\dot{\mathbf n}`.
``rigid``, ``particles``
    particle positions, :math:`g_{ij}`, multipliers.
``axis-angle``, ``angle``, ``asymptotic``
    unit axis :math:`\mathbf k`
    (rational parametrisation), angle :math:`\alpha` (rationalised
    by :math:`\alpha = 2\arctan\tau`), :math:`\mathbf n = r\mathbf e`.

Modules
-------
:func:`run_audit` is defined here; the rest lives in
:mod:`eulerpoisson.paper.audit_language` (the transcriptions),
:mod:`eulerpoisson.paper.audit_frames` (the frames),
:mod:`eulerpoisson.paper.audit_compare` (comparison and display),
:mod:`eulerpoisson.paper.audit_lie` (the Lie series checks),
:mod:`eulerpoisson.paper.audit_checks` (one entry and its results) and
:mod:`eulerpoisson.paper.audit_report` (the report and its writers), and the
public names are re-exported here.

References
----------
Paper eq. 1.1-1.30 (``/work/shared/paper/paper.tex``).
"""

from __future__ import annotations

import time
from collections.abc import Sequence

from ..errors import InvalidInputError
from .audit_checks import CheckResult as CheckResult
from .audit_checks import EntryResult as EntryResult
from .audit_checks import audit_entry as audit_entry
from .audit_compare import N_POINTS as N_POINTS
from .audit_compare import AuditError as AuditError
from .audit_frames import Session as _Session
from .audit_frames import integrability_summary as _integrability
from .audit_lie import LIE_NUMERIC_INERTIA as LIE_NUMERIC_INERTIA
from .audit_lie import LIE_NUMERIC_PI0 as LIE_NUMERIC_PI0
from .audit_report import FORMATS as FORMATS
from .audit_report import STATUSES as STATUSES
from .audit_report import AuditReport as AuditReport
from .audit_report import write_report as write_report
from .entries import ENTRIES, CheckSpec, EntrySpec
from .symbolic import sympy_module as _sp

__all__ = [
    "AuditError",
    "STATUSES",
    "FORMATS",
    "CheckResult",
    "EntryResult",
    "AuditReport",
    "audit_entry",
    "run_audit",
    "write_report",
    "ENTRIES",
    "CheckSpec",
    "EntrySpec",
]


def run_audit(
    *,
    entries: Sequence[EntrySpec] | None = None,
    seed: int = 20240607,
    points: int = N_POINTS,
    integrability: bool = True,
) -> AuditReport:
    """Run the audit of the paper.

    Parameters
    ----------
    entries : sequence of EntrySpec, optional
        Entries to audit (default: all of :data:`ENTRIES`).
    seed : int
        Seed of the random rational points (the verdicts do not depend on it;
        the witnesses do).
    points : int
        Random points per comparison (>= 1).
    integrability : bool
        Also compute the integrability summary.

    Returns
    -------
    AuditReport

    Raises
    ------
    InvalidInputError
        Bad ``points`` or a malformed entry.

    Examples
    --------
    >>> from eulerpoisson.paper.audit import run_audit, ENTRIES
    >>> rep = run_audit(entries=[e for e in ENTRIES if e.equation == "1.12"], integrability=False)
    >>> rep.entries[0].status
    'misprint'
    """
    sympy = _sp()
    if isinstance(points, bool) or not isinstance(points, int) or points < 1:
        raise InvalidInputError(f"points must be a positive integer, got {points!r}")
    t0 = time.perf_counter()
    session = _Session(seed, points)
    specs = list(ENTRIES if entries is None else entries)
    results = [audit_entry(s, session=session) for s in specs]
    integ = _integrability(session) if integrability else {}
    elapsed = time.perf_counter() - t0
    from importlib import metadata

    try:
        version = metadata.version("eulerpoisson")
    except metadata.PackageNotFoundError:  # pragma: no cover
        version = "unknown"
    meta = {
        "eulerpoisson": version,
        "sympy": sympy.__version__,
        "seed": seed,
        "points_per_comparison": points,
        "inertia": "general symmetric (I11, I12, I13, I22, I23, I33) unless an entry says otherwise",
    }
    return AuditReport(entries=results, integrability=integ, elapsed_s=elapsed, meta=meta)
