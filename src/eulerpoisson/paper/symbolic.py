r"""Symbolic (SymPy) derivation of the paper's formulas from its Lagrangian.

Everything here is derived from first principles, never copied from the
paper's printed formulas, so that :mod:`eulerpoisson.paper.audit` can compare the
two:

* the rotation matrix :math:`R(\mathbf n)` from the axis-angle construction
  before eq. 1.7 and the half-angle identities (eq. 1.8-1.9);
* the body angular velocity
  :math:`\Omega_k = -\tfrac12\epsilon_{kij}(R^T\dot R)_{ij}` (eq. 1.10), the
  conversion matrix :math:`A = \tfrac12(\partial\boldsymbol\Omega/
  \partial\dot{\mathbf n})^T` and :math:`\tilde A = A^{-1}` (eq. 1.11-1.12);
* the metric :math:`G_{ij} = \partial^2 L/\partial\dot n_i\partial\dot n_j`
  of :math:`L = \tfrac12\boldsymbol\Omega\cdot I\boldsymbol\Omega`
  (eq. 1.13), its inverse, the Christoffel symbols and the Euler-Lagrange
  (geodesic) equations;
* the momenta :math:`\pi = \partial L/\partial\dot{\mathbf n}`, the Legendre
  transform :math:`H(\mathbf n, \boldsymbol\pi)`, Hamilton's equations
  (eq. 1.14-1.16), the angular momenta :math:`\mathbf m = RI\boldsymbol\Omega`
  and :math:`\mathbf M = I\boldsymbol\Omega` in canonical variables (eq. 1.17),
  and the brackets of the non-canonical coordinates :math:`(\mathbf n,
  \mathbf m)`, :math:`(\mathbf n, \boldsymbol\Omega)`, :math:`(\mathbf n,
  \mathbf M)` computed from the canonical bracket (eq. 1.21, 1.28);
* the Lie series :math:`z(t) = e^{tL_H} z_0` of eq. 1.23.1.

The heavy top (:math:`L = \tfrac12\dot{\mathbf n}^TG\dot{\mathbf n} - U(\mathbf n)`,
:math:`U = -\mu\,\mathbf g\cdot R(\mathbf n)\mathbf c`) is derived on top of
this module in :mod:`eulerpoisson.paper.heavy_top`
(:func:`~eulerpoisson.paper.heavy_top.derive_heavy_top`).

The inertia tensor is either the general symmetric matrix with entries
``I11, I12, I13, I22, I23, I33`` (``inertia="general"``) or
``diag(I1, I2, I3)`` (``inertia="diagonal"``).

Rational expressions are handled as expanded polynomial numerators over
denominators that are products of known factors (:math:`1+\mathbf n^2`,
:math:`\det I`, ...): sums, products, derivatives and substitutions need no
gcd, common factors are removed by exact trial division, and a rational
function is zero exactly when its numerator is (:func:`rsimp`,
:func:`is_zero`).  This is much faster than :func:`sympy.simplify` and makes
the derivation with a general inertia tensor take seconds.

Modules
-------
Every name is re-exported here from :mod:`eulerpoisson.paper.symbolic_tensors`
(SymPy on first use, tensors, the canonical bracket, rotations),
:mod:`eulerpoisson.paper.symbolic_rational` (the rational functions),
:mod:`eulerpoisson.paper.symbolic_derivation` (:func:`derive`) and
:mod:`eulerpoisson.paper.lie_series` (eq. 1.23.1).

References
----------
A. A. Deriglazov, "Geodesic motion on the symplectic leaf of SO(3) with
distorted e(3) algebra and Liouville integrability of a free rigid body",
eq. 1.1-1.30 (``/work/shared/paper/paper.tex``).
"""

from __future__ import annotations

from .lie_series import MAX_LIE_ORDER as MAX_LIE_ORDER
from .lie_series import LieSeriesCheck as LieSeriesCheck
from .lie_series import check_lie_series as check_lie_series
from .lie_series import hamilton_rhs as hamilton_rhs
from .lie_series import lie_series as lie_series
from .lie_series import taylor_coefficients as taylor_coefficients
from .symbolic_derivation import INERTIA_KINDS as INERTIA_KINDS
from .symbolic_derivation import Derivation as Derivation
from .symbolic_derivation import derive as derive
from .symbolic_rational import Ctx as Ctx
from .symbolic_rational import Rat as Rat
from .symbolic_rational import inverse3 as inverse3
from .symbolic_rational import is_zero as is_zero
from .symbolic_rational import rinv3 as rinv3
from .symbolic_rational import rmm as rmm
from .symbolic_rational import rsimp as rsimp
from .symbolic_rational import rsimp_matrix as rsimp_matrix
from .symbolic_rational import rsum as rsum
from .symbolic_rational import rtr as rtr
from .symbolic_tensors import cross as cross
from .symbolic_tensors import cyclic_tensor as cyclic_tensor
from .symbolic_tensors import dot as dot
from .symbolic_tensors import hat as hat
from .symbolic_tensors import levi_civita as levi_civita
from .symbolic_tensors import poisson_bracket as poisson_bracket
from .symbolic_tensors import rotation_from_axis_angle as rotation_from_axis_angle
from .symbolic_tensors import rotation_from_quaternion as rotation_from_quaternion
from .symbolic_tensors import sympy_module as sympy_module

__all__ = [
    "INERTIA_KINDS",
    "Derivation",
    "derive",
    "levi_civita",
    "hat",
    "cross",
    "dot",
    "cyclic_tensor",
    "rsimp",
    "rsimp_matrix",
    "is_zero",
    "inverse3",
    "poisson_bracket",
    "rotation_from_axis_angle",
    "rotation_from_quaternion",
    "lie_series",
    "taylor_coefficients",
    "hamilton_rhs",
    "LieSeriesCheck",
    "check_lie_series",
]
