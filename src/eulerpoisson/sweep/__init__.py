"""Parameter sweeps on a Dask cluster (or serially) into a resumable Zarr store, and the tennis-racket atlas."""

from .runner import STATUS, SweepConfig, compute_points, load_config, load_sweep, plot_atlas, run_sweep

__all__ = ["SweepConfig", "load_config", "compute_points", "run_sweep", "load_sweep", "plot_atlas", "STATUS"]
