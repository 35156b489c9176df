r"""The paper's formulas and claims, transcribed as data for :mod:`eulerpoisson.paper.audit`.

Nothing here decides a verdict: every entry only records what the paper
prints (the LaTeX source snippet and a faithful SymPy transcription) and,
where the computation may find a mismatch, a candidate correction and the
human-readable description of the difference.  :func:`eulerpoisson.paper.audit.run_audit`
evaluates everything and decides.

Transcription language (``printed``, ``corrected``, ``simpler``, ``let``)
-------------------------------------------------------------------------
Python expressions evaluated with integer literals turned into SymPy
integers (so ``1/2`` is exact).  Free indices (``CheckSpec.index``) run over
``0, 1, 2`` (the paper's ``1, 2, 3``); summations are written out with
``sum(... for k in R3)``, so a repeated index is summed only where the paper
sums it (``n[j]*n[j]`` with ``j`` free is :math:`n_j^2`).  ``a == b == c``
is a chain of printed equalities; every side must equal the derived quantity
(``CheckSpec.derived``) or, without one, each other.

Names: ``n, ndot, nddot, pi, m, Omega, omega, M, H, ...`` (their meaning
depends on the frame, see :mod:`eulerpoisson.paper.audit`), ``I, Iinv, R, A, At``
(:math:`\tilde A`), ``G, Ginv`` (bound to the *derived* objects so that a
misprint in one formula does not propagate), ``delta, eps, dot, cross``
(:math:`[u, v]`), ``hat`` (:math:`\hat v_{ij}=\epsilon_{ijp}v_p`), ``nhat(i, j)``,
``PB`` (canonical bracket), ``at_origin`` (set :math:`\mathbf n = 0`) and the
claim helpers documented in :mod:`eulerpoisson.paper.audit`.
"""

from __future__ import annotations

from dataclasses import dataclass

__all__ = ["CheckSpec", "EntrySpec", "ENTRIES"]


@dataclass(frozen=True)
class CheckSpec:
    """One comparison or claim inside an entry.

    Attributes
    ----------
    label : str
        Short name of the check.
    printed : str
        Transcription of the printed formula (see module docstring).
    derived : str or None
        Key of the derived quantity it is compared with (``None``: the sides
        of ``printed`` are compared with each other, or ``kind == "claim"``).
    frame : str
        Variables and meaning of the names (see :mod:`eulerpoisson.paper.audit`).
    index : str
        Free indices, e.g. ``"ij"``.
    kind : {"equal", "claim"}
        ``"claim"``: ``printed`` evaluates to a bool.
    let : tuple of (name, index, expression)
        Auxiliary printed definitions evaluated first.
    corrected, corrected_latex : str or None
        Candidate correction (used only if the printed formula fails).
    differs : str or None
        What differs, in words (shown only for a misprint).
    simpler, simpler_latex : str or None
        Candidate simpler equivalent form (shown only if it verifies).
    symbolic : bool
        Attempt an exact symbolic proof (always also random points).
    inertia : {"general", "diagonal"}
        Inertia tensor of the derivation used.
    latex : str or None
        The part of the printed LaTeX this check covers.
    """

    label: str
    printed: str
    derived: str | None = None
    frame: str = "plain"
    index: str = ""
    kind: str = "equal"
    let: tuple = ()
    corrected: str | None = None
    corrected_latex: str | None = None
    differs: str | None = None
    simpler: str | None = None
    simpler_latex: str | None = None
    symbolic: bool = True
    inertia: str = "general"
    latex: str | None = None


@dataclass(frozen=True)
class EntrySpec:
    """One numbered equation or prose claim of the paper.

    Attributes
    ----------
    equation : str
        ``"1.12"`` for ``\\label{u1.12}``; a short label such as
        ``"before 1.8"`` or ``"footnote 1.9"`` for unnumbered claims.
    title, section, context : str
        What it is, where, and the sentence around it (LaTeX source).
    latex : str
        Verbatim LaTeX source of the formula or claim.
    checks : tuple of CheckSpec
    definition : str or None
        If set, the entry is a definition / starting point (status
        ``not-checkable`` with this reason) and its checks only test
        consistency.
    note : str
        What is checked and how (text with inline ``$math$``).
    """

    equation: str
    title: str
    section: str
    context: str
    latex: str
    checks: tuple = ()
    definition: str | None = None
    note: str = ""


S1 = "Introduction: Lagrangian of a rigid body in terms of unconstrained rotation vector"
S2 = "Canonical Hamiltonian formulation and integrability"
S3 = "Hamiltonian formulation in terms of phase-space variables n_i, Omega_j"

# printed sub-expressions reused by several transcriptions
_CYC_IJK = "(nhat(i,j)*n[k] + nhat(j,k)*n[i] + nhat(k,i)*n[j])"
_R9 = "1/(1+dot(n,n))*((1-dot(n,n))*delta(i,j) + 2*n[i]*n[j] - 2*sum(eps(i,j,k)*n[k] for k in R3))"
_A12 = "1/(1+dot(n,n))*(delta(i,j) - sum(eps(i,j,k)*n[k] for k in R3))"
_R7 = "delta(i,j)*cos(alpha) + (1-cos(alpha))*k[i]*k[j] - sum(eps(i,j,p)*k[p] for p in R3)*sin(alpha)"

