r"""The paper's formulations of the free rigid body as numeric objects.

Five coordinate systems describe the same motion. Each is a
:class:`Formulation`: the state layout, the right-hand side, the Hamiltonian,
the Poisson tensor and the integrals, side by side, all batched over leading
axes (states of shape ``(..., d)``) and valid for any symmetric
positive-definite inertia tensor :math:`I` (not only a diagonal one).

========================  =========================  ====  ==========================
registry name             variables                  d     paper equations
========================  =========================  ====  ==========================
``"euler-poisson"``       :math:`(R, \Omega)`        12    1.4, 1.5, 1.25
``"canonical"``           :math:`(n, \pi)`           6     1.13-1.19
``"momentum"``            :math:`(n, m)`             6     1.17, 1.20-1.23
``"velocity"``            :math:`(n, \Omega)`        6     1.26-1.30
``"geodesic"``            :math:`(n, \dot n)`        6     1.11, 1.13, 1.14
========================  =========================  ====  ==========================

Derivations (all checked numerically in ``tests/test_formulations.py``)
-----------------------------------------------------------------------
Write :math:`s = 1+\mathbf n^2`, :math:`N = [\mathbf n]_\times`,
:math:`A = (\mathbf 1+N)/s`, :math:`\tilde A = A^{-1} = \mathbf 1+\mathbf n\mathbf n^T-N`
(eq. 1.12 corrected). Then :math:`\tilde A^T\tilde A = s(\mathbf 1+\mathbf n\mathbf n^T)`,
:math:`R = A\tilde A^T`, :math:`R^T = \tilde A A^T`, :math:`\det A = s^{-2}`.

* Kinematics: :math:`\boldsymbol\Omega = 2A^T\dot{\mathbf n}`,
  :math:`\dot{\mathbf n} = \tfrac12\tilde A^T\boldsymbol\Omega
  = \tfrac12(\boldsymbol\Omega + \mathbf n\times\boldsymbol\Omega + (\mathbf n\cdot\boldsymbol\Omega)\mathbf n)`.
* Momenta: :math:`\boldsymbol\pi = G\dot{\mathbf n} = 2AI\boldsymbol\Omega`,
  :math:`\mathbf M = I\boldsymbol\Omega = \tfrac12\tilde A\boldsymbol\pi`,
  :math:`\mathbf m = R\mathbf M = \tfrac12\tilde A^T\boldsymbol\pi` (because
  :math:`A\tilde A^T\tilde A = \tilde A^T`).
* Canonical equations: :math:`\dot{\mathbf n} = \tfrac12\tilde A^T\boldsymbol\Omega` and
  :math:`\dot{\boldsymbol\pi} = -\tfrac12\left[(\mathbf n\cdot\boldsymbol\pi)\boldsymbol\Omega
  + (\mathbf n\cdot\boldsymbol\Omega)\boldsymbol\pi + \boldsymbol\Omega\times\boldsymbol\pi\right]`,
  i.e. :math:`\dot\pi_i = -\tfrac14[\delta_{ij}(\mathbf n\cdot\boldsymbol\pi) + \pi_i n_j
  + \epsilon_{ijk}\pi_k](I^{-1}\tilde A\boldsymbol\pi)_j`. The paper's eq. 1.16
  prints :math:`\epsilon_{ijk}n_k`; the correct last term has :math:`\pi_k`.
* Brackets. The flow of :math:`m_j` is the left rotation about
  :math:`\mathbf e_j`, the flow of :math:`M_j` the right one, so
  :math:`\{n_i, m_j\} = \tfrac12\tilde A_{ij}`, :math:`\{m_i, m_j\} = \epsilon_{ijk}m_k`,
  :math:`\{n_i, M_j\} = \tfrac12\tilde A_{ji}`, :math:`\{M_i, M_j\} = -\epsilon_{ijk}M_k`,
  :math:`\{m_i, M_j\} = 0` (eq. 1.18). The cyclic term of eqs. 1.21 and 1.28 is
  :math:`\hat n_{ij}n_k + \mathrm{cycle} = \mathbf n^2\epsilon_{ijk}` (three-dimensional
  Schouten identity), so the printed brackets are right but simplify:
  :math:`\{m_i,m_j\}` is exactly the :math:`so(3)` bracket and does not depend on
  :math:`\mathbf n`.
* Geodesic equation: differentiating :math:`\dot{\mathbf n} = \tfrac12\tilde A^T\boldsymbol\Omega`
  and using Euler's equation gives

  .. math::
      \ddot{\mathbf n} = \frac{2(\mathbf n\cdot\dot{\mathbf n})}{s}\dot{\mathbf n}
      + 2\tilde A^T I^{-1}\left[(I\mathbf w)\times\mathbf w\right],\qquad
      \mathbf w = A^T\dot{\mathbf n} = \frac{\dot{\mathbf n}-\mathbf n\times\dot{\mathbf n}}{s},

  whose symmetric part is the Christoffel symbol of :math:`G = 4AIA^T`
  (see :func:`christoffel`). For :math:`I\propto\mathbf 1` only the first term
  survives: the geodesics are reparametrized straight lines (gnomonic chart of
  :math:`S^3`).

With a potential (the heavy top, the gravity gradient)
------------------------------------------------------
``formulation(name, body, torque=...)`` adds a conservative torque
(:class:`~eulerpoisson.torques.Gravity`,
:class:`~eulerpoisson.torques.GravityGradient`, any
:class:`~eulerpoisson.torques.Torque` with ``conservative = True`` and a
:meth:`~eulerpoisson.torques.Torque.potential`): :math:`H = H_0 + U(t, R)`
with the *same* Poisson tensor. Its body-frame torque is minus the body-frame
gradient of :math:`U`: along :math:`\delta R = R[\delta\boldsymbol\theta]_\times`,
:math:`\delta U = -\boldsymbol\tau\cdot\delta\boldsymbol\theta`. In the Gibbs
chart :math:`\delta\boldsymbol\theta = 2A^T\delta\mathbf n` (eq. 1.11), so

.. math::
    \frac{\partial U}{\partial\mathbf n} = -2A(\mathbf n)\boldsymbol\tau,\qquad
    \dot{\boldsymbol\pi} = -\frac{\partial H_0}{\partial\mathbf n} + 2A\boldsymbol\tau,

(:func:`gibbs_potential_gradient`), consistent with Euler's equations since
:math:`\mathbf M = \tfrac12\tilde A\boldsymbol\pi` gains
:math:`\tfrac12\tilde A(2A\boldsymbol\tau) = \boldsymbol\tau`. Pushed to the
other charts with the brackets above: :math:`I\dot{\boldsymbol\Omega}` gains
:math:`\boldsymbol\tau` in :math:`(R, \boldsymbol\Omega)` and
:math:`(\mathbf n, \boldsymbol\Omega)`; :math:`\dot{\mathbf m}` gains
:math:`-\tfrac12\tilde A^T\partial_{\mathbf n}U = \tilde A^TA\boldsymbol\tau = R\boldsymbol\tau`
in :math:`(\mathbf n, \mathbf m)` (:math:`\tilde A^TA = A\tilde A^T` since
:math:`[\mathbf n]_\times` and :math:`\mathbf n\mathbf n^T` commute); and
:math:`\ddot{\mathbf n}` gains :math:`-G^{-1}\partial_{\mathbf n}U = \tfrac12\tilde A^TI^{-1}\boldsymbol\tau`
in :math:`(\mathbf n, \dot{\mathbf n})` (Euler-Lagrange equations of
:math:`L = \tfrac12\dot{\mathbf n}^TG\dot{\mathbf n} - U`). A
time-dependent potential (the gravity gradient) makes the vector field depend
on the time: ``vector_field(state, t)``, ``rhs(t, y)``. The symbolic
derivation from the Lagrangian is :func:`eulerpoisson.paper.heavy_top.derive_heavy_top`.

Where the printed paper differs (each checked numerically in the tests)
-----------------------------------------------------------------------
* Eq. 1.12: :math:`\tilde A_{ij}` has :math:`n_in_j`, not :math:`n_jn_j`.
* Eq. 1.16: the last term of :math:`\dot\pi_i` is :math:`\epsilon_{ijk}\pi_k`, not
  :math:`\epsilon_{ijk}n_k` (the printed one is not :math:`-\partial H/\partial n_i`).
* Text after eq. 1.13: :math:`G(\mathbf 0) = 4I`, not :math:`\delta`.
* Footnote to eq. 1.17: at :math:`\mathbf n = 0`,
  :math:`E = \tfrac12 I^{-1}_{ij}m_im_j` (the factor :math:`\tfrac12` is missing).
* Eqs. 1.21, 1.28 are correct; with eq. 1.22 they reduce to
  :math:`\{m_i,m_j\} = \epsilon_{ijk}m_k` and :math:`\{\Omega_i,\Omega_j\} = -I^{-1}_{ia}I^{-1}_{jb}\epsilon_{abc}M_c`.

Kernels
-------
The right-hand sides and Hamiltonians are also plain *kernels*
(:func:`canonical_rhs`, :func:`geodesic_rhs`, ...) written with ``+ - * /``
only, on *component-first* inputs: a vector is anything with ``v[0], v[1],
v[2]`` (a tuple of floats, a 1-D array, an array of shape ``(3, ...)``, sympy
symbols, truncated Taylor series) and a matrix anything with ``M[i][j]``.
They return tuples. The objects call them with ``np.moveaxis(x, -1, 0)``;
:func:`numba_kernels` compiles them with numba.

Poisson bracket convention: :math:`\{f, g\} = \partial_{\mathbf n}f\cdot\partial_{\boldsymbol\pi}g
- \partial_{\boldsymbol\pi}f\cdot\partial_{\mathbf n}g`, :math:`\{n_i,\pi_j\} = \delta_{ij}`,
:math:`P_{ab} = \{z_a, z_b\}` and :math:`\dot z = P(z)\nabla H(z)`.

Modules
-------
Every name is re-exported here from :mod:`eulerpoisson.model.formulation_base`
(:class:`Formulation`), the families
:mod:`eulerpoisson.model.formulation_euler_poisson` and
:mod:`eulerpoisson.model.formulation_gibbs`, the registry
:mod:`eulerpoisson.model.formulation_registry` (:func:`formulation`),
:mod:`eulerpoisson.model.formulation_kernels` (the kernels) and
:mod:`eulerpoisson.model.gibbs_lagrangian` (the Lagrangian side).

References
----------
A. A. Deriglazov, *Geodesic motion on the symplectic leaf of SO(3) with
distorted e(3) algebra and Liouville integrability of a free rigid body*
(the paper), eqs. 1.4-1.30.
J. E. Marsden and T. S. Ratiu, *Introduction to Mechanics and Symmetry*,
2nd ed., Springer (1999), ch. 13-15 (momentum maps of left and right actions).
"""

