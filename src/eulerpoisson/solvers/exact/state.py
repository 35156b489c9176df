r"""Layout of the per-body state of the exact method's compiled kernels (private).

The kernels (:mod:`.scalar`, :mod:`.lanes`, :mod:`.lagrange_kernels`) keep the
constants of one body in a flat float64 array ``cst`` of length
:data:`N_CONST` (the lane kernel keeps ``LANES`` of them interleaved: field
``k`` of lane ``l`` at ``CL[k * LANES + l]``).  This module names every
offset of that array, once: the kernels read and write the fields by these
names only.  The names are plain module-level integers, which numba folds
into the compiled code as constants.

Fields (``lazy``: computed on first use, with a ``C_HAVE_*`` flag that is
``1.0`` once it is):

======================  ======  ===========================================================
name                    offset  content
======================  ======  ===========================================================
``C_REGIME``            0       regime code (:data:`REGIME_A`, :data:`REGIME_B`, :data:`SEPARATRIX`,
                                :data:`EQUILIBRIUM`)
``C_CASEB``             1       1.0 in regime B (circulation about the largest-moment axis)
``C_SEP``               2       1.0 on the separatrix
``C_M``, ``C_M1``       3, 4    elliptic parameter ``m`` and ``1 - m``
``C_KP``                5       ``k' = sqrt(m1)``
``C_KH``, ``C_KL``      6, 7    ``K`` (``pi/2`` on the separatrix), double-double
``C_PH``, ``C_PCORR``   8, 9    ``prod(1 + sqrt(p_i))`` of the Landen chain, as ``ph * (1 + pcorr)``
``C_LAM``               10      frequency ``lambda`` (scaled time)
``C_T0H``, ``C_T0L``    11, 12  initial phase ``tau0``, double-double
``C_AC`` ... ``C_AA``   13-15   amplitudes ``A_c``, ``A_2``, ``A_a``
``C_SA``, ``C_SC``      16, 17  signs of the axial and circled components
``C_RATE``, ``C_COEF``  18, 19  precession rate and the coefficient of the elliptic integral
``C_NU``, ``C_OMNU``    20, 21  characteristic ``nu`` and ``1 - nu``
``C_JC``                22      complete ``J_c`` (lazy)
``C_NADD``, ``C_CADD``  23, 24  constants of the addition theorem
``C_NUD``, ``C_OMNUD``  25, 26  characteristic of the direct form of ``G`` and its complement
``C_JCD``               27      complete integral of the direct form (lazy)
``C_G0``                28      ``1 + N`` (B), 1 (A)
``C_TSCALE``            29      ``2**escale``, or 0 where that is not a normal number
``C_SN0``               30      ``sn(tau0)`` (lazy, with the values at ``tau0``)
``C_JFAR0``             31      ``J_far(tau0)`` (lazy)
``C_THETA0``            32      azimuth at ``tau0`` (lazy, with the values at ``tau0``)
``C_KFULL``             33      ``K``, ``inf`` on the separatrix (bound of the near branch)
``C_Q0W`` ... ``C_Q0Z``  34-37   minimal rotation of the initial momentum
``C_PERM0`` ... ``2``   38-40   sorting permutation ``perm[k]`` (as floats)
``C_SGN0`` ... ``2``    41-43   signs ``sgn[k]`` of the sorted axes
``C_EM``                44      exponent of the ``M`` scaling
``C_ESCALE``            45      exponent of the time scaling
``C_NLEV``              46      number of Landen levels
``C_M0S`` ... ``2``     47-49   sorted, signed, *unscaled* ``M0`` (the exact output at ``t = 0``)
``C_MSCALE``            50      ``2**eM``, or 0 where that is not a normal number
(unused)                51, 52
``C_TAU0V`` (block)     53-57   ``n, r, s, c, d`` of the reduced ``tau0`` (lazy): ``C_TAU0_N`` ...
``C_HAVE_*``            58-61   flags of ``C_JC``, ``C_JCD``, ``C_JFAR0`` and of the values at ``tau0``
``C_SQM`` (block)       62      Landen levels ``sqrt(p_i)`` (:data:`MAX_LANDEN` entries)
``C_PCL`` (block)       102     Landen levels ``1 - p_i`` (:data:`MAX_LANDEN` entries)
======================  ======  ===========================================================

Examples
--------
>>> from eulerpoisson.solvers.exact import state
>>> state.N_CONST, state.C_PCL + state.MAX_LANDEN
(142, 142)
>>> state.C_TAU0_R == state.C_TAU0V + 1 and state.C_SGN1 == state.C_SGN0 + 1
True
"""

from __future__ import annotations

