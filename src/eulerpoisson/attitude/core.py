r"""The attitude functions and the :class:`Attitude` class, under their historical module name.

Kept for compatibility: everything that ``eulerpoisson.attitude.core`` defined now lives in
the modules of one concept each, and is re-exported here unchanged (the same objects):

* :mod:`.common`: :func:`skew`, :func:`unskew` and small helpers;
* :mod:`.quaternion`: quaternion algebra, normalization, sign, rotation matrices, scipy rotations;
* :mod:`.gibbs`: the paper's Gibbs vector n = k tan(alpha/2), its charts, the matrices
  A(n), Ã(n), R(n) and the metric G(n);
* :mod:`.rotvec`: axis-angle, the rotation vector alpha k and modified Rodrigues parameters;
* :mod:`.euler`: Euler angles in all 12 sequences;
* :mod:`.attitude`: the :class:`Attitude` class and the ``AttitudeLike`` alias.

New code imports from :mod:`eulerpoisson.attitude` (or from those modules).
"""

from __future__ import annotations

# the names marked noqa are not in __all__ but were importable from here before the split, and the rest
# of the package imports them from here
from .attitude import (
    Attitude,
    AttitudeLike,  # noqa: F401
)
from .common import (
    finite_result,  # noqa: F401
    skew,
    unskew,
)
from .euler import (
    EULER_GIMBAL_TOL,
    euler_from_gibbs,
    euler_from_quaternion,
    gibbs_from_euler,
    parse_seq,  # noqa: F401
    quaternion_from_euler,
)
from .gibbs import (
    conversion_matrix,
    gibbs_chart,
    gibbs_compose,
    gibbs_from_matrix,
    gibbs_from_quaternion,
    gibbs_inverse,
    gibbs_rate_from_omega,
    inverse_conversion_matrix,
    inverse_metric,
    matrix_from_conversion,
    matrix_from_gibbs,
    metric,
    omega_from_gibbs_rate,
    quaternion_from_chart,
    quaternion_from_gibbs,
)
from .quaternion import (
    UNIT_QUATERNION_TOLERANCE,
    as_quaternion,  # noqa: F401
    matrix_from_quaternion,
    matrix_from_unit_quaternion,  # noqa: F401
    quaternion_canonical,
    quaternion_conjugate,
    quaternion_from_matrix,
    quaternion_from_rotation_matrix,  # noqa: F401
    quaternion_from_scipy,
    quaternion_make_continuous,
    quaternion_multiply,
    quaternion_normalize,
    scipy_from_quaternion,
)
from .rotvec import (
    axis_angle_from_gibbs,
    axis_angle_from_quaternion,
    gibbs_from_axis_angle,
    gibbs_from_mrp,
    gibbs_from_rotvec,
    mrp_from_gibbs,
    mrp_from_quaternion,
    quaternion_from_axis_angle,
    quaternion_from_mrp,
    quaternion_from_rotvec,
    rotvec_from_gibbs,
    rotvec_from_quaternion,
)

__all__ = [
    "Attitude",
    "UNIT_QUATERNION_TOLERANCE",
    "skew",
    "unskew",
    "quaternion_multiply",
    "quaternion_conjugate",
    "quaternion_normalize",
    "quaternion_canonical",
    "quaternion_make_continuous",
    "quaternion_from_gibbs",
    "gibbs_from_quaternion",
    "matrix_from_quaternion",
    "quaternion_from_matrix",
    "matrix_from_gibbs",
    "gibbs_from_matrix",
    "quaternion_from_axis_angle",
    "axis_angle_from_quaternion",
    "quaternion_from_rotvec",
    "rotvec_from_quaternion",
    "quaternion_from_mrp",
    "mrp_from_quaternion",
    "quaternion_from_euler",
    "euler_from_quaternion",
    "quaternion_from_scipy",
    "scipy_from_quaternion",
    "gibbs_from_axis_angle",
    "axis_angle_from_gibbs",
    "gibbs_from_rotvec",
    "rotvec_from_gibbs",
    "gibbs_from_mrp",
    "mrp_from_gibbs",
    "gibbs_from_euler",
    "euler_from_gibbs",
    "gibbs_compose",
    "gibbs_inverse",
    "gibbs_chart",
    "quaternion_from_chart",
    "conversion_matrix",
    "inverse_conversion_matrix",
    "matrix_from_conversion",
    "omega_from_gibbs_rate",
    "gibbs_rate_from_omega",
    "metric",
    "inverse_metric",
    "EULER_GIMBAL_TOL",
]
