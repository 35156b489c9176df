"""Parameter sweeps on a Dask cluster (or serially) into a resumable Zarr store, and the tennis-racket atlas."""

from .atlas import plot_atlas
from .config import SweepConfig, load_config
from .points import STATUS, compute_points
from .runner import load_sweep, run_sweep, sweep_summary

__all__ = [
    "SweepConfig",
    "load_config",
    "compute_points",
    "run_sweep",
    "load_sweep",
    "plot_atlas",
    "STATUS",
    "sweep_summary",
]
