r"""Attitude sets centred on the paper's rotation vector n = k tan(alpha/2).

The functions ``<to>_from_<from>`` convert between the Gibbs vector, unit
quaternions (scalar first), rotation matrices, axis-angle, the rotation vector
alpha k (``rotvec``, scipy's), modified Rodrigues parameters and Euler angles;
the paper's matrices A(n), Ã(n) and the metric G(n) = 4 A I Aᵀ are here too,
and :class:`Attitude` is a thin class over them (modules :mod:`.quaternion`,
:mod:`.gibbs`, :mod:`.rotvec`, :mod:`.euler`, :mod:`.attitude`; :mod:`.core`
re-exports them all under its historical name).
"""

# the public names, one list: those of .core (which gathers the modules of one concept each)
from .core import *  # noqa: F403
from .core import __all__  # noqa: F401
