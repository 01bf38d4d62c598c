"""scikit-fem reference solver (Q1, P1, P2) for the same problems the CTM-RPIM solver solves."""
from .hyperelastic import solve_fem_hyperelastic
from .solve import solve_fem

__all__ = ["solve_fem", "solve_fem_hyperelastic"]
