r"""The free-body part of the equations of motion: Euler's coefficients, written once.

In the principal frame Euler's equations (paper eq. 1.5) read

.. math:: \dot\Omega_1 = a_1\Omega_2\Omega_3,\quad \dot\Omega_2 = a_2\Omega_3\Omega_1,\quad
          \dot\Omega_3 = a_3\Omega_1\Omega_2, \qquad
          a_1 = \frac{I_2-I_3}{I_1},\ a_2 = \frac{I_3-I_1}{I_2},\ a_3 = \frac{I_1-I_2}{I_3}.

:func:`euler_coefficients` is used by every integrator, numpy and compiled
alike (it is compiled inline into the numba kernels), so the three
expressions exist once.
"""

from __future__ import annotations

from ..util.jit import jitable

__all__ = ["euler_coefficients"]


@jitable
def euler_coefficients(I1, I2, I3):
    r"""Euler's coefficients :math:`(a_1, a_2, a_3)` of the principal moments (floats or arrays).

    References
    ----------
    Paper eq. 1.5.
    """
    return (I2 - I3) / I1, (I3 - I1) / I2, (I1 - I2) / I3
