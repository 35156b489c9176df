r"""Attitude sets centred on the paper's rotation vector n = k tan(alpha/2).

The functions ``<to>_from_<from>`` convert between the Gibbs vector, unit
quaternions (scalar first), rotation matrices, axis-angle, the rotation vector
alpha k (``rotvec``, scipy's), modified Rodrigues parameters and Euler angles;
the paper's matrices A(n), Ã(n) and the metric G(n) = 4 A I Aᵀ are here too,
and :class:`Attitude` is a thin class over them (modules :mod:`.quaternion`,
:mod:`.gibbs`, :mod:`.rotvec`, :mod:`.euler`, :mod:`.attitude`; :mod:`.core`
re-exports them all under its historical name).
"""

from .attitude import Attitude
from .common import (
    skew,
    unskew,
)
from .euler import (
    EULER_GIMBAL_TOL,
    euler_from_gibbs,
    euler_from_quaternion,
    gibbs_from_euler,
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
    matrix_from_quaternion,
    quaternion_canonical,
    quaternion_conjugate,
    quaternion_from_matrix,
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
