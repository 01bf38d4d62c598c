"""Quasi-static neo-Hookean total-Lagrangian solve with dolfinx: the strain energy written in UFL, its first
and second variations by ``ufl.derivative`` (nothing of ctmrpim's P and A), Newton-Raphson with load stepping.

    W = mu/2 (tr C + 1 - 3) - mu ln J + lambda/2 (ln J)^2   (plane strain, F33 = 1),
    R(u) = t * int dW/dF : grad v dX - lambda_load F_dead,    K = dR/du.

The stepping is the scikit-fem reference's (``ctmrpim.solvers.load_stepping``, restated here): equal
increments of the load factor, the secant predictor, convergence when the residual at free dofs is within
``tolerance`` of max(|F_ext|, |F_int|) and the step within ``tolerance`` of |u|, an increment halved where
Newton fails and grown back after an easy one. Prescribed displacements grow with the load factor.
"""
from __future__ import annotations

import time

import basix
import numpy as np
import ufl
from dolfinx import fem
from dolfinx.fem import petsc as fem_petsc
from fx_mesh import MeshData
from fx_post import Probes, at_vertices, integral, lu, project
from fx_problem import Discrete, dead_load, discretise, scale_dirichlet
from petsc4py import PETSc


class NotConverged(RuntimeError):
    """Newton gave up after its cut-backs (the bridge raises a ConvergenceError with ``history``)."""

    def __init__(self, message: str, history: list) -> None:
        super().__init__(message)
        self.history = history


def _energy(d: Discrete, spec: dict, u):
    """The strain energy density W(F) and the Cauchy stress (sxx, syy, sxy, szz) of the displacement ``u``."""
    mu = fem.Constant(d.md.mesh, PETSc.ScalarType(spec["material"]["mu"]))
    lam = fem.Constant(d.md.mesh, PETSc.ScalarType(spec["material"]["lambda"]))
    F = ufl.variable(ufl.Identity(2) + ufl.grad(u))
    J = ufl.det(F)
    W = mu / 2 * (ufl.tr(F.T * F) + 1 - 3) - mu * ufl.ln(J) + lam / 2 * ufl.ln(J) ** 2
    sigma = ufl.diff(W, F) * F.T / J
    return W, [sigma[0, 0], sigma[1, 1], sigma[0, 1], lam * ufl.ln(J) / J]


def solve(md: MeshData, spec: dict, timings: dict) -> tuple[dict, dict]:
    """Solve the neo-Hookean problem ``spec`` on ``md`` by load stepping: the result record and nodal arrays."""
    start = time.perf_counter()
    d = discretise(md, spec)
    q = spec["quadrature"]
    u = fem.Function(d.V)
    v, du = ufl.TestFunction(d.V), ufl.TrialFunction(d.V)
    W, cauchy = _energy(d, spec, u)
    dx = ufl.Measure("dx", domain=md.mesh, metadata={"quadrature_degree": q["stiffness"]})
    internal = d.thickness * W * dx
    residual_form = fem.form(ufl.derivative(internal, u, v))
    tangent_form = fem.form(ufl.derivative(ufl.derivative(internal, u, v), u, du))
    L = dead_load(d, spec, v)
    f_dead = fem_petsc.assemble_vector(fem.form(L)).array.copy() if L is not None else np.zeros(u.x.array.size)
    fixed = np.unique(np.concatenate([bc.dof_indices()[0] for bc in d.bcs])) if d.bcs else np.zeros(0, int)
    names = [p["name"] for p in spec["probes"]]
    probes = Probes(md, np.array([p["at"] for p in spec["probes"]]).reshape(-1, 2), names)
    timings["setup"] = time.perf_counter() - start

    start = time.perf_counter()

    def assemble(U: np.ndarray):
        u.x.array[:] = U
        f_int = fem_petsc.assemble_vector(residual_form)
        K = fem_petsc.assemble_matrix(tangent_form, bcs=d.bcs)
        K.assemble()
        return f_int.array.copy(), K

    def prescribed(factor: float) -> np.ndarray:
        scale_dirichlet(d, factor)
        x = u.vector.duplicate()
        x.zeroEntries()
        fem_petsc.set_bc(x, d.bcs)
        return x.array[fixed].copy()

    def on_converged(U: np.ndarray) -> dict:
        u.x.array[:] = U
        vals = probes(u) if names else []
        return {n: {"x": p["x"], "y": p["y"], "ux": float(vals[i][0]), "uy": float(vals[i][1])}
                for i, (n, p) in enumerate(zip(names, spec["probes"]))}

    U, history, counts = _step_loads(u.x.array.size, spec["loading"], fixed, f_dead, assemble, prescribed,
                                     on_converged)
    u.x.array[:] = U
    timings["solve"] = time.perf_counter() - start

    start = time.perf_counter()
    ncells = int(md.mesh.topology.index_map(2).size_local)
    projected = project(md, d.degree, cauchy, q["projection"])
    u_p, s_p = (probes(u), probes(projected)) if names else ([], [])
    record = {
        "probes": {n: {"x": p["x"], "y": p["y"], "ux": float(u_p[i][0]), "uy": float(u_p[i][1]),
                       **{k: float(s_p[i][j]) for j, k in enumerate(("sxx", "syy", "sxy"))}}
                   for i, (n, p) in enumerate(zip(names, spec["probes"]))},
        "errors": {},
        "strain_energy": spec["thickness"] * integral(md, W, q["stiffness"]),
        "history": history,
        "counts": {"nodes": len(md.input_vertex), "dofs": int(u.x.array.size), "elements": ncells,
                   "integration_points": ncells * len(basix.make_quadrature(getattr(basix.CellType, md.cell),
                                                                            q["stiffness"])[1]), **counts},
    }
    nodal = at_vertices(md, projected)
    timings["postprocess"] = time.perf_counter() - start
    return record, {"u": at_vertices(md, u), "stress": nodal[:, :3], "stress_zz": nodal[:, 3], "masks": d.masks}


