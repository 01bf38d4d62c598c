"""The frame of the explicit solver: the configuration its points are built on (Section 2.1.4).

**Configuration.** Boundary (the reference triangulation carried while valid, so corners are kept, else the
alpha shape), CTM points and RPIM shape functions are built on the node
positions x_r of the last rebuild (the frame, a
:class:`~ctmrpim.discretisation.configuration.Configuration`). Between rebuilds the points move with the body:
the deformation gradient relative to x_r is F = I + grad_r (x - x_r), and

    F_int = sum_p w_r,p P_p grad_r N,      P = det F sigma F^-T,

the internal force on the current configuration written on x_r (exactly the force of the moved points,
without rebuilding anything). The Cauchy stress is updated at the points each step with the increment
f = F_{n+1} F_n^-1 (Hughes-Winget: sigma rotated by Q, then the Mohr-Coulomb return of the strain
increment in the rotated frame; :mod:`ctmrpim.materials.objective_stress`, :mod:`ctmrpim.materials.mohr_coulomb`;
the step itself is :mod:`ctmrpim.solvers.explicit.step`, the rebuilds :mod:`ctmrpim.solvers.explicit.rebuild`).

**Robustness at a thinning front**: a node that leaves the alpha shape becomes a free particle
(``detached = "free"``; gravity and the walls still act on it) or stops the run (``"stop"``); a
support holding fewer than ``method.min_support`` nodes is widened to that many; a point whose moment
matrix is singular, whose gradients exceed GRADIENT_LIMIT / d_c (it extrapolates), or which one step
turns inside out (:mod:`ctmrpim.solvers.explicit.step`) gets weight 0 (it integrates nothing; all counted
in ``summary.json``).
"""
from __future__ import annotations

import numpy as np

from ctmrpim.discretisation.alpha_shape import Boundary, alpha_shape, carried_boundary
from ctmrpim.discretisation.configuration import Configuration, build, lay_points
from ctmrpim.discretisation.state_transfer import NodalProjection
from ctmrpim.solvers.explicit.errors import Diverged

#: Largest |grad N| d_c of a point that integrates: regular clouds give 1.2 to 1.7, a thinned flow front
#: up to about 7; 40 to 60 was measured at points left beyond the nodes of a front (spurious stiffness
#: there cut the stable time step 30-fold).
GRADIENT_LIMIT = 10.0
#: The deformation gradient (xx, xy, yx, yy) of a point relative to a frame built where it is.
IDENTITY = np.array([1.0, 0.0, 0.0, 1.0])


class FrameBuilder:
    """Builds the frames of an :class:`~ctmrpim.solvers.explicit.run.ExplicitRun` (a mixin of it: reads the
    run's ``case``, ``settings``, ``lengths``, ``d_c``, ``thickness``, reference nodes ``X`` and
    ``reference_triangles``, counts into ``dropped_points`` and ``tracking``)."""

    def lay_frame(self, x: np.ndarray, free: np.ndarray) -> Configuration:
        """Boundary and new CTM points on positions x (n, 2) of the body's nodes (``free`` (n,) marks the
        others), and RPIM there. A node outside the alpha shape has left the body: with ``detached = "stop"`` the run
        stops naming it; with ``"free"`` it becomes a free particle for good (gravity and the walls move
        it, it keeps its mass, no stress): a grain that left the flow does not rejoin it, so it can never
        land on top of a node of the body (two nodes at one place make the RPIM moment matrix singular)."""
        # the reference triangulation, carried, keeps the body's corners while it is valid and touches no node
        # that has left the body (alpha_shape.carried_boundary); the alpha shape re-tracks once it is not
        tri = self.reference_triangles
        carried = None if free[tri].any() else carried_boundary(x, tri, self.X, self.lengths.alpha)
        self.tracking[carried is None] += 1
        if carried is not None:
            quad, w = lay_points([x[lp] for lp in carried.loops], self.lengths, self.thickness)
            return self.frame_at(x, free, quad.points, w, carried.loops, carried.triangles)
        body = np.flatnonzero(~free)
        sub = alpha_shape(x[body], self.lengths.alpha, self.d_c)
        detached = body[sub.detached]
        if len(detached) and self.settings.detached == "stop":
            i = int(detached[0])
            raise Diverged(f"{len(detached)} node(s) left the body (outside the alpha shape), e.g. node #{i} "
                           f"at ({x[i, 0]:.5g}, {x[i, 1]:.5g}): it has left the domain of influence; "
                           "increase method.alpha or set explicit.detached = \"free\"", key="method.alpha")
        free = free.copy()
        free[detached] = True
        loops = [body[lp] for lp in sub.loops]
        quad, w = lay_points([x[lp] for lp in loops], self.lengths, self.thickness)
        return self.frame_at(x, free, quad.points, w, loops, body[sub.triangles])

    def frame_at(self, x: np.ndarray, free: np.ndarray, points: np.ndarray, w: np.ndarray,
                 loops: list[np.ndarray], triangles: np.ndarray) -> Configuration:
        """RPIM of the body's nodes at positions x (n, 2) (``free`` (n,) marks the others) at ``points`` (m, 2)
        with weights ``w`` (m,); ``loops`` the boundary (node indices) and ``triangles`` (t, 3) the alpha
        triangles that fill it (node indices; they move with the nodes like the loops, and are the surface
        of the saved states). A point whose moment matrix is singular, or whose shape-function gradients
        exceed GRADIENT_LIMIT / d_c (it extrapolates from a support on one side, where the nodes around it
        have left the body), gets weight 0: it integrates nothing (counted)."""
        boundary = Boundary(points=x, loops=loops, triangles=np.asarray(triangles, int).reshape(-1, 3),
                            detached=np.flatnonzero(free))
        frame = build(x.copy(), boundary, points.copy(), w.copy(), self.lengths, active=np.flatnonzero(~free),
                      min_nodes=self.case.method.min_support, drop_singular=True)
        dropped = np.union1d(frame.sf.dropped, extrapolating_points(frame, self.d_c))
        frame.w[dropped] = 0.0
        self.dropped_points += len(dropped)
        return frame


def extrapolating_points(frame: Configuration, d_c: float) -> np.ndarray:
    """(k,) indices of the points of ``frame`` whose shape-function gradients exceed GRADIENT_LIMIT / d_c: they
    extrapolate from a support on one side, where the nodes around them have left the body."""
    dx, dy = frame.sf.dNdx, frame.sf.dNdy
    size = np.sqrt(np.asarray(dx.multiply(dx).max(axis=1).todense()).ravel()
                   + np.asarray(dy.multiply(dy).max(axis=1).todense()).ravel()) * d_c
    return np.flatnonzero(size > GRADIENT_LIMIT)


def project_onto_nodes(frame: Configuration, w: np.ndarray, values: np.ndarray) -> np.ndarray:
    """Nodal values (n, k) of point values (m, k) with point weights ``w`` (m,): the L2 projection over the
    body nodes that some point of positive weight supports; the others (free particles, nodes left beside
    the dropped points of a thinned front, where the stress is about zero) get zero."""
    out = np.zeros((frame.N.shape[1], values.shape[1]))
    keep = frame.active[np.asarray(abs(frame.N[:, frame.active]).T @ w).ravel() > 0]
    out[keep] = NodalProjection(frame.N[:, keep], w)(values)
    return out
