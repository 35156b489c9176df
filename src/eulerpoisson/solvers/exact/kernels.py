r"""Compiled kernels of the closed-form free rigid body (private): the entry points.

The exact method's compiled code is split into modules that import each
other in one direction only (``state`` <- ``scalar_elliptic`` <- ``scalar``
<- ``lanes_setup`` <- ``lanes`` <- ``kernels``; ``lagrange_kernels`` reads
this module):

* :mod:`eulerpoisson.solvers.exact.state`: the layout of the per-body state
  array ``cst`` (its fields ``C_*``, :data:`N_CONST`, the regime codes);
* :mod:`eulerpoisson.solvers.exact.scalar_elliptic`: double-double
  arithmetic, Carlson's ``R_F``/``R_J``, the AGM and Landen chain
  (``params``), the Jacobi functions (``sncndn3``), scalar;
* :mod:`eulerpoisson.solvers.exact.scalar`: the scalar kernel, a scalar
  transcription of :mod:`eulerpoisson.solvers.exact.motion` (every
  floating-point operation in the same order on the same operands):
  :func:`body_setup`, :func:`body_eval`, :func:`motion_kernel_scalar`,
  :func:`constants_kernel`, :func:`free_flow`;
* :mod:`eulerpoisson.solvers.exact.lanes` (its per-body set-up in
  :mod:`eulerpoisson.solvers.exact.lanes_setup`): the lane kernel, sixteen
  evaluations in lockstep, bitwise equal to :func:`motion_kernel_scalar`.

This module chooses among them: :data:`motion_kernel` is the kernel
:func:`eulerpoisson.solvers.exact.motion.exact_motion` runs (the lane kernel:
``motion_kernel(inertia, M0, t, Mout, qout)`` fills ``Mout`` (nb, T, 3) and
``qout`` (nb, T, 4) for bodies (nb, 3) and times (T,), inputs validated by
the caller: finite, moments > 0, C-contiguous float64), and it re-exports the
names of the modules above that the package, the tests and the benchmarks
read from here.

The compiled kernels are used when numba is installed and the environment
variable ``EULERPOISSON_NO_NUMBA`` is not ``"1"`` (:data:`USE_NUMBA`, decided
when eulerpoisson is imported, without importing numba: the dispatchers and
intrinsics are made on the first call of a kernel and loaded from numba's
cache, :mod:`eulerpoisson.util.jit`; ``eulerpoisson warmup`` fills the cache);
otherwise :mod:`eulerpoisson.solvers.exact.motion` runs its NumPy path (the
reference), which ``solve`` also runs for small problems (no numba import).
The functions are plain Python when numba is not used (correct, bitwise
equal, but slow; not used by the package then).

Examples
--------
>>> from eulerpoisson.solvers.exact import kernels, lanes
>>> kernels.motion_kernel is lanes.motion_lanes
True
"""

from __future__ import annotations

__all__ = [
    "USE_NUMBA",
    "N_CONST",
    "MAX_LANDEN",
    "body_setup",
    "body_eval",
    "motion_kernel",
    "motion_kernel_scalar",
    "free_flow",
    "equilibrium_eval",
    "constants_kernel",
]