def _step_loads(n: int, loading: dict, fixed: np.ndarray, f_dead: np.ndarray, assemble, prescribed, on_converged):
    """Load factor from 0 to 1 in increments (module docstring): the converged dofs, the history, the counts."""
    steps, tol = int(loading["steps"]), float(loading["tolerance"])
    U = np.zeros(n)
    factor, dfactor, last_step, last_dfactor = 0.0, 1.0 / steps, None, 0.0
    history, cutbacks, iterations = [], 0, 0
    while factor < 1.0 - 1e-12:
        target = min(1.0, factor + dfactor)
        trial = U.copy()
        if last_step is not None:
            trial += (target - factor) / last_dfactor * last_step
        trial[fixed] = prescribed(target)
        converged, ref, first, it = False, None, 0.0, 0
        for it in range(1, int(loading["max_iterations"]) + 1):
            try:
                f_int, K = assemble(trial)
            except (RuntimeError, ValueError):
                break
            if not np.all(np.isfinite(f_int)):      # ln J of an inverted material
                break
            f_ext = target * f_dead
            if ref is None:
                ref = max(np.linalg.norm(f_ext), 1e-30)
            r = f_ext - f_int
            scale = max(ref, np.linalg.norm(f_int))
            r[fixed] = 0.0
            rhs = K.createVecRight()
            rhs.array[:] = r
            step = K.createVecRight()
            lu(K).solve(rhs, step)
            du = step.array.copy()
            trial += du
            iterations += 1
            if it == 1:
                first = np.linalg.norm(du)
            elif not np.isfinite(np.linalg.norm(du)) or np.linalg.norm(du) > 100.0 * max(first, np.linalg.norm(U)):
                break
            if np.linalg.norm(r) <= tol * scale and np.linalg.norm(du) <= tol * max(np.linalg.norm(trial), 1e-30):
                converged = True
                break
        if not converged:
            if cutbacks >= int(loading["max_cutbacks"]):
                history.append({"load_factor": target, "converged": False, "iterations": it,
                                "note": f"no convergence after {cutbacks} cut-backs"})
                raise NotConverged(f"Newton did not converge at load factor {target:.4g} after {cutbacks} "
                                   "cut-backs; use more load steps", history)
            cutbacks += 1
            dfactor *= 0.5
            history.append({"load_factor": target, "converged": False, "iterations": it,
                            "note": f"increment cut back to {dfactor:.4g}"})
            continue
        last_step, last_dfactor = trial - U, target - factor
        U, factor = trial, target
        if it <= int(loading["max_iterations"]) // 2:
            dfactor = min(2.0 * dfactor, 1.0 / steps)
        history.append({"load_factor": factor, "converged": True, "iterations": it, **on_converged(U)})
    return U, history, {"load_increments": sum(h["converged"] for h in history), "newton_iterations": iterations,
                        "cutbacks": cutbacks}
