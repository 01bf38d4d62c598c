"""Explicit dynamic adaptive CTM-RPIM (Section 2.1.4, Eqs. 8-11): :mod:`ctmrpim.solvers.explicit.run` drives a
run and gives the overview of the other modules (frame, step, contact, rebuild, time step, energy, state, output)."""
