"""Genesis (``pip install genesis-world``): not driven yet.

``python -m pip install --only-binary :all: genesis-world`` fails here: every release pins
``pygltflib==1.16.0``, which has no wheel (an sdist only); Genesis also needs PyTorch. The adapter
reports that until Genesis can be installed and its rigid solver driven.
"""

from __future__ import annotations

from ..cases import ReferenceCase
from ..runs import Conventions
from .base import Engine, EngineRun, EngineUnavailable, SamplePlan

__all__ = ["GenesisEngine"]


class GenesisEngine(Engine):
    """Genesis's rigid solver (adapter pending: the package does not install here)."""

    name = "genesis"
    title = "Genesis"
    package = "genesis-world"
    module = "genesis"
    settings = {"rigid": "Genesis's rigid solver, default options"}
    conventions = Conventions("wxyz", "space", "body-to-space")

    def available(self) -> tuple[bool, str]:
        ok, why = super().available()
        if not ok:
            return False, why + " (here: pygltflib==1.16.0, which every genesis-world release pins, has no wheel)"
        return False, "genesis imports, but its adapter is not written yet (it could not be installed to build it)"

    def simulate(self, case: ReferenceCase, setting: str, plan: SamplePlan) -> EngineRun:  # pragma: no cover
        raise EngineUnavailable(self.available()[1])
