"""Pictures and animations of trajectories (matplotlib, the ``plot`` extra)."""
