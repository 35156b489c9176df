"""Small shared utilities: argument validation, the numba switch (kernels made on first use) and their warm-up."""
