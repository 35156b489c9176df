r"""The drift of a model's integrals along a trajectory, seen whole or in pieces (bounded memory).

:meth:`eulerpoisson.Trajectory.drift` and the command line's long runs both
use :class:`DriftAccumulator`: the integrals of :meth:`eulerpoisson.Model.integrals`
are evaluated piece by piece and only their largest deviation from the first
sample is kept, so a run of 10⁷ samples needs the memory of one piece.

For each integral :math:`x`, the drift is :math:`\max_t|x(t) - x(t_0)|/s`
with the scale :math:`s` of its kind: for the energy-like integrals
(``energy``, ``jacobi``) the sum of the magnitudes of their terms at
:math:`t_0` (kinetic energy plus :math:`|U|`, so that a zero total energy
does not divide by zero), for the angular momenta (``m_*``, ``M3``)
:math:`|\mathbf m(t_0)|`, for the others their own magnitude. A zero scale
(a body at rest) gives the absolute deviation.
"""

from __future__ import annotations

import numpy as np

from ..attitude.core import matrix_from_unit_quaternion

__all__ = ["DriftAccumulator"]


class DriftAccumulator:
    """Largest deviation of each integral of ``model`` from its value at the first sample.

    Parameters
    ----------
    model : Model

    Examples
    --------
    >>> import numpy as np, eulerpoisson as ep
    >>> tr = ep.solve([1.0, 2.0, 3.0], np.linspace(0, 10, 101), omega0=[1.0, 0.1, 0.5])
    >>> acc = DriftAccumulator(tr.model)
    >>> for part in (tr[:50], tr[50:]):
    ...     acc.update(part.t, part.quaternion, part.omega)
    >>> acc.result() == tr.drift()
    True
    """

    def __init__(self, model):
        self.model = model
        self._first: dict | None = None
        self._dev: dict = {}
        self._kin0 = None
        self._mn0 = None

    def update(self, t, q, omega) -> None:
        """Take the samples ``t`` (T,), ``q`` (*batch, T, 4), ``omega`` (*batch, T, 3) (the first call: from t0)."""
        t = np.asarray(t, dtype=float)
        if t.size == 0:
            return
        vals = self.model.integrals(t, q, omega)
        if self._first is None:
            self._first = {k: v[..., 0] for k, v in vals.items()}
            inertia = np.asarray(self.model.body.inertia, dtype=float)
            w0 = np.asarray(omega, dtype=float)[..., 0, :]
            M0 = np.einsum("...ij,...j->...i", inertia, w0)
            self._kin0 = 0.5 * np.sum(w0 * M0, axis=-1)
            R0 = matrix_from_unit_quaternion(np.asarray(q, dtype=float)[..., 0, :])
            m0 = np.einsum("...ij,...j->...i", R0, M0)
            self._mn0 = np.sqrt(np.sum(m0 * m0, axis=-1))
        for k, v in vals.items():
            d = np.max(np.abs(v - self._first[k][..., None]), axis=-1)
            self._dev[k] = d if k not in self._dev else np.maximum(self._dev[k], d)

    def result(self) -> dict:
        """The relative drift of every integral (floats for one body, arrays of the batch shape otherwise).

        Raises
        ------
        ValueError
            Nothing was given to :meth:`update`.
        """
        if self._first is None:
            raise ValueError("no samples: the drift is measured from the first sample")
        out = {}
        keys = list(self._dev)
        if self.model.is_free:  # the order of the free body's report: energy, |m|, then its components
            keys = ["energy", "m_norm", "m_x", "m_y", "m_z"]
        for k in keys:
            x0 = self._first[k]
            if k in ("energy", "jacobi"):
                scale = self._kin0 + np.abs(x0 - self._kin0)
            elif k.startswith("m_") or k == "M3":
                scale = self._mn0
            else:
                scale = np.abs(x0)
            rel = self._dev[k] / np.where(scale > 0, scale, 1.0)
            out[k] = float(rel) if np.ndim(rel) == 0 else rel
        return out
