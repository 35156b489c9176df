"""Numerical building blocks: elliptic functions and integrals, the quaternion product."""