from __future__ import annotations

from .formulation_base import Formulation as Formulation
from .formulation_base import gibbs_potential_gradient as gibbs_potential_gradient
from .formulation_euler_poisson import EulerPoisson as EulerPoisson
from .formulation_gibbs import MAX_GIBBS_NORM as MAX_GIBBS_NORM
from .formulation_gibbs import Canonical as Canonical
from .formulation_gibbs import Geodesic as Geodesic
from .formulation_gibbs import Momentum as Momentum
from .formulation_gibbs import Velocity as Velocity
from .formulation_kernels import canonical_hamiltonian as canonical_hamiltonian
from .formulation_kernels import canonical_rhs as canonical_rhs
from .formulation_kernels import euler_poisson_rhs as euler_poisson_rhs
from .formulation_kernels import euler_rhs as euler_rhs
from .formulation_kernels import geodesic_energy as geodesic_energy
from .formulation_kernels import geodesic_rhs as geodesic_rhs
from .formulation_kernels import kinetic_energy as kinetic_energy
from .formulation_kernels import momentum_hamiltonian as momentum_hamiltonian
from .formulation_kernels import momentum_rhs as momentum_rhs
from .formulation_kernels import numba_kernels as numba_kernels
from .formulation_kernels import velocity_rhs as velocity_rhs
from .formulation_registry import FORMULATIONS as FORMULATIONS
from .formulation_registry import formulation as formulation
from .gibbs_lagrangian import canonical_momentum as canonical_momentum
from .gibbs_lagrangian import christoffel as christoffel
from .gibbs_lagrangian import christoffel_from_metric as christoffel_from_metric
from .gibbs_lagrangian import geodesic_acceleration as geodesic_acceleration
from .gibbs_lagrangian import lagrangian as lagrangian
from .gibbs_lagrangian import metric_derivative as metric_derivative

__all__ = [
    "Formulation",
    "EulerPoisson",
    "Canonical",
    "Momentum",
    "Velocity",
    "Geodesic",
    "FORMULATIONS",
    "formulation",
    "gibbs_potential_gradient",
    # Lagrangian side
    "metric_derivative",
    "christoffel",
    "christoffel_from_metric",
    "lagrangian",
    "canonical_momentum",
    "geodesic_acceleration",
    # kernels
    "euler_rhs",
    "kinetic_energy",
    "euler_poisson_rhs",
    "canonical_rhs",
    "canonical_hamiltonian",
    "momentum_rhs",
    "momentum_hamiltonian",
    "velocity_rhs",
    "geodesic_rhs",
    "geodesic_energy",
    "numba_kernels",
]