__all__ = [
    "MAX_LANDEN",
    "EQUILIBRIUM",
    "REGIME_A",
    "REGIME_B",
    "SEPARATRIX",
    "C_REGIME",
    "C_CASEB",
    "C_SEP",
    "C_M",
    "C_M1",
    "C_KP",
    "C_KH",
    "C_KL",
    "C_PH",
    "C_PCORR",
    "C_LAM",
    "C_T0H",
    "C_T0L",
    "C_AC",
    "C_A2",
    "C_AA",
    "C_SA",
    "C_SC",
    "C_RATE",
    "C_COEF",
    "C_NU",
    "C_OMNU",
    "C_JC",
    "C_NADD",
    "C_CADD",
    "C_NUD",
    "C_OMNUD",
    "C_JCD",
    "C_G0",
    "C_TSCALE",
    "C_SN0",
    "C_JFAR0",
    "C_THETA0",
    "C_KFULL",
    "C_Q0W",
    "C_Q0X",
    "C_Q0Y",
    "C_Q0Z",
    "C_PERM0",
    "C_PERM1",
    "C_PERM2",
    "C_SGN0",
    "C_SGN1",
    "C_SGN2",
    "C_EM",
    "C_ESCALE",
    "C_NLEV",
    "C_M0S",
    "C_M0S1",
    "C_M0S2",
    "C_MSCALE",
    "C_TAU0V",
    "C_TAU0_N",
    "C_TAU0_R",
    "C_TAU0_S",
    "C_TAU0_C",
    "C_TAU0_D",
    "N_TAU0V",
    "C_HAVE_JC",
    "C_HAVE_JCD",
    "C_HAVE_JFAR0",
    "C_HAVE_T0",
    "C_SQM",
    "C_PCL",
    "N_CONST",
    "LANES",
]

#: maximum number of Landen levels (as in numerics.elliptic; about 5 are ever used)
MAX_LANDEN = 40

# --- regime codes (as in motion) --------------------------------------------
EQUILIBRIUM = 0
REGIME_A = 1
REGIME_B = 2
SEPARATRIX = 3

# --- offsets of the per-body constants array ---------------------------------
C_REGIME = 0
C_CASEB = 1  # 1.0 regime B (circulation about the largest-moment axis)
C_SEP = 2  # 1.0 on the separatrix
C_M = 3
C_M1 = 4
C_KP = 5  # sqrt(m1)
C_KH = 6  # K (pi/2 on the separatrix), double-double
C_KL = 7
C_PH = 8  # prod(1 + sqrt(p_i)) of the Landen chain, ph * (1 + pcorr)
C_PCORR = 9
C_LAM = 10
C_T0H = 11  # tau0, double-double
C_T0L = 12
C_AC = 13
C_A2 = 14
C_AA = 15
C_SA = 16
C_SC = 17
C_RATE = 18
C_COEF = 19
C_NU = 20
C_OMNU = 21
C_JC = 22  # lazy
C_NADD = 23
C_CADD = 24
C_NUD = 25
C_OMNUD = 26
C_JCD = 27  # lazy
C_G0 = 28
C_TSCALE = 29  # 2**escale, or 0 where not a normal number (then ldexp)
C_SN0 = 30  # lazy (with the values at tau0)
C_JFAR0 = 31  # lazy
C_THETA0 = 32  # lazy (with the values at tau0)
C_KFULL = 33
C_Q0W = 34
C_Q0X = 35
C_Q0Y = 36
C_Q0Z = 37
C_PERM0 = 38  # perm[k] as float, k = 0, 1, 2
C_PERM1 = 39
C_PERM2 = 40
C_SGN0 = 41  # sgn[k]
C_SGN1 = 42
C_SGN2 = 43
C_EM = 44  # exponent of the M scaling
C_ESCALE = 45  # exponent of the time scaling
C_NLEV = 46  # number of Landen levels
C_M0S = 47  # sorted, signed, *unscaled* M0 (3 entries; exact output at t = 0)
C_M0S1 = 48
C_M0S2 = 49
C_MSCALE = 50  # 2**eM, or 0 where not a normal number
# (51 and 52 are not used)
C_TAU0V = 53  # n, r, s, c, d of the reduced tau0 (N_TAU0V entries; lazy)
C_TAU0_N = 53
C_TAU0_R = 54
C_TAU0_S = 55
C_TAU0_C = 56
C_TAU0_D = 57
#: entries of the block ``C_TAU0V``
N_TAU0V = 5
C_HAVE_JC = 58  # flags of the lazily computed constants: 1.0 once computed
C_HAVE_JCD = 59
C_HAVE_JFAR0 = 60
C_HAVE_T0 = 61
C_SQM = 62  # Landen levels sqrt(p_i) (MAX_LANDEN entries)
C_PCL: int = C_SQM + MAX_LANDEN  # and 1 - p_i
#: length of the per-body constants array
N_CONST: int = C_PCL + MAX_LANDEN

#: evaluations in lockstep in the lane kernel: its state interleaves LANES arrays, field k of lane l at k * LANES + l
LANES = 16
