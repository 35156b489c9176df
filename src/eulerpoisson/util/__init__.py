"""Small shared utilities: argument validation and the numba switch."""