from ...util.jit import USE_NUMBA as USE_NUMBA  # numba importable and EULERPOISSON_NO_NUMBA not "1"
from .lanes import motion_lanes
from .scalar import body_eval as body_eval
from .scalar import body_setup as body_setup
from .scalar import constants_kernel as constants_kernel
from .scalar import equilibrium_eval as equilibrium_eval
from .scalar import exponent_lane as exponent_lane
from .scalar import free_flow as free_flow
from .scalar import jsep as jsep
from .scalar import jtot_args as jtot_args
from .scalar import jtot_from as jtot_from
from .scalar import motion_kernel_scalar as motion_kernel_scalar
from .scalar import near_xadd as near_xadd
from .scalar import perm3 as perm3
from .scalar import pick3 as pick3
from .scalar import pow2 as pow2
from .scalar import pre_amplitude as pre_amplitude
from .scalar import pre_regime as pre_regime
from .scalar import qmin as qmin
from .scalar import qmul as qmul
from .scalar import setup_post as setup_post
from .scalar import setup_pre as setup_pre
from .scalar import theta_v as theta_v
from .scalar_elliptic import LANDEN_THRESHOLD as LANDEN_THRESHOLD
from .scalar_elliptic import MAX_AGM as MAX_AGM
from .scalar_elliptic import MAX_DUPLICATION as MAX_DUPLICATION
from .scalar_elliptic import PI_HI as PI_HI
from .scalar_elliptic import PI_LO as PI_LO
from .scalar_elliptic import PIO2_HI as PIO2_HI
from .scalar_elliptic import PIO2_LO as PIO2_LO
from .scalar_elliptic import RC_SERIES_MAX as RC_SERIES_MAX
from .scalar_elliptic import RDJ_QFAC as RDJ_QFAC
from .scalar_elliptic import RF_QFAC as RF_QFAC
from .scalar_elliptic import SINCOS_POLY_MAX as SINCOS_POLY_MAX
from .scalar_elliptic import TWO200 as TWO200
from .scalar_elliptic import TWOM100 as TWOM100
from .scalar_elliptic import TWOM104 as TWOM104
from .scalar_elliptic import cos_poly as cos_poly
from .scalar_elliptic import dd_add as dd_add
from .scalar_elliptic import dd_div_f as dd_div_f
from .scalar_elliptic import dd_mul as dd_mul
from .scalar_elliptic import dd_mul_f as dd_mul_f
from .scalar_elliptic import dd_sqrt_f as dd_sqrt_f
from .scalar_elliptic import dn_from_sc as dn_from_sc
from .scalar_elliptic import fast_sqrt as fast_sqrt
from .scalar_elliptic import imag_level as imag_level
from .scalar_elliptic import params as params
from .scalar_elliptic import quadrant as quadrant
from .scalar_elliptic import rc1 as rc1
from .scalar_elliptic import rc1_series as rc1_series
from .scalar_elliptic import real_level as real_level
from .scalar_elliptic import reduce as reduce
from .scalar_elliptic import rf_poly as rf_poly
from .scalar_elliptic import rj1 as rj1
from .scalar_elliptic import rj3 as rj3
from .scalar_elliptic import rj_finish as rj_finish
from .scalar_elliptic import rj_init as rj_init
from .scalar_elliptic import sech_real as sech_real
from .scalar_elliptic import sin_poly as sin_poly
from .scalar_elliptic import sncndn3 as sncndn3
from .scalar_elliptic import two_prod as two_prod
from .scalar_elliptic import two_sum as two_sum
from .state import C_A2 as C_A2
from .state import C_AA as C_AA
from .state import C_AC as C_AC
from .state import C_CADD as C_CADD
from .state import C_CASEB as C_CASEB
from .state import C_COEF as C_COEF
from .state import C_EM as C_EM
from .state import C_ESCALE as C_ESCALE
from .state import C_G0 as C_G0
from .state import C_HAVE_JC as C_HAVE_JC
from .state import C_HAVE_JCD as C_HAVE_JCD
from .state import C_HAVE_JFAR0 as C_HAVE_JFAR0
from .state import C_HAVE_T0 as C_HAVE_T0
from .state import C_JC as C_JC
from .state import C_JCD as C_JCD
from .state import C_JFAR0 as C_JFAR0
from .state import C_KFULL as C_KFULL
from .state import C_KH as C_KH
from .state import C_KL as C_KL
from .state import C_KP as C_KP
from .state import C_LAM as C_LAM
from .state import C_M as C_M
from .state import C_M0S as C_M0S
from .state import C_M1 as C_M1
from .state import C_MSCALE as C_MSCALE
from .state import C_NADD as C_NADD
from .state import C_NLEV as C_NLEV
from .state import C_NU as C_NU
from .state import C_NUD as C_NUD
from .state import C_OMNU as C_OMNU
from .state import C_OMNUD as C_OMNUD
from .state import C_PCL as C_PCL
from .state import C_PCORR as C_PCORR
from .state import C_PERM0 as C_PERM0
from .state import C_PH as C_PH
from .state import C_Q0W as C_Q0W
from .state import C_Q0X as C_Q0X
from .state import C_Q0Y as C_Q0Y
from .state import C_Q0Z as C_Q0Z
from .state import C_RATE as C_RATE
from .state import C_REGIME as C_REGIME
from .state import C_SA as C_SA
from .state import C_SC as C_SC
from .state import C_SEP as C_SEP
from .state import C_SGN0 as C_SGN0
from .state import C_SN0 as C_SN0
from .state import C_SQM as C_SQM
from .state import C_T0H as C_T0H
from .state import C_T0L as C_T0L
from .state import C_TAU0V as C_TAU0V
from .state import C_THETA0 as C_THETA0
from .state import C_TSCALE as C_TSCALE
from .state import MAX_LANDEN as MAX_LANDEN
from .state import N_CONST as N_CONST
from .state import REGIME_A as REGIME_A
from .state import REGIME_B as REGIME_B
from .state import SEPARATRIX as SEPARATRIX

#: The compiled entry point of the closed form: the lane kernel (sixteen evaluations in lockstep), whose
#: results are those of :func:`motion_kernel_scalar` bit for bit (``tests/test_exact_lanes.py``).
motion_kernel = motion_lanes
