"""scikit-fem reference solver (Q1, P1, P2) for the same problems the CTM-RPIM solver solves.

It is the method ``"fem"`` of :mod:`ctmrpim.methods` (``reference_fem.method.METHOD``, announced by the
entry point ``ctmrpim.methods: fem``), so ``ctmrpim.solve(case, "fem", "p2")`` reaches it without the
core importing it.
"""
from reference_fem.hyperelastic import solve_fem_hyperelastic
from reference_fem.solve import solve_fem

__all__ = ["solve_fem", "solve_fem_hyperelastic"]
