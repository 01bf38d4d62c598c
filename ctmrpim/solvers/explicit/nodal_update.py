"""The nodal half of a central-difference step, compiled (numba): Eqs. (9)-(11) node by node, with the walls and the
step's works (:mod:`ctmrpim.solvers.explicit.step`).

    f = F_ext - F_int,   f_damp = -f_l |f| sign(v_{n-1/2}),   v_{n+1/2} = v_{n-1/2} + h (f + f_damp) / m   (Eqs. 9-11)

with h = (dt_{n-1} + dt_n) / 2 the time from v_{n-1/2} to v_{n+1/2} (the central difference of a varying step),
then the fixed dofs held (v = 0), the walls' contact (:func:`ctmrpim.solvers.explicit.contact.contact`) and
x_{n+1} = x_n + dt_n v_{n+1/2}; in the dynamic stage also the step's works with the mid-step displacement
h (v_{n+1/2} + v_{n-1/2}) / 2: of gravity, of the internal force, of the damping and of the walls (their velocity
corrections, m (v_{n+1/2} - v_{n-1/2} - dv) (v_{n+1/2} + v_{n-1/2}) / 2). Why h and not dt_n: with dt_n in the
velocity update the works balance the kinetic energy just as exactly, but they are booked over h_n-weighted
velocities that are not the nodes' displacement (x_{n+1} - x_{n-1}) / 2 = (dt_n v_{n+1/2} + dt_{n-1} v_{n-1/2}) / 2:
at every change of the step the booked internal work missed f (dt_n - dt_{n-1}) v_{n-1/2} / 2, a first-order
error that the material's ledger saw (measured on the 496-node collapse: -1.9e-4 of the gravity work in its
first 700 steps, 6 changes of dt). With h the gap is f (dt_n - dt_{n-1}) (v_{n+1/2} - v_{n-1/2}) / 4, second order.

Why compiled: as numpy expressions these were about thirty array operations on the (n, 2) nodal arrays and one per
wall, 0.2 ms a step on the 1071-node column (a fifth of the step once the point pass scatters the force), each
a pass over arrays a few kB long, where the call costs more than the arithmetic. The sums run node by node in
index order: fixed by the cloud, so a resumed run repeats the uninterrupted one.
"""
from __future__ import annotations

import numpy as np
from numba import njit

from ctmrpim.solvers.explicit.contact import contact


@njit(cache=True, nogil=True)
def nodal_update(f_int, weight, mass, movable, v_old, x, dt, h, damping, walls, works, v, x_new, f):
    """v (n, 2) <- v_{n+1/2}, x_new (n, 2) <- x_{n+1}, f (n, 2) <- F_ext - F_int from the internal force ``f_int``,
    the nodal weights m g ``weight``, the lumped ``mass`` (n,), the free dofs ``movable`` (n, 2), v_{n-1/2}
    ``v_old`` and x_n ``x``, the step ``dt`` and the velocity's step ``h``; ``damping`` the local damping f_l,
    ``walls`` the contact table (:func:`ctmrpim.solvers.explicit.contact.wall_table`). Where ``works`` has 4
    entries the step's works of gravity, internal force, damping and walls are added into them (the dynamic stage).
    Returns the first node whose velocity is not finite, or -1."""
    book = works.shape[0] == 4
    bad = -1
    wg = wi = wd = ww = 0.0
    for j in range(x.shape[0]):
        m = mass[j]
        f0 = weight[j, 0] - f_int[j, 0]
        f1 = weight[j, 1] - f_int[j, 1]
        f[j, 0], f[j, 1] = f0, f1
        d0 = d1 = 0.0
        if damping != 0.0:
            d0 = -damping * abs(f0) * np.sign(v_old[j, 0])
            d1 = -damping * abs(f1) * np.sign(v_old[j, 1])
        dv0, dv1 = h * (f0 + d0) / m, h * (f1 + d1) / m
        a0 = v_old[j, 0] + dv0 if movable[j, 0] else 0.0
        a1 = v_old[j, 1] + dv1 if movable[j, 1] else 0.0
        a0, a1 = contact(walls, x[j, 0], x[j, 1], a0, a1, dt)
        if bad < 0 and not (np.isfinite(a0) and np.isfinite(a1)):
            bad = j
        v[j, 0], v[j, 1] = a0, a1
        x_new[j, 0], x_new[j, 1] = x[j, 0] + dt * a0, x[j, 1] + dt * a1
        if book:
            m0, m1 = 0.5 * h * (a0 + v_old[j, 0]), 0.5 * h * (a1 + v_old[j, 1])
            wg += weight[j, 0] * m0 + weight[j, 1] * m1
            wi += f_int[j, 0] * m0 + f_int[j, 1] * m1
            wd += d0 * m0 + d1 * m1
            ww += m * ((a0 - v_old[j, 0] - dv0) * 0.5 * (a0 + v_old[j, 0])
                       + (a1 - v_old[j, 1] - dv1) * 0.5 * (a1 + v_old[j, 1]))
    if book:
        works[0] += wg
        works[1] += wi
        works[2] += wd
        works[3] += ww
    return bad