ENTRIES: tuple[EntrySpec, ...] = (
    EntrySpec(
        equation="1.1",
        title="Action of the n-particle body with rigidity constraints",
        section=S1,
        context=r"In the previous work \cite{AAD23} we discussed the dynamics of a rigid body, taking its Lagrangian action (1.1) as the only starting point of the analysis.",
        latex=r"S=\int dt ~\frac12\sum_{N=1}^{n}m_N\dot{\bf y}_N^2+\frac12\sum_{A=2}^{4}\sum_{N=2}^{n}\lambda_{AN}\left[({\bf y}_A-{\bf y}_1, {\bf y}_N-{\bf y}_1)-a_{AN}\right],",
        definition="the variational starting point of the paper (an action, not an identity)",
        note="Consistency check with $n = 4$ particles: the constraint term is invariant under a common translation of all particles, so the constraint forces sum to zero and the centre of mass moves uniformly, as (1.2) states.",
        checks=(
            CheckSpec(
                label="constraint forces sum to zero",
                frame="particles",
                index="i",
                printed="total_force(1/2*sum(sum(lam(A,N)*(dot(y(A)-y(1), y(N)-y(1)) - a(A,N)) for N in range(2,5)) for A in range(2,5)))[i]",
                derived="zero",
            ),
        ),
    ),
    EntrySpec(
        equation="1.2",
        title="General solution: centre of mass plus a rotation",
        section=S1,
        context=r"The analysis of equations following from the action (1.1) shows that all their solutions are of the form (1.2) [...] $R_{ij}(t)$ is an orthogonal matrix, $R^TR={\bf 1}$, $\det R=+1$.",
        latex=r"{\bf y}_N(t)={\bf C}_0+{\bf V}_0 t+{\bf x}_N(t), \qquad \mbox{where} \quad   {\bf x}_N(t)=R(t){\bf x}_N(0).",
        note="With $R = R(\\mathbf n)$ of (1.9) for arbitrary $\\mathbf n$: the motions (1.2) keep the constraints of (1.1), and $R$ is orthogonal with unit determinant. That every solution has this form is the result of [AAD23] and is not re-derived.",
        checks=(
            CheckSpec(
                label="constraints of (1.1) preserved",
                frame="rigid",
                printed="dot((C0 + V0*t + R*x(2)) - (C0 + V0*t + R*x(1)), (C0 + V0*t + R*x(3)) - (C0 + V0*t + R*x(1)))",
                derived="constraint_at_t0",
            ),
            CheckSpec(label="R^T R = 1", index="ij", printed="(R.T*R)[i,j]", derived="delta"),
            CheckSpec(label="det R = +1", printed="det(R)", derived="one"),
        ),
    ),
    EntrySpec(
        equation="1.3",
        title="Action of the rotation matrix",
        section=S1,
        context=r"The dynamics of $R_{ij}$ is completely determined by its own Lagrangian action (1.3).",
        latex=r"S=\int dt ~ ~ \frac12 g_{ij}\dot R_{ki}\dot R_{kj} -\frac12 \lambda_{ij}\left[R_{ki}R_{kj}-\delta_{ij}\right],",
        note="$g_{ij}$ is not defined in this paper; with $g_{ij}=\\sum_N m_N x^i_N(0)x^j_N(0)$ (as in [AAD23]) the kinetic term of (1.1) on the motions (1.2) is the kinetic term of (1.3) (checked for two particles), and with $\\dot R = R[\\boldsymbol\\Omega]_\\times$ it equals $\\frac12\\Omega_i I_{ij}\\Omega_j$ with $I = \\mathrm{tr}(g)\\,1 - g$ (general symmetric $g$).",
        checks=(
            CheckSpec(
                label="kinetic term = 1/2 Omega I Omega, I = tr(g) 1 - g",
                frame="rigid",
                printed="1/2*sum(g[i,j]*Rdot[k,i]*Rdot[k,j] for i in R3 for j in R3 for k in R3)",
                derived="kinetic_from_g",
            ),
            CheckSpec(
                label="kinetic term of (1.1) on rigid motions",
                frame="rigid",
                let=(("gp", "ij", "mass(1)*x(1)[i]*x(1)[j] + mass(2)*x(2)[i]*x(2)[j]"),),
                printed="1/2*sum(gp[i,j]*Rdot[k,i]*Rdot[k,j] for i in R3 for j in R3 for k in R3)",
                derived="kinetic_particles",
            ),
        ),
    ),
    EntrySpec(
        equation="1.4",
        title="Euler-Poisson equation for R",
        section=S1,
        context=r"Their Hamiltonian equations turn out to be just the Euler-Poisson equations \cite{AAD23}",
        latex=r"\dot R_{ij}=-\epsilon_{jkm}\Omega_k R_{im},",
        note="$R(\\mathbf n(t))$ with $\\dot{\\mathbf n} = \\frac12\\tilde A^T\\boldsymbol\\Omega$ (the $\\dot{\\mathbf n}$ solving $\\boldsymbol\\Omega = 2A^T\\dot{\\mathbf n}$, eq. 1.30) differentiated by the chain rule equals the right-hand side for arbitrary $\\mathbf n$, $\\boldsymbol\\Omega$.",
        checks=(
            CheckSpec(
                label="dR/dt along n-dot(n, Omega)",
                frame="kinematic",
                index="ij",
                printed="-sum(eps(j,k,mm)*Omega[k]*R[i,mm] for k in R3 for mm in R3)",
                derived="Rdot_of_Omega",
            ),
        ),
    ),
    EntrySpec(
        equation="1.5",
        title="Euler equations",
        section=S1,
        context=r"Their Hamiltonian equations turn out to be just the Euler-Poisson equations",
        latex=r"I\dot{\boldsymbol\Omega}=[I{\boldsymbol\Omega}, {\boldsymbol\Omega}],",
        note="$\\dot{\\boldsymbol\\Omega} = \\{\\boldsymbol\\Omega(\\mathbf n,\\boldsymbol\\pi), H\\}$ computed with the canonical bracket; general symmetric $I$. $[\\cdot,\\cdot]$ is the cross product.",
        checks=(
            CheckSpec(
                label="I Omega-dot = [I Omega, Omega]",
                frame="canonical",
                index="i",
                printed="(I*Omegadot)[i] == cross(I*Omega, Omega)[i]",
            ),
        ),
    ),
    EntrySpec(
        equation="before 1.6",
        title="lambda = 1 is an eigenvalue of R; the axis",
        section=S1,
        context=r"with $\lambda=1$ we have: $\det(R-{\bf 1})=\det(R-RR^T)=\det R\det({\bf 1}-R^T)=-\det(R-{\bf 1})$, which implies $\det(R-{\bf 1})=0$. Then the equation $R{\bf k}={\bf k}$ for eigenvectors has two solutions",
        latex=r"\det(R-{\bf 1})=\det(R-RR^T)=\det R\det({\bf 1}-R^T)=-\det(R-{\bf 1})",
        note="For $R = R(\\mathbf n)$: every member of the chain vanishes, and $\\mathbf n$ spans the axis ($R\\mathbf n = \\mathbf n$).",
        checks=(
            CheckSpec(
                label="det chain",
                printed="det(R - one) == det(R - R*R.T) == det(R)*det(one - R.T) == -det(R - one)",
                derived="zero",
            ),
            CheckSpec(label="R n = n", index="i", printed="(R*n)[i]", derived="n"),
        ),
    ),
    EntrySpec(
        equation="1.6",
        title="Longitudinal/transverse decomposition",
        section=S1,
        context=r"we use the projectors: $\delta_{ij}=P_{ij}({\bf k})+N_{ij}({\bf k})$, $P_{ij}({\bf k})\equiv k_i k_j$, $N_{ij}({\bf k})\equiv\delta_{ij}-k_i k_j$ to decompose the vectors $x^i$ and $x'^i$ on transverse and longitudinal parts",
        latex=r"x^i=x^i_l+x^i_t=P_{ij}x^j+N_{ij}x^j, \qquad" + "\n" + r"x'^i=x'^i_l+x'^i_t=P_{ij}x'^j+N_{ij}x'^j.",
        note="Unit axis $\\mathbf k = (2a, 2b, 1-a^2-b^2)/(1+a^2+b^2)$, arbitrary $\\mathbf x$ (the same identity covers $\\mathbf x'$).",
        checks=(
            CheckSpec(
                label="x = Px + Nx",
                frame="axis-angle",
                index="i",
                printed="sum(k[i]*k[j]*x[j] for j in R3) + sum((delta(i,j) - k[i]*k[j])*x[j] for j in R3)",
                derived="x",
            ),
            CheckSpec(
                label="P, N are complementary projectors",
                frame="axis-angle",
                index="ij",
                let=(("P", "ij", "k[i]*k[j]"), ("N", "ij", "delta(i,j) - k[i]*k[j]")),
                printed="(P*P)[i,j] - P[i,j] == (N*N)[i,j] - N[i,j] == (P*N)[i,j]",
                derived="zero",
            ),
            CheckSpec(
                label="x_t orthogonal to k",
                frame="axis-angle",
                printed="sum((delta(i,j) - k[i]*k[j])*x[j]*k[i] for i in R3 for j in R3)",
                derived="zero",
            ),
        ),
    ),
    EntrySpec(
        equation="1.7",
        title="Rotation matrix in terms of axis and angle",
        section=S1,
        context=r"so ${\bf x}'=P{\bf x}+N{\bf x}\cos\alpha+[{\bf k}, {\bf x}]\sin\alpha$. This gives us the matrix $R$",
        latex=r"R_{ij}=\delta_{ij}\cos\alpha+(1-\cos\alpha)k_i k_j-\epsilon_{ijk}k_k\sin\alpha.",
        note="Derived as the Jacobian $\\partial x'_i/\\partial x_j$ of the construction in the text (unit $\\mathbf k$, angle $\\alpha$; trigonometric functions are rationalised with $\\alpha = 2\\arctan\\tau$). Also: $R\\mathbf k = \\mathbf k$, $R^TR = 1$, and the rotation is counterclockwise seen from the tip of $\\mathbf k$ ($\\mathbf k = \\mathbf e_3$ maps $\\mathbf e_1$ to $(\\cos\\alpha, \\sin\\alpha, 0)$). The index $k$ of $\\epsilon_{ijk}k_k$ is renamed $p$ in the transcription.",
        checks=(
            CheckSpec(label="R(k, alpha)", frame="axis-angle", index="ij", printed=_R7, derived="R_axis_angle"),
            CheckSpec(
                label="R k = k",
                frame="axis-angle",
                index="i",
                let=(("R7", "ij", _R7),),
                printed="(R7*k)[i]",
                derived="k",
            ),
            CheckSpec(
                label="R^T R = 1",
                frame="axis-angle",
                index="ij",
                let=(("R7", "ij", _R7),),
                printed="(R7.T*R7)[i,j]",
                derived="delta",
            ),
            CheckSpec(
                label="counterclockwise about k",
                frame="angle",
                index="i",
                let=(("k", "i", "delta(i,2)"), ("R7", "ij", _R7)),
                printed="R7[i,0]",
                derived="ccw_image_of_e1",
            ),
        ),
    ),
    EntrySpec(
        equation="before 1.8",
        title="Half-angle identities",
        section=S1,
        context=r"Further, using the identities $\sin\alpha=2\tan^2(\alpha/2)/(1+\tan^2(\alpha/2)$ and $\cos\alpha=(1-\tan^2(\alpha/2))/(1+\tan^2(\alpha/2)$, we introduce the vector",
        latex=r"\sin\alpha=2\tan^2(\alpha/2)/(1+\tan^2(\alpha/2)$ and $\cos\alpha=(1-\tan^2(\alpha/2))/(1+\tan^2(\alpha/2)",
        note="Compared with SymPy's rewriting of $\\sin\\alpha$, $\\cos\\alpha$ in $\\tan(\\alpha/2)$; exact comparison after $\\alpha = 2\\arctan\\tau$. Both printed formulas also lack a closing parenthesis in the source.",
        checks=(
            CheckSpec(
                label="sin",
                frame="angle",
                printed="2*tan(alpha/2)**2/(1+tan(alpha/2)**2)",
                derived="sin_half_angle",
                corrected="2*tan(alpha/2)/(1+tan(alpha/2)**2)",
                corrected_latex=r"\sin\alpha=2\tan(\alpha/2)/(1+\tan^2(\alpha/2))",
                differs="the numerator is $2\\tan(\\alpha/2)$, not $2\\tan^2(\\alpha/2)$ (the printed right-hand side is $1-\\cos\\alpha$); the closing parenthesis is missing",
                latex=r"\sin\alpha=2\tan^2(\alpha/2)/(1+\tan^2(\alpha/2)",
            ),
            CheckSpec(
                label="cos",
                frame="angle",
                printed="(1-tan(alpha/2)**2)/(1+tan(alpha/2)**2)",
                derived="cos_half_angle",
                latex=r"\cos\alpha=(1-\tan^2(\alpha/2))/(1+\tan^2(\alpha/2)",
            ),
        ),
    ),
    EntrySpec(
        equation="1.8",
        title="Gibbs rotation vector",
        section=S1,
        context=r"we introduce the vector",
        latex=r"n_i=k_i\tan(\alpha/2), \qquad 0\le{\bf n}^2=\tan^2(\alpha/2)<\infty.",
        note="$\\mathbf n$ is defined here; the checkable part is $\\mathbf n^2 = \\tan^2(\\alpha/2)$ for a unit axis, and $\\mathbf n^2\\to\\infty$ as $\\alpha\\to\\pi^-$.",
        checks=(
            CheckSpec(
                label="n^2 = tan^2(alpha/2)",
                frame="axis-angle",
                let=(("n8", "i", "k[i]*tan(alpha/2)"),),
                printed="dot(n8, n8) == tan(alpha/2)**2",
            ),
            CheckSpec(
                label="n^2 -> infinity as alpha -> pi",
                frame="angle",
                kind="claim",
                printed="limit(tan(alpha/2)**2, alpha, PI, '-') == oo",
            ),
        ),
    ),
    EntrySpec(
        equation="footnote 1.9",
        title="Relation to quaternion (Cayley-Klein) parameters",
        section=S1,
        context=r"\footnote{The rotation vector is related with Cayley-Klein (or quaternion) parameters $q^0, {\bf q}$ as follows: $n^i=q^i/q^0$.}",
        latex=r"n^i=q^i/q^0",
        note="With the Euler parameters $q^0=\\cos(\\alpha/2)$, ${\\bf q}={\\bf k}\\sin(\\alpha/2)$ of the rotation $(\\mathbf k,\\alpha)$, $q^i/q^0$ is the $n_i$ of (1.8); and the quaternion $(q^0,\\mathbf q)\\propto(1,\\mathbf n)$ has the rotation matrix $R(\\mathbf n)$ (standard active formula, scalar first).",
        checks=(
            CheckSpec(
                label="n = q/q0",
                frame="axis-angle",
                index="i",
                let=(("n8", "i", "k[i]*tan(alpha/2)"),),
                printed="n8[i] == q[i]/q0",
            ),
            CheckSpec(label="R(q) = R(n)", index="ij", printed="Rquat(1, n)[i,j]", derived="R"),
        ),
    ),
    EntrySpec(
        equation="1.9",
        title="Rotation matrix in terms of n",
        section=S1,
        context=r"In terms of this unconstrained vector, we get the final form of the desired parameterization",
        latex=r"R_{ij}({\bf n})=\frac{1}{1+{\bf n}^2}\left[(1-{\bf n}^2)\delta_{ij}+2n_i n_j-2\epsilon_{ijk}n_k\right].",
        note="Derived by substituting $\\mathbf k = \\mathbf n/|\\mathbf n|$, $\\cos\\alpha = (1-\\mathbf n^2)/(1+\\mathbf n^2)$, $\\sin\\alpha = 2|\\mathbf n|/(1+\\mathbf n^2)$ into the construction of (1.7). Also the sentence after (1.9): $R_{ij}(0)=\\delta_{ij}$.",
        checks=(
            CheckSpec(label="R(n)", index="ij", printed=_R9, derived="R"),
            CheckSpec(
                label="R(0) = 1",
                index="ij",
                let=(("R9", "ij", _R9),),
                printed="at_origin(R9[i,j])",
                derived="delta",
            ),
        ),
    ),
    EntrySpec(
        equation="1.10",
        title="Lagrangian in terms of the body angular velocity",
        section=S1,
        context=r"To express the Lagrangian (1.3) in terms of ${\bf n}$, it is convenient first to rewrite it in terms of angular velocity in the body as follows:",
        latex=r"L=\frac12 I_{ij}\Omega_i\Omega_j -\frac12 \lambda_{ij}\left[R_{ki}R_{kj}-\delta_{ij}\right], \qquad \mbox{where} \quad \Omega_k\equiv-\frac12\epsilon_{kij}(R^T\dot R)_{ij}.",
        definition="definition of the Lagrangian and of the body angular velocity",
        note="Consistency: for $R(\\mathbf n(t))$, $R^T\\dot R$ is antisymmetric and equals $[\\boldsymbol\\Omega]_\\times$, i.e. $(R^T\\dot R)_{ij} = -\\epsilon_{ijk}\\Omega_k$, the convention of (1.4).",
        checks=(
            CheckSpec(
                label="R^T R-dot = -eps Omega",
                frame="velocity",
                index="ij",
                printed="(R.T*Rdot)[i,j]",
                derived="eps_Omega",
            ),
        ),
    ),
    EntrySpec(
        equation="footnote 1.10",
        title="Equivalence of the variational problems (1.3) and (1.10)",
        section=S1,
        context=r"\footnote{The variational problems (\ref{u1.3}) and (\ref{u1.10}) are equivalent, see the Appendix in \cite{AAD23}.}",
        latex=r"The variational problems (\ref{u1.3}) and (\ref{u1.10}) are equivalent",
        note="Checked: the kinetic terms agree, $\\frac12 g_{ij}\\dot R_{ki}\\dot R_{kj} = \\frac12 I_{ij}\\Omega_i\\Omega_j$ with $I = \\mathrm{tr}(g)1 - g$, for $R(\\mathbf n(t))$ and arbitrary $\\mathbf n, \\dot{\\mathbf n}$ (general symmetric $g$); the multiplier terms are identical. The rest of the equivalence (Appendix of [AAD23]) is not re-derived.",
        checks=(
            CheckSpec(
                label="kinetic terms of (1.3) and (1.10)",
                frame="velocity",
                printed="1/2*sum(g[i,j]*Rdot[k,i]*Rdot[k,j] for i in R3 for j in R3 for k in R3)",
                derived="kinetic_from_g_velocity",
            ),
        ),
    ),
    EntrySpec(
        equation="1.11",
        title="Body angular velocity in terms of n, n-dot",
        section=S1,
        context=r"Using the parameterization (1.9) we get",
        latex=r"\Omega_k({\bf n}, \dot{\bf n})=2(A^T\dot{\bf n})_k,",
        note="$A$ as printed in (1.12); $\\boldsymbol\\Omega$ derived from $-\\frac12\\epsilon_{kij}(R^T\\dot R)_{ij}$ with $R(\\mathbf n)$.",
        checks=(
            CheckSpec(
                label="Omega = 2 A^T n-dot",
                frame="velocity",
                index="k",
                let=(("A12", "ij", _A12),),
                printed="2*sum(A12[j,k]*ndot[j] for j in R3)",
                derived="Omega_v",
            ),
        ),
    ),
    EntrySpec(
        equation="1.12",
        title="Conversion matrix A and its inverse",
        section=S1,
        context=r"where the conversion matrix is",
        latex=r"A_{ij}=\frac{1}{1+{\bf n}^2}\left[\delta_{ij}-\epsilon_{ijk}n_k\right], \quad \mbox{then} \quad A^{-1}_{ij}\equiv\tilde A_{ij}=\delta_{ij}+n_j n_j"
        + "\n"
        + r"+\epsilon_{ijk}n_k.",
        note="Derived $A = \\frac12(\\partial\\boldsymbol\\Omega/\\partial\\dot{\\mathbf n})^T$ and $\\tilde A = A^{-1}$ (exact inverse). The printed $n_j n_j$ is transcribed literally as $n_j^2$ ($j$ is a free index).",
        checks=(
            CheckSpec(
                label="A",
                index="ij",
                printed=_A12,
                derived="A",
                latex=r"A_{ij}=\frac{1}{1+{\bf n}^2}\left[\delta_{ij}-\epsilon_{ijk}n_k\right]",
            ),
            CheckSpec(
                label="A^{-1}",
                index="ij",
                printed="delta(i,j) + n[j]*n[j] + sum(eps(i,j,k)*n[k] for k in R3)",
                derived="Atilde",
                corrected="delta(i,j) + n[i]*n[j] + sum(eps(i,j,k)*n[k] for k in R3)",
                corrected_latex=r"A^{-1}_{ij}\equiv\tilde A_{ij}=\delta_{ij}+n_i n_j+\epsilon_{ijk}n_k",
                differs="$n_j n_j$ should be $n_i n_j$ (the two agree on the diagonal only)",
                latex=r"A^{-1}_{ij}\equiv\tilde A_{ij}=\delta_{ij}+n_j n_j+\epsilon_{ijk}n_k",
            ),
        ),
    ),
    EntrySpec(
        equation="after 1.12",
        title="R = A tilde-A^T",
        section=S1,
        context=r"The rotation matrix $R$ can be written in terms of these matrices as follows: $R=A\tilde A^T$.",
        latex=r"R=A\tilde A^T",
        note="$A$, $\\tilde A = A^{-1}$ derived; $R$ derived from (1.7).",
        checks=(CheckSpec(label="R = A At^T", index="ij", printed="(A*At.T)[i,j]", derived="R"),),
    ),
    EntrySpec(
        equation="1.13",
        title="Lagrangian in unconstrained variables; the metric G",
        section=S1,
        context=r"Using these expressions in (1.10), we get the Lagrangian in terms of unconstrained variables [...] with the metric $G_{ij}({\bf n})=4(AIA^T)_{ij}$.",
        latex=r"L=2 I_{ij}(A^T\dot{\bf n})_i(A^T\dot{\bf n})_j=\frac12G_{ij}({\bf n})\dot n_i\dot n_j=\frac{2}{(1+{\bf n}^2)^2}I_{ij} \left[\dot{\bf n}-[{\bf n}, \dot{\bf n}]\right]_i"
        + "\n"
        + r"\left[\dot{\bf n}-[{\bf n}, \dot{\bf n}]\right]_j.",
        note="Derived $L = \\frac12 I_{ij}\\Omega_i\\Omega_j$ with $\\boldsymbol\\Omega(\\mathbf n,\\dot{\\mathbf n})$ from $R(\\mathbf n)$, and $G_{ij} = \\partial^2 L/\\partial\\dot n_i\\partial\\dot n_j$; general symmetric $I$. In the middle member $G$ is the printed $4AIA^T$.",
        checks=(
            CheckSpec(
                label="L (three forms)",
                frame="velocity",
                let=(("G13", "ij", "4*(A*I*A.T)[i,j]"),),
                printed=(
                    "2*sum(I[i,j]*(A.T*ndot)[i]*(A.T*ndot)[j] for i in R3 for j in R3)"
                    " == 1/2*sum(G13[i,j]*ndot[i]*ndot[j] for i in R3 for j in R3)"
                    " == 2/(1+dot(n,n))**2*sum(I[i,j]*(ndot - cross(n, ndot))[i]*(ndot - cross(n, ndot))[j] for i in R3 for j in R3)"
                ),
                derived="L",
            ),
            CheckSpec(
                label="G = 4 A I A^T",
                frame="velocity",
                index="ij",
                printed="4*(A*I*A.T)[i,j]",
                derived="G",
                latex=r"G_{ij}({\bf n})=4(AIA^T)_{ij}",
            ),
        ),
    ),
    EntrySpec(
        equation="after 1.13 (n -> 0)",
        title="Metric near the origin",
        section=S1,
        context=r"The metric has an unusual asymptotic behavior: $G\rightarrow\delta$ as ${\bf n}\rightarrow 0$, and $G\rightarrow 1/{\bf n}^2$ as ${\bf n}\rightarrow\infty$, that is this is almost Euclidean in the vicinity of origin while vanishes at infinity.",
        latex=r"$G\rightarrow\delta$ as ${\bf n}\rightarrow 0$",
        note="Derived $\\lim_{\\mathbf n\\to 0} G$ for general symmetric $I$.",
        checks=(
            CheckSpec(
                label="lim G at n = 0",
                index="ij",
                printed="delta(i,j)",
                derived="G_at_origin",
                corrected="4*I[i,j]",
                corrected_latex=r"G\rightarrow 4I \mbox{ as } {\bf n}\rightarrow 0",
                differs="the limit is the constant metric $4I$, which is $\\delta$ only for $I = \\frac14\\mathbf 1$; 'almost Euclidean' holds in the sense of a constant (flat) metric",
            ),
        ),
    ),
    EntrySpec(
        equation="after 1.13 (n -> infinity)",
        title="Metric at infinity",
        section=S1,
        context=r"$G\rightarrow 1/{\bf n}^2$ as ${\bf n}\rightarrow\infty$, that is this is almost Euclidean in the vicinity of origin while vanishes at infinity. Note that ${\bf n}\rightarrow\infty$ corresponds to the angle $\alpha\rightarrow\pi$.",
        latex=r"$G\rightarrow 1/{\bf n}^2$ as ${\bf n}\rightarrow\infty$",
        note="Along $\\mathbf n = r\\mathbf e$ (unit $\\mathbf e$), $r\\to\\infty$. The printed statement is read as $\\mathbf n^2 G\\to\\delta$. The computed limit $4\\hat e I\\hat e^T$ ($\\hat e_{ij} = \\epsilon_{ijk}e_k$) has rank 2: the radial component $e_iG_{ij}e_j = 4\\,\\mathbf e\\cdot I\\mathbf e/(1+r^2)^2$ decays like $1/\\mathbf n^4$ (supplementary check). $G\\to 0$ (vanishes at infinity) is confirmed.",
        checks=(
            CheckSpec(
                label="lim n^2 G",
                frame="asymptotic",
                index="ij",
                printed="delta(i,j)",
                derived="n2G_at_infinity",
                corrected="4*(hat(e)*I*hat(e).T)[i,j]",
                corrected_latex=r"{\bf n}^2 G_{ij}\rightarrow 4(\hat e I\hat e^T)_{ij},\quad \hat e_{ij}=\epsilon_{ijk}e_k,\ {\bf e}={\bf n}/|{\bf n}|",
                differs="$G$ does fall off like $1/\\mathbf n^2$ in the directions transverse to $\\mathbf n$, but the coefficient is the degenerate tensor $4\\hat eI\\hat e^T$, not $\\delta$; the radial component falls off like $1/\\mathbf n^4$",
            ),
            CheckSpec(
                label="G vanishes at infinity", frame="asymptotic", index="ij", printed="0", derived="G_at_infinity"
            ),
            CheckSpec(
                label="supplementary (not printed): radial component",
                frame="asymptotic",
                printed="4*dot(e, I*e)/(1+r**2)**2",
                derived="G_radial",
            ),
        ),
    ),
    EntrySpec(
        equation="footnote 1.13",
        title="Geodesic equations in the natural parametrization",
        section=S1,
        context=r"\footnote{More exactly, this Lagrangian implies geodesic equations in the natural parametrization, see Sect. 6.5 in \cite{deriglazov2010classical}.}",
        latex=r"this Lagrangian implies geodesic equations in the natural parametrization",
        note="The Euler-Lagrange equations of $L=\\frac12G_{ij}\\dot n_i\\dot n_j$ are $G_{il}(\\ddot n_l + \\Gamma^l{}_{jk}\\dot n_j\\dot n_k)$ with the Christoffel symbols of $G$, and $G_{ij}\\dot n_i\\dot n_j$ is constant on them (the parameter is proportional to arc length). General symmetric $I$.",
        checks=(
            CheckSpec(
                label="Euler-Lagrange = G (geodesic equation)",
                frame="velocity",
                index="i",
                printed="EL[i] == sum(G[i,l]*(nddot[l] + sum(Gamma2(l,j,k)*ndot[j]*ndot[k] for j in R3 for k in R3)) for l in R3)",
                symbolic=False,
            ),
            CheckSpec(
                label="speed conserved on geodesics",
                frame="velocity",
                printed="on_shell(ddt(sum(G[i,j]*ndot[i]*ndot[j] for i in R3 for j in R3)))",
                derived="zero",
                symbolic=False,
            ),
        ),
    ),
    EntrySpec(
        equation="1.14",
        title="Canonical momenta and the inverse metric",
        section=S2,
        context=r"Computing the conjugate momenta $\pi_i=\partial L/\partial\dot n^i$, we get",
        latex=r"\pi_i=G_{ij}\dot n_j, \qquad \mbox{then} \quad \dot n_i=G^{-1}_{ij}\pi_j, \quad \mbox{where} \quad G^{-1}=\frac14 \tilde A^TI^{-1}\tilde A.",
        note="$\\pi = \\partial L/\\partial\\dot{\\mathbf n}$, $G^{-1} = \\mathrm{adj}(G)/\\det G$ computed from the Hessian; $\\dot{\\mathbf n} = \\partial H/\\partial\\boldsymbol\\pi$. General symmetric $I$.",
        checks=(
            CheckSpec(label="pi = G n-dot", frame="velocity", index="i", printed="(G*ndot)[i]", derived="momenta"),
            CheckSpec(
                label="G^{-1} = 1/4 At^T I^{-1} At",
                index="ij",
                printed="1/4*(At.T*Iinv*At)[i,j]",
                derived="Ginv",
            ),
            CheckSpec(
                label="n-dot = G^{-1} pi",
                frame="canonical",
                index="i",
                let=(("Ginv14", "ij", "1/4*(At.T*Iinv*At)[i,j]"),),
                printed="(Ginv14*pi)[i]",
                derived="ndot_c",
            ),
        ),
    ),
    EntrySpec(
        equation="1.15",
        title="Hamiltonian",
        section=S2,
        context=r"Then the Hamiltonian $H=\pi_i\dot n_i-L$ is",
        latex=r"H=\frac12 G^{-1}_{ij}\pi_i \pi_j=\frac18 I^{-1}_{ij}(\tilde A{\boldsymbol\pi})_i(\tilde A{\boldsymbol\pi})_j=\frac18 I^{-1}_{ij}[{\boldsymbol\pi}+({\bf n}, {\boldsymbol\pi}){\bf n}+[{\boldsymbol\pi}, {\bf n}]]_i[{\boldsymbol\pi}+({\bf n}, {\boldsymbol\pi}){\bf n}+[{\boldsymbol\pi}, {\bf n}]]_j,",
        note="Derived $H$ by Legendre transform (and independently $\\pi_i\\dot n_i - L$ with the velocities substituted, at random points). General symmetric $I$.",
        checks=(
            CheckSpec(
                label="H (three forms)",
                frame="canonical",
                printed=(
                    "1/2*sum(Ginv[i,j]*pi[i]*pi[j] for i in R3 for j in R3)"
                    " == 1/8*sum(Iinv[i,j]*(At*pi)[i]*(At*pi)[j] for i in R3 for j in R3)"
                    " == 1/8*sum(Iinv[i,j]*(pi + dot(n,pi)*n + cross(pi,n))[i]*(pi + dot(n,pi)*n + cross(pi,n))[j] for i in R3 for j in R3)"
                ),
                derived="H",
            ),
            CheckSpec(
                label="H = pi n-dot - L (direct Legendre transform)",
                frame="canonical",
                printed="dot(pi, ndot_of_pi) - L_of_pi",
                derived="H",
                symbolic=False,
                latex=r"H=\pi_i\dot n_i-L",
            ),
        ),
    ),
    EntrySpec(
        equation="1.15.1",
        title="Canonical Poisson brackets",
        section=S2,
        context=r"while the canonical Poisson brackets are",
        latex=r"\{n_i, \pi_j\}=\delta_{ij}, \qquad \{n_i, n_j\}=\{\pi_i, \pi_j\}=0.",
        definition="definition of the canonical Poisson structure",
        note="Checks that the bracket $\\{f,g\\}=\\sum_i(\\partial_{n_i}f\\,\\partial_{\\pi_i}g-\\partial_{\\pi_i}f\\,\\partial_{n_i}g)$ used throughout realises it.",
        checks=(
            CheckSpec(label="{n_i, pi_j}", frame="canonical", index="ij", printed="PB(n[i], pi[j])", derived="delta"),
            CheckSpec(
                label="{n_i, n_j} = {pi_i, pi_j} = 0",
                frame="canonical",
                index="ij",
                printed="PB(n[i], n[j]) == PB(pi[i], pi[j])",
                derived="zero",
            ),
        ),
    ),
    EntrySpec(
        equation="1.18",
        title="Brackets of At^T pi and At pi commute",
        section=S2,
        context=r"For the latter use we observe, that they imply",
        latex=r"\{(\tilde A^T{\boldsymbol\pi})_i, (\tilde A{\boldsymbol\pi})_j\}=0.",
        note="$\\tilde A^T\\boldsymbol\\pi = 2\\mathbf m$ and $\\tilde A\\boldsymbol\\pi = 2\\mathbf M = 2I\\boldsymbol\\Omega$: space and body angular momenta commute.",
        checks=(
            CheckSpec(
                label="{(At^T pi)_i, (At pi)_j}",
                frame="canonical",
                index="ij",
                printed="PB((At.T*pi)[i], (At*pi)[j])",
                derived="zero",
            ),
        ),
    ),
    EntrySpec(
        equation="1.16",
        title="Hamilton's equations",
        section=S2,
        context=r"The Hamiltonian equations of motion can be then obtained according the standard rule: $\dot n_i=\{ n_i, H\}$, $\dot\pi_i=\{\pi_i, H\}$, and read as follows:",
        latex=r"\dot n_i=\frac14(\tilde A^T I^{-1}\tilde A{\boldsymbol\pi})_i, \qquad"
        + "\n"
        + r"\dot\pi_i=-\frac14[\delta_{ij}({\bf n}, {\boldsymbol\pi})+\pi_in_j+\epsilon_{ijk}n_k](I^{-1}\tilde A{\boldsymbol\pi})_j.",
        note="$\\{n_i, H\\}$ and $\\{\\pi_i, H\\}$ from the derived $H$, general symmetric $I$.",
        checks=(
            CheckSpec(
                label="n-dot",
                frame="canonical",
                index="i",
                printed="1/4*(At.T*Iinv*At*pi)[i]",
                derived="ndot_c",
                latex=r"\dot n_i=\frac14(\tilde A^T I^{-1}\tilde A{\boldsymbol\pi})_i",
            ),
            CheckSpec(
                label="pi-dot",
                frame="canonical",
                index="i",
                printed="-1/4*sum((delta(i,j)*dot(n,pi) + pi[i]*n[j] + sum(eps(i,j,k)*n[k] for k in R3))*(Iinv*At*pi)[j] for j in R3)",
                derived="pidot_c",
                corrected="-1/4*sum((delta(i,j)*dot(n,pi) + pi[i]*n[j] + sum(eps(i,j,k)*pi[k] for k in R3))*(Iinv*At*pi)[j] for j in R3)",
                corrected_latex=r"\dot\pi_i=-\frac14[\delta_{ij}({\bf n}, {\boldsymbol\pi})+\pi_in_j+\epsilon_{ijk}\pi_k](I^{-1}\tilde A{\boldsymbol\pi})_j",
                differs="$\\epsilon_{ijk}n_k$ should be $\\epsilon_{ijk}\\pi_k$ (it comes from $\\partial[\\boldsymbol\\pi,\\mathbf n]_j/\\partial n_i$)",
                latex=r"\dot\pi_i=-\frac14[\delta_{ij}({\bf n}, {\boldsymbol\pi})+\pi_in_j+\epsilon_{ijk}n_k](I^{-1}\tilde A{\boldsymbol\pi})_j",
            ),
        ),
    ),
    EntrySpec(
        equation="1.16.1",
        title="First-order (Hamiltonian) action",
        section=S2,
        context=r"Equivalently, they can be obtained as the conditions of extremum of the first-order Hamiltonian action",
        latex=r"S_H=\int dt  ~\pi_i\dot n_i-H(n_i, \pi_j).",
        note="Euler-Lagrange equations of $L_H = \\pi_i\\dot n_i - H$ in the six variables $(\\mathbf n, \\boldsymbol\\pi)$: with respect to $n_i$ they are $\\dot\\pi_i - \\{\\pi_i, H\\}$, with respect to $\\pi_i$ they are $-(\\dot n_i - \\{n_i,H\\})$.",
        checks=(
            CheckSpec(
                label="EL w.r.t. n",
                frame="phase-velocity",
                index="i",
                printed="el_n(dot(pi, ndot) - H)[i]",
                derived="hamilton_pi_residual",
            ),
            CheckSpec(
                label="EL w.r.t. pi",
                frame="phase-velocity",
                index="i",
                printed="el_pi(dot(pi, ndot) - H)[i]",
                derived="hamilton_n_residual",
            ),
        ),
    ),
    EntrySpec(
        equation="footnote 1.16.1",
        title="Energy and angular momentum on motions through the identity",
        section=S2,
        context=r"\footnote{On the subset of solutions which describe the moviments of a body (they are the solutions that pass through unit element of $SO(3)$), the four integrals are not independent: $E=I^{-1}_{ij} m_i m_j$, see \cite{AAD23} for the details.}",
        latex=r"E=I^{-1}_{ij} m_i m_j",
        note="$E = H$ and $\\mathbf m(\\mathbf n,\\boldsymbol\\pi)$ are conserved, so the relation holds on a trajectory through the identity iff it holds at $\\mathbf n = 0$; checked there. (For general $\\mathbf n$, $E = \\frac12(RI^{-1}R^T)_{ij}m_im_j$, footnote after (1.20).)",
        checks=(
            CheckSpec(
                label="E at n = 0",
                frame="canonical",
                printed="at_origin(sum(Iinv[i,j]*m[i]*m[j] for i in R3 for j in R3))",
                derived="H_at_origin",
                corrected="at_origin(1/2*sum(Iinv[i,j]*m[i]*m[j] for i in R3 for j in R3))",
                corrected_latex=r"E=\frac12 I^{-1}_{ij} m_i m_j",
                differs="a factor $\\frac12$ is missing",
            ),
        ),
    ),
    EntrySpec(
        equation="1.17",
        title="Angular momentum in canonical variables",
        section=S2,
        context=r"Three more integals of motion are the components of angular momentum of the body: ${\bf m}=RI{\boldsymbol\Omega}$. To see this in the Hamiltonian framework, we write them in terms of canonical variables",
        latex=r"m_i=\frac12(\tilde A^T{\boldsymbol\pi})_i=\frac12(\pi_i+({\bf n}{\boldsymbol\pi})n_i  -[{\boldsymbol\pi}, {\bf n}]_i).",
        note="Derived $\\mathbf m = RI\\boldsymbol\\Omega(\\mathbf n, \\boldsymbol\\pi)$ with $\\boldsymbol\\Omega$ from (1.10) at $\\dot{\\mathbf n} = \\{\\mathbf n, H\\}$, general symmetric $I$.",
        checks=(
            CheckSpec(
                label="m (two forms)",
                frame="canonical",
                index="i",
                printed="1/2*(At.T*pi)[i] == 1/2*(pi[i] + dot(n,pi)*n[i] - cross(pi,n)[i])",
                derived="m_c",
            ),
        ),
    ),
    EntrySpec(
        equation="after 1.17",
        title="m(n, pi) and its brackets do not depend on the inertia tensor",
        section=S2,
        context=r"Remarkably, the functions $m_i(n_j, \pi_k)$ (and hence their brackets)  do not depend on the inertia tensor.",
        latex=r"the functions $m_i(n_j, \pi_k)$ (and hence their brackets)  do not depend on the inertia tensor",
        note="$\\mathbf m = RI\\boldsymbol\\Omega(\\mathbf n,\\boldsymbol\\pi)$ is computed with a general symmetric $I$ and its derivatives with respect to the six $I_{ij}$ vanish; so do those of $\\{n_i, m_j\\}$, $\\{m_i, m_j\\}$ (also the abstract's claim that the Poisson structure does not depend on $I$).",
        checks=(
            CheckSpec(label="m independent of I", frame="canonical", kind="claim", printed="independent_of_inertia(m)"),
            CheckSpec(
                label="brackets independent of I",
                frame="nm",
                kind="claim",
                printed="independent_of_inertia(PBnX) and independent_of_inertia(PBXX)",
            ),
        ),
    ),
    EntrySpec(
        equation="1.19",
        title="Conservation of angular momentum",
        section=S2,
        context=r"Using Eqs. (1.15), (1.18) and (1.17), we immediately conclude",
        latex=r"\{ m_i, H \}=0,",
        note="General symmetric $I$.",
        checks=(CheckSpec(label="{m_i, H}", frame="canonical", index="i", printed="PB(m[i], H)", derived="zero"),),
    ),
    EntrySpec(
        equation="1.20",
        title="Equations of motion in the variables (n, m)",
        section=S2,
        context=r"The equalities (1.17) are invertible with respect to $\pi_i$, so we can work with the rigid body in terms of non canonical phase-space variables $n_i$, $m_j$ instead of $n_i$, $\pi_j$. Making this change of variables in (1.16), we get an equivalent system",
        latex=r"\dot n_i=\frac12(\tilde A^T I^{-1}R^T{\bf m})_i, \qquad  \dot m_i=0.",
        note="$\\{n_i, H\\}$ and $\\{m_i, H\\}$ rewritten with $\\boldsymbol\\pi(\\mathbf n, \\mathbf m)$; invertibility: $\\det(\\partial\\mathbf m/\\partial\\boldsymbol\\pi) = (1+\\mathbf n^2)^2/8 \\ne 0$. General symmetric $I$.",
        checks=(
            CheckSpec(label="n-dot", frame="nm", index="i", printed="1/2*(At.T*Iinv*R.T*m)[i]", derived="ndot"),
            CheckSpec(label="m-dot", frame="nm", index="i", printed="0", derived="mdot"),
            CheckSpec(
                label="(1.17) invertible",
                frame="canonical",
                kind="claim",
                printed="nonzero(det(jac(m, pi)))",
            ),
        ),
    ),
    EntrySpec(
        equation="footnote 1.20",
        title="Hamiltonian in the variables (n, m)",
        section=S2,
        context=r"\footnote{The Hamiltonian in these variables is $\frac12(RI^{-1}R^T)_{ij}m_im_j$, see also Eq. (\ref{u1.25}) below.}",
        latex=r"\frac12(RI^{-1}R^T)_{ij}m_im_j",
        note="General symmetric $I$.",
        checks=(
            CheckSpec(
                label="H(n, m)",
                frame="nm",
                printed="1/2*sum((R*Iinv*R.T)[i,j]*m[i]*m[j] for i in R3 for j in R3)",
                derived="H",
            ),
        ),
    ),
    EntrySpec(
        equation="1.21",
        title="Poisson brackets of (n, m)",
        section=S2,
        context=r"Poisson structure of the theory in these variables is [...] where $\hat n_{ij}\equiv \epsilon_{ijp}n_p$ is the antisymmetric matrix equivalent to the vector $n_p$.",
        latex=r"\{n_i, n_j\}=0, \qquad   \{n_i, m_j\}=\frac12 \tilde A_{ij}=\frac12 [\epsilon_{ijk}n_k+\delta_{ij}+n_i n_j], \cr"
        + "\n"
        + r"\{m_i, m_j\}=\frac{1}{1+{\bf n}^2}[\epsilon_{ijk}m_k+"
        + "\n"
        + r"(\hat n_{ij}n_k+cycle\,(ijk) )m_k], \quad",
        note="Brackets computed with the canonical bracket and rewritten with $\\boldsymbol\\pi = 2A^T\\mathbf m$. 'cycle (ijk)' is read as the sum over cyclic permutations, $\\hat n_{ij}n_k+\\hat n_{jk}n_i+\\hat n_{ki}n_j$. Since this sum equals $\\mathbf n^2\\epsilon_{ijk}$, the bracket collapses to the $so(3)$ bracket.",
        checks=(
            CheckSpec(label="{n_i, n_j}", frame="nm", index="ij", printed="0", derived="PBnn"),
            CheckSpec(
                label="{n_i, m_j}",
                frame="nm",
                index="ij",
                printed="1/2*At[i,j] == 1/2*(sum(eps(i,j,k)*n[k] for k in R3) + delta(i,j) + n[i]*n[j])",
                derived="PBnX",
            ),
            CheckSpec(
                label="{m_i, m_j}",
                frame="nm",
                index="ij",
                printed="1/(1+dot(n,n))*(sum(eps(i,j,k)*m[k] for k in R3) + sum(" + _CYC_IJK + "*m[k] for k in R3))",
                derived="PBXX",
                simpler="sum(eps(i,j,k)*m[k] for k in R3)",
                simpler_latex=r"\{m_i, m_j\}=\epsilon_{ijk}m_k",
            ),
        ),
    ),
    EntrySpec(
        equation="after 1.21 (e(3))",
        title="Even in the linear approximation the (n, m) algebra differs from e(3)",
        section=S2,
        context=r"Even in the linear approximation, this algebra is different from the isometry algebra $e(3)$ of ${\mathbb R}^3$.",
        latex=r"Even in the linear approximation, this algebra is different from the isometry algebra $e(3)$ of ${\mathbb R}^3$.",
        note="Linearised at $(\\mathbf n,\\mathbf m)=0$ and compared with $e(3)$, $\\{J_i,J_j\\}=\\epsilon_{ijk}J_k$, $\\{J_i,P_j\\}=\\epsilon_{ijk}P_k$, $\\{P_i,P_j\\}=0$, with $\\mathbf J=\\mathbf m$, $\\mathbf P = c\\,\\mathbf n$ (any $c\\neq0$): $\\{m_i,m_j\\}$ agrees, but $\\{n_i, m_j\\}$ has the constant term $\\frac12\\delta_{ij}$ (which makes the structure symplectic) and the coefficient $\\frac12$ instead of $1$ in front of $\\epsilon_{ijk}n_k$. The difference is shown in the integrability section.",
        checks=(
            CheckSpec(
                label="linearised (n,m) minus e(3)",
                frame="nm",
                kind="claim",
                printed="nonzero_matrix(e3_difference('nm'))",
            ),
        ),
    ),
    EntrySpec(
        equation="after 1.21 (nondegenerate)",
        title="The Poisson structure (1.21) is nondegenerate",
        section=S2,
        context=r"We also emphasise that the Poisson tensor determined by (1.21) is just the canonical Poisson tensor (1.18) written in a noncanonical coordinates of the phase space. This implies, in particular, that the Poisson structure (1.21) is nondegenerate and hence does not admite the Casimir functions.",
        latex=r"the Poisson structure (\ref{u1.21}) is nondegenerate",
        note="Pfaffian of the $6\\times6$ Poisson tensor of $(\\mathbf n,\\mathbf m)$ computed symbolically: $\\mathrm{Pf} = -(1+\\mathbf n^2)^2/8$, $\\det = (1+\\mathbf n^2)^4/64$. Editorial: the sentence refers to 'the canonical Poisson tensor (1.18)'; the canonical brackets are eq. (1.15.1) (eq. (1.18) is the bracket of $\\tilde A^T\\pi$ with $\\tilde A\\pi$).",
        checks=(CheckSpec(label="Pfaffian", frame="nm", kind="claim", printed="nonzero(pfaffian(P))"),),
    ),
    EntrySpec(
        equation="after 1.21 (no Casimir)",
        title="No Casimir functions",
        section=S2,
        context=r"the Poisson structure (1.21) is nondegenerate and hence does not admite the Casimir functions.",
        latex=r"does not admite the Casimir functions",
        note="A Casimir $C$ has $P\\,\\nabla C = 0$; $P$ has full rank 6 at (random rational) points, so $\\nabla C = 0$ and $C$ is constant.",
        checks=(CheckSpec(label="rank of P = 6", frame="nm", kind="claim", printed="generic_rank(P) == 6"),),
    ),
    EntrySpec(
        equation="after 1.21 (antisymmetry)",
        title="The cyclic sum is antisymmetric on k and j",
        section=S2,
        context=r"The expression $(\hat n_{ij}n_k+cycle\,(ijk) )$ is antisymmetric on $k$ and $j$, so we have the identity",
        latex=r"The expression $(\hat n_{ij}n_k+cycle\,(ijk) )$ is antisymmetric on $k$ and $j$",
        note="In fact the cyclic sum equals $\\mathbf n^2\\epsilon_{ijk}$ (totally antisymmetric), the identity that collapses (1.21), (1.22), (1.28), (1.29).",
        checks=(
            CheckSpec(
                label="T_ijk = -T_ikj",
                index="ijk",
                let=(("T", "ijk", _CYC_IJK),),
                printed="T[i,j,k] == -T[i,k,j]",
                simpler="dot(n,n)*eps(i,j,k)",
                simpler_latex=r"\hat n_{ij}n_k+\hat n_{jk}n_i+\hat n_{ki}n_j={\bf n}^2\epsilon_{ijk}",
            ),
        ),
    ),
    EntrySpec(
        equation="1.22",
        title="Identity for the cyclic sum",
        section=S2,
        context=r"so we have the identity",
        latex=r"(\hat n_{ij}n_k+cycle\,(ijk) )m_k m_j=0.",
        note="$\\mathbf m$ arbitrary.",
        checks=(
            CheckSpec(
                label="T m m = 0",
                frame="nm",
                index="i",
                printed="sum(" + _CYC_IJK + "*m[k]*m[j] for j in R3 for k in R3)",
                derived="zero",
            ),
        ),
    ),
    EntrySpec(
        equation="1.23",
        title="m^2 commutes with m",
        section=S2,
        context=r"Using this identity and Eq. (1.21) we conclude, that the phase-space function ${\bf m}^2$ has vanishing brackets with $m_i$",
        latex=r"\{m_i, {\bf m}^2\}=0.",
        note="Canonical bracket of $\\mathbf m(\\mathbf n,\\boldsymbol\\pi)$.",
        checks=(
            CheckSpec(label="{m_i, m^2}", frame="canonical", index="i", printed="PB(m[i], dot(m,m))", derived="zero"),
        ),
    ),
    EntrySpec(
        equation="after 1.23 (involution)",
        title="H, m^2, m_3 are independent and in involution",
        section=S2,
        context=r"This equation together with (1.19) show that the three independent integrals of motion $H$, ${\bf m}^2$ and $m_3$ are in involution. According to the Liouville's theorem [...] this implies the integrability in quadratures",
        latex=r"the three independent integrals of motion $H$, ${\bf m}^2$ and $m_3$ are in involution",
        note="All pairwise canonical brackets vanish (general symmetric $I$); the Jacobian of $(H, \\mathbf m^2, m_3)$ with respect to $(\\mathbf n,\\boldsymbol\\pi)$ has rank 3 at random rational points (independence).",
        checks=(
            CheckSpec(label="{H, m^2}", frame="canonical", printed="PB(H, dot(m,m))", derived="zero"),
            CheckSpec(label="{H, m_3}", frame="canonical", printed="PB(H, m[2])", derived="zero"),
            CheckSpec(label="{m^2, m_3}", frame="canonical", printed="PB(dot(m,m), m[2])", derived="zero"),
            CheckSpec(
                label="independence",
                frame="canonical",
                kind="claim",
                printed="generic_rank(jac(Matrix([H, dot(m,m), m[2]]), Matrix.vstack(n, pi))) == 3",
            ),
        ),
    ),
    EntrySpec(
        equation="1.23.1",
        title="General solution as the exponential of the Hamiltonian vector field",
        section=S2,
        context=r"we can use now the known formula of Hamiltonian mechanics to write the solution to the equations (1.16) in terms of exponential of the Hamiltonian vector field [...] After computing all derivatives, one should take $n_{0i}=0$, in accordance with the initial conditions. The resulting expression depends on $3$ arbitrary constants $\pi_i$, and is therefore a general solution",
        latex=r"z^a(t, z^b_0)=e^{t\{z^c_0, ~H(n_{0 i}, \pi_{0 j})\}\frac{\partial}{\partial z^c_0}}z^a_0, \qquad \mbox{where} \quad   z^a=( n_i, \pi_j).",
        note="Truncated Lie series $\\sum_k t^k L_H^k z/k!$ at $\\mathbf n_0 = 0$ (symbolic.lie_series): (i) its Taylor coefficients satisfy Hamilton's equations of the derived $H$ exactly up to the truncation order, for symbolic $\\boldsymbol\\pi_0$ and a symbolic general $I$ (order 3) and for two random rational general $I$, $\\boldsymbol\\pi_0$ (order 6); (ii) against solve_ivp of (1.16) the truncation error scales like $t^{\\mathrm{order}+1}$ (orders 2-6); (iii) $\\boldsymbol\\Omega(0)=\\frac12I^{-1}\\boldsymbol\\pi_0$ is invertible, so the three constants $\\pi_{0i}$ reach every initial angular velocity (general solution).",
        checks=(
            CheckSpec(
                label="series solves Hamilton's equations (symbolic)",
                frame="canonical",
                kind="claim",
                printed="lie_symbolic_check(3)",
                inertia="general",
            ),
            CheckSpec(
                label="series solves Hamilton's equations (exact, random)",
                frame="canonical",
                kind="claim",
                printed="lie_exact_check(6, 2)",
            ),
            CheckSpec(
                label="truncation error ~ t^(order+1)",
                frame="canonical",
                kind="claim",
                printed="lie_numeric_check((2, 3, 4, 5, 6))",
            ),
            CheckSpec(
                label="pi_0 parametrises all initial Omega",
                frame="canonical",
                kind="claim",
                printed="nonzero(det(jac(at_origin(Omega), pi)))",
            ),
        ),
    ),
    EntrySpec(
        equation="1.24",
        title="Angular velocities and momenta",
        section=S3,
        context=r"The relations between them are",
        latex=r"2(A^T\dot{\bf n})_i={\bf\Omega}=R^T{\boldsymbol\omega}=I^{-1}R^T{\bf m}=I^{-1}{\bf M},",
        note="In $(\\mathbf n,\\dot{\\mathbf n})$: $\\boldsymbol\\Omega$ from $R^T\\dot R$ and $\\boldsymbol\\omega$ from $\\dot R R^T$ (space angular velocity). In canonical variables: $I^{-1}R^T\\mathbf m$ with $\\mathbf m$ of (1.17) and $I^{-1}\\mathbf M$ with $\\mathbf M = \\frac12\\tilde A\\boldsymbol\\pi$ (eq. 1.18) equal $\\boldsymbol\\Omega(\\mathbf n,\\boldsymbol\\pi)$. General symmetric $I$.",
        checks=(
            CheckSpec(
                label="2 A^T n-dot = Omega = R^T omega",
                frame="velocity",
                index="i",
                printed="2*(A.T*ndot)[i] == Omega[i] == (R.T*omega)[i]",
                derived="Omega_v",
            ),
            CheckSpec(
                label="I^{-1} R^T m = I^{-1} M",
                frame="canonical",
                index="i",
                let=(("m17", "i", "1/2*(At.T*pi)[i]"), ("M18", "i", "1/2*(At*pi)[i]")),
                printed="(Iinv*R.T*m17)[i] == (Iinv*M18)[i]",
                derived="Omega_c",
            ),
        ),
    ),
    EntrySpec(
        equation="1.25",
        title="Kinetic energy in various forms",
        section=S3,
        context=r"According to this, the kinetic part of the Lagrangian (1.10) can be presented in various forms as follows:",
        latex=r"E=\frac12I_{ij}\Omega_i\Omega_j=\frac12(RI^{-1}R^T)_{ij}m_im_j=\frac12 (RIR^T)_{ij}\omega_i\omega_j=\frac12I^{-1}_{ij}M_i M_j.",
        note="In the chart $(\\mathbf n,\\boldsymbol\\Omega)$ with $\\mathbf m$, $\\boldsymbol\\omega$, $\\mathbf M$ the derived functions of the chart; $E$ compared with the derived $H$. General symmetric $I$.",
        checks=(
            CheckSpec(
                label="E (four forms)",
                frame="nOmega",
                printed=(
                    "1/2*sum(I[i,j]*Omega[i]*Omega[j] for i in R3 for j in R3)"
                    " == 1/2*sum((R*Iinv*R.T)[i,j]*m[i]*m[j] for i in R3 for j in R3)"
                    " == 1/2*sum((R*I*R.T)[i,j]*omega[i]*omega[j] for i in R3 for j in R3)"
                    " == 1/2*sum(Iinv[i,j]*M[i]*M[j] for i in R3 for j in R3)"
                ),
                derived="H",
            ),
        ),
    ),
    EntrySpec(
        equation="1.26",
        title="Omega in terms of pi and back",
        section=S3,
        context=r"Using Eqs. (1.11) and (1.14) we get",
        latex=r"{\boldsymbol\Omega}=\frac12 I^{-1}\tilde A{\boldsymbol\pi}, \qquad {\boldsymbol\pi}=2AI{\boldsymbol\Omega}.",
        note="General symmetric $I$.",
        checks=(
            CheckSpec(
                label="Omega(n, pi)", frame="canonical", index="i", printed="1/2*(Iinv*At*pi)[i]", derived="Omega_c"
            ),
            CheckSpec(label="pi(n, Omega)", frame="nOmega", index="i", printed="2*(A*I*Omega)[i]", derived="pi"),
        ),
    ),
    EntrySpec(
        equation="1.27",
        title="Hamiltonian in the variables (n, Omega)",
        section=S3,
        context=r"Using this in Eq. (1.15) we get the Hamiltonian",
        latex=r"H=\frac12 I_{ij}\Omega_i\Omega_j,",
        note="General symmetric $I$.",
        checks=(
            CheckSpec(
                label="H(n, Omega)",
                frame="nOmega",
                printed="1/2*sum(I[i,j]*Omega[i]*Omega[j] for i in R3 for j in R3)",
                derived="H",
            ),
        ),
    ),
    EntrySpec(
        equation="1.28",
        title="Poisson brackets of (n, Omega)",
        section=S3,
        context=r"while the canonical Poisson brackets (1.15.1) imply",
        latex=r"\{n_i, n_j\}=0, \qquad \{n_i, \Omega_j\}=\frac12(\tilde A^TI^{-1})_{ij}=\frac12[-\epsilon_{ikp}n_p+\delta_{ik}+n_i n_k]I^{-1}_{kj},  \quad ~ \cr"
        + "\n"
        + r"\{\Omega_i, \Omega_j\}=\frac{-1}{1+{\bf n}^2}(I^{-1})_{ia}(I^{-1})_{jb}\left[\epsilon_{abc}(I\Omega)_c+(\hat n_{ab}n_c+cycle \, (abc)\,)(I\Omega)_c\right].",
        note="Canonical brackets rewritten with $\\boldsymbol\\pi = 2AI\\boldsymbol\\Omega$; general symmetric $I$. With the cyclic sum $=\\mathbf n^2\\epsilon_{abc}$ the second bracket collapses.",
        checks=(
            CheckSpec(label="{n_i, n_j}", frame="nOmega", index="ij", printed="0", derived="PBnn"),
            CheckSpec(
                label="{n_i, Omega_j}",
                frame="nOmega",
                index="ij",
                printed="1/2*(At.T*Iinv)[i,j] == 1/2*sum((-sum(eps(i,k,p)*n[p] for p in R3) + delta(i,k) + n[i]*n[k])*Iinv[k,j] for k in R3)",
                derived="PBnX",
            ),
            CheckSpec(
                label="{Omega_i, Omega_j}",
                frame="nOmega",
                index="ij",
                printed="-1/(1+dot(n,n))*sum(Iinv[i,a]*Iinv[j,b]*(eps(a,b,c)*(I*Omega)[c] + (nhat(a,b)*n[c] + nhat(b,c)*n[a] + nhat(c,a)*n[b])*(I*Omega)[c]) for a in R3 for b in R3 for c in R3)",
                derived="PBXX",
                simpler="-sum(Iinv[i,a]*Iinv[j,b]*eps(a,b,c)*(I*Omega)[c] for a in R3 for b in R3 for c in R3)",
                simpler_latex=r"\{\Omega_i, \Omega_j\}=-(I^{-1})_{ia}(I^{-1})_{jb}\epsilon_{abc}(I\Omega)_c",
            ),
        ),
    ),
    EntrySpec(
        equation="after 1.28 (M)",
        title="Brackets of (n, M): the same without the inertia tensor",
        section=S3,
        context=r"If we take $M_i$ instead of $\Omega_i$, we obtain the similar expressions, but without  the inertia tensor $I$.",
        latex=r"If we take $M_i$ instead of $\Omega_i$, we obtain the similar expressions, but without  the inertia tensor $I$.",
        note="Transcribed as (1.28) with $I\\to 1$ and $\\boldsymbol\\Omega\\to\\mathbf M$; computed in the chart $(\\mathbf n,\\mathbf M)$, general symmetric $I$ (which drops out).",
        checks=(
            CheckSpec(label="{n_i, M_j}", frame="nM", index="ij", printed="1/2*At.T[i,j]", derived="PBnX"),
            CheckSpec(
                label="{M_i, M_j}",
                frame="nM",
                index="ij",
                printed="-1/(1+dot(n,n))*(sum(eps(i,j,k)*M[k] for k in R3) + sum(" + _CYC_IJK + "*M[k] for k in R3))",
                derived="PBXX",
                simpler="-sum(eps(i,j,k)*M[k] for k in R3)",
                simpler_latex=r"\{M_i, M_j\}=-\epsilon_{ijk}M_k",
            ),
        ),
    ),
    EntrySpec(
        equation="after 1.28 (nondegenerate, e(3))",
        title="(n, Omega) structure: nondegenerate and not e(3) even linearised",
        section=S3,
        context=r"Any case, the Poisson structure is nondegenerate and even in the linear approximation differs from the algebra $e(3)$.",
        latex=r"Any case, the Poisson structure is nondegenerate and even in the linear approximation differs from the algebra $e(3)$.",
        note="Pfaffian in $(\\mathbf n,\\boldsymbol\\Omega)$: $-(1+\\mathbf n^2)^2/(8\\det I)$; linearised brackets compared with $e(3)$ with $\\mathbf J = -I\\boldsymbol\\Omega$ (the sign that matches $\\{J_i,J_j\\}=\\epsilon_{ijk}J_k$), $\\mathbf P = \\mathbf n$; same for $(\\mathbf n,\\mathbf M)$ with $\\mathbf J=-\\mathbf M$. General symmetric $I$.",
        checks=(
            CheckSpec(label="Pfaffian (n, Omega)", frame="nOmega", kind="claim", printed="nonzero(pfaffian(P))"),
            CheckSpec(
                label="linearised (n, Omega) minus e(3)",
                frame="nOmega",
                kind="claim",
                printed="nonzero_matrix(e3_difference('nOmega'))",
            ),
            CheckSpec(
                label="linearised (n, M) minus e(3)",
                frame="nM",
                kind="claim",
                printed="nonzero_matrix(e3_difference('nM'))",
            ),
        ),
    ),
    EntrySpec(
        equation="1.29",
        title="Identity used for the Euler equations",
        section=S3,
        context=r"To prove this, we observe that it is $SO(3)$ covariant equation, so we can assume that the inertia tensor is of diagonal form, $I_{ij}=diagonal\, (I_1, I_2, I_3)$. Then the identity can be easily confirmed by direct calculation.",
        latex=r"(\hat n_{ab}n_c+cycle \, (abc)\,)(I\Omega)_c \Omega_b=-{\bf n}^2[I{\boldsymbol\Omega}, {\boldsymbol\Omega}]_a.",
        note="Verified directly for a general symmetric $I$ (no diagonalisation needed): it is $\\mathbf n^2\\epsilon_{abc}(I\\Omega)_c\\Omega_b$ by the cyclic-sum identity.",
        checks=(
            CheckSpec(
                label="identity",
                frame="nOmega",
                index="a",
                printed="sum((nhat(a,b)*n[c] + nhat(b,c)*n[a] + nhat(c,a)*n[b])*(I*Omega)[c]*Omega[b] for b in R3 for c in R3) == -dot(n,n)*cross(I*Omega, Omega)[a]",
                simpler="dot(n,n)*sum(eps(a,b,c)*(I*Omega)[c]*Omega[b] for b in R3 for c in R3)",
                simpler_latex=r"(\hat n_{ab}n_c+cycle)(I\Omega)_c\Omega_b={\bf n}^2\epsilon_{abc}(I\Omega)_c\Omega_b",
            ),
        ),
    ),
    EntrySpec(
        equation="1.30",
        title="Equations of motion in the variables (n, Omega)",
        section=S3,
        context=r"Using Eqs. (1.27), (1.28) and (1.29), we obtain Hamiltonian equations of motion of a rigid body in terms of these variables",
        latex=r"\dot n_i=\frac12(\tilde A^T\Omega)_i, \qquad I_{ij}\dot\Omega_j=[I{\boldsymbol\Omega}, ~ {\boldsymbol\Omega}]_i.",
        note="$\\{n_i,H\\}$ and $\\{\\Omega_i,H\\}$ computed canonically and rewritten in $(\\mathbf n,\\boldsymbol\\Omega)$; general symmetric $I$.",
        checks=(
            CheckSpec(label="n-dot", frame="nOmega", index="i", printed="1/2*(At.T*Omega)[i]", derived="ndot"),
            CheckSpec(
                label="Euler equations",
                frame="nOmega",
                index="i",
                printed="sum(I[i,j]*Omegadot[j] for j in R3) == cross(I*Omega, Omega)[i]",
            ),
        ),
    ),
)
