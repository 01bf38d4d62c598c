"""Explicit dynamic adaptive CTM-RPIM (issue 7): the step's kinematics, walls, lumped mass, time step,
free fall, energy, the gravity stage, checkpoint and resume, divergence messages, bad input."""
from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import meshio
import numpy as np
import pytest

from ctmrpim import benchmarks
from ctmrpim.discretisation.lumped_mass import lumped_mass
from ctmrpim.errors import ProblemError
from ctmrpim.materials.mohr_coulomb import APEX, ELASTIC, LEFT, MAIN, RIGHT, MohrCoulomb, plastic_strain_increment
from ctmrpim.materials.mohr_coulomb_kernel import point_update
from ctmrpim.materials.objective_stress import (
    det2,
    det_c,
    first_piola_c,
    hughes_winget,
    hughes_winget_c,
    inv2,
    largest_strain,
    largest_strain_c,
    relative_c,
    rotate_c,
)
from ctmrpim.problem.model import Wall
from ctmrpim.solvers.explicit.contact import enforce_walls
from ctmrpim.solvers.explicit.run import ExplicitRun, solve_explicit
from ctmrpim.solvers.explicit.state import input_key

QUICK = ["nodes.grid=[16, 9]", "method.alpha=2.0"]


def _matrices(F4: np.ndarray) -> np.ndarray:
    return F4.reshape(-1, 2, 2)


@pytest.fixture
def gradients():
    rng = np.random.default_rng(3)
    return np.tile([1.0, 0.0, 0.0, 1.0], (50, 1)) + 0.2 * rng.standard_normal((50, 4))


def test_component_forms_match_the_matrix_forms(gradients):
    """The explicit step's component algebra is the matrix algebra of objective_stress, to round-off."""
    rng = np.random.default_rng(4)
    F, G = gradients, gradients[::-1].copy()
    Fm, Gm = _matrices(F), _matrices(G)
    stress = rng.standard_normal((50, 4))
    sig = np.zeros((50, 2, 2))
    sig[:, 0, 0], sig[:, 1, 1], sig[:, 0, 1], sig[:, 1, 0] = stress[:, 0], stress[:, 1], stress[:, 2], stress[:, 2]
    assert np.allclose(det_c(F), det2(Fm))
    P = det2(Fm)[:, None, None] * sig @ inv2(Fm).transpose(0, 2, 1)
    assert np.allclose(first_piola_c(stress, F), P.reshape(-1, 4), atol=1e-13)
    assert np.allclose(relative_c(G, F), (Gm @ inv2(Fm)).reshape(-1, 4), atol=1e-13)
    de, Q = hughes_winget(Fm)
    strain, c, s = hughes_winget_c(F)
    assert np.allclose(strain, np.c_[de[:, 0, 0], de[:, 1, 1], 2 * de[:, 0, 1]], atol=1e-13)
    assert np.allclose(np.stack([c, -s, s, c], axis=1), Q.reshape(-1, 4), atol=1e-13)
    rotated = Q @ sig @ Q.transpose(0, 2, 1)
    r = rotate_c(stress, c, s)
    assert np.allclose(r[:, :3], np.c_[rotated[:, 0, 0], rotated[:, 1, 1], rotated[:, 0, 1]], atol=1e-13)
    assert np.array_equal(r[:, 3], stress[:, 3])
    assert largest_strain_c(F) == pytest.approx(largest_strain(Fm), rel=1e-12)


@pytest.mark.parametrize("c, psi", [(0.0, 0.0), (2.0e3, 10.0)])
def test_compiled_point_update_matches_the_numpy_forms(c, psi):
    """The compiled per-point step is the numpy algebra (Hughes-Winget, rotation, Box 8.4 return, plastic
    strain increment, dissipation) point for point, in every return region, to round-off."""
    material = MohrCoulomb(E=0.84e6, nu=0.3, c=c, phi=19.8, psi=psi, density=2650.0)
    rng = np.random.default_rng(5)
    m = 4000
    p = rng.uniform(-500.0, 4000.0, m)          # some tensile: the apex is reached where c = 0
    stress = np.c_[-p * rng.uniform(0.3, 1.2, m), -p, p * rng.uniform(-0.4, 0.4, m), -p * rng.uniform(0.5, 1.0, m)]
    stress, _ = material.update(stress, np.zeros((m, 3)))          # admissible starting states
    plastic = 1e-3 * rng.standard_normal((m, 4))
    f = np.tile([1.0, 0.0, 0.0, 1.0], (m, 1)) + 10.0 ** rng.uniform(-5, -2, (m, 1)) * rng.standard_normal((m, 4))
    dead = rng.random(m) < 0.02
    w = rng.uniform(0.5, 1.5, m)
    got, got_plastic, region, dissipation, viscous, work = point_update(material, f, stress, plastic, dead, w,
                                                                        np.ones((m, 4)), 2.0)
    assert {ELASTIC, MAIN, RIGHT, LEFT} <= set(region[~dead]) and (c > 0 or APEX in set(region))
    strain, cq, sq = hughes_winget_c(f)
    rotated, rotated_plastic = rotate_c(stress, cq, sq), rotate_c(plastic, cq, sq)
    want, want_region = material.update(rotated, strain)
    dp = plastic_strain_increment(material, strain, want - rotated)
    want[dead], dp[dead], rotated_plastic[dead] = 0.0, 0.0, 0.0
    scale = np.abs(stress).max()
    assert np.abs(got - want).max() < 1e-10 * scale
    assert np.array_equal(region[~dead], want_region[~dead])
    assert np.abs(got_plastic - (rotated_plastic + dp)).max() < 1e-13
    density = 0.5 * ((rotated + want) * dp * [1.0, 1.0, 2.0, 1.0]).sum(axis=1)
    assert dissipation == pytest.approx(w @ density, rel=1e-10, abs=1e-12 * scale)
    D = material.D("strain")          # viscous stress beta D de / dt (beta / dt = 2 here), zz from plane strain
    want_viscous = 2.0 * np.c_[strain @ D.T, D[0, 1] * (strain[:, 0] + strain[:, 1])][:, [0, 1, 2, 3]]
    want_viscous[dead] = 0.0
    assert np.abs(viscous - want_viscous).max() < 1e-12 * np.abs(want_viscous).max()
    assert work == pytest.approx(w[~dead] @ strain[~dead].sum(axis=1), rel=1e-12)   # unit old viscous stress


def test_hughes_winget_of_a_rigid_rotation_is_that_rotation():
    theta = 0.3
    f = np.array([[np.cos(theta), -np.sin(theta), np.sin(theta), np.cos(theta)]])
    strain, c, s = hughes_winget_c(f)
    assert np.abs(strain).max() < 1e-15
    assert (c[0], s[0]) == pytest.approx((np.cos(theta), np.sin(theta)), abs=1e-15)


def test_walls_no_slip_frictionless_coulomb_and_release():
    base = Wall("base", (0, 0), (0, 2))                       # normal normalised on construction
    assert base.normal == (0.0, 1.0)
    x = np.array([[0.0, 0.0], [0.0, 0.0], [0.0, 1e-3], [0.0, 0.0]])
    v = np.array([[1.0, -2.0], [1.0, -2.0], [1.0, -2.0], [1.0, 3.0]])
    dt = 1e-3
    no_slip = enforce_walls([base], x, v, dt)
    assert np.array_equal(no_slip[0], [0.0, 0.0])            # on the base, pressed: stopped
    assert no_slip[2] == pytest.approx([0.0, -1.0])          # lands exactly on the base this step, no slip
    assert np.array_equal(no_slip[3], v[3])                  # moving away: free
    smooth = enforce_walls([Wall("b", (0, 0), (0, 1), friction=0.0)], x, v, dt)
    assert smooth[0] == pytest.approx([1.0, 0.0])            # tangential velocity kept
    rough = enforce_walls([Wall("b", (0, 0), (0, 1), friction=0.3)], x, v, dt)
    assert rough[0] == pytest.approx([1.0 - 0.3 * 2.0, 0.0])  # Coulomb: |dv_t| = mu |dv_n|
    sticky = enforce_walls([Wall("b", (0, 0), (0, 1), friction=0.6)], x, v, dt)
    assert sticky[0] == pytest.approx([0.0, 0.0])            # mu |dv_n| >= |v_t|: stick
    with pytest.raises(ProblemError):
        Wall("w", (0, 0), (0, 0))
    with pytest.raises(ProblemError):
        Wall("w", (0, 0), (0, 1), friction=-0.1)


def test_lumped_mass_is_positive_and_sums_to_the_body_mass():
    case = benchmarks.load("column-collapse", QUICK)
    run = ExplicitRun(case, Path("unused"), "key")
    assert (run.mass > 0).all()
    assert run.mass.sum() == pytest.approx(2650.0 * 0.2 * 0.1, rel=1e-12)   # the grid's alpha shape is the rectangle
    with pytest.raises(ProblemError, match="density"):
        lumped_mass(run.X, np.array([[0, 1, 2]]), 0.0, 1.0)


def test_critical_time_step_bounds_the_wave_speed_step():
    """The power-iteration step is stable and of the order of d / c_p (RPIM is stiffer than linear FEM)."""
    case = benchmarks.load("column-collapse", QUICK)
    run = ExplicitRun(case, Path("unused"), "key")
    run.start()
    assert 0.2 * run.dt_wave < run.dt < 2.0 * run.dt_wave
    import scipy.sparse as sp
    from scipy.sparse.linalg import eigsh
    n = len(run.X)
    K = np.column_stack([run._stiffness(run.frame)(e.reshape(n, 2)).ravel() for e in np.eye(2 * n)])
    m = np.repeat(run.mass, 2)
    lam = eigsh(sp.csr_matrix(K / np.sqrt(m)[:, None] / np.sqrt(m)[None, :]), k=1, which="LA",
                return_eigenvectors=False)[0]
    assert run.omega == pytest.approx(np.sqrt(lam), rel=0.05)     # the estimate is close to omega_max
    assert run.omega <= np.sqrt(lam) * (1 + 1e-9)                 # and from below (a Rayleigh quotient)


def test_free_fall_follows_central_differences_and_stays_stress_free(tmp_path):
    """No walls, no supports, no gravity stage: every node falls as the discrete scheme says
    (x_n = x_0 - g dt^2 n (n + 1) / 2), no stress appears, and kinetic energy = work of gravity."""
    case = benchmarks.load("column-collapse", QUICK + ["explicit.initial=\"none\"", "explicit.duration=0.01",
                                                       "explicit.dt=1e-4", "explicit.save_every=1.0"])
    case.problem.walls = []
    run = ExplicitRun(case, tmp_path, "key")
    run.start()
    run.run(progress=False)
    n = run.step
    assert n == 100
    drop = 9.81 * 1e-4 ** 2 * n * (n + 1) / 2
    assert np.allclose(run.x - run.X, [0.0, -drop], atol=1e-15)
    assert np.abs(run.stress).max() < 1e-9 * 2650 * 9.81 * 0.1    # round-off of the partition of unity
    assert run.rebuilds == 0
    assert run.kinetic_energy() == pytest.approx(run.energy.gravity, rel=1e-12)


def test_elastic_vibration_conserves_energy(tmp_path):
    """A strong (elastic) column released from its weight on a frictionless base, no damping: gravity
    work = kinetic + elastic energy change to the scheme's accuracy, and nothing is dissipated."""
    case = benchmarks.load("column-collapse", QUICK + ["material.c=1e9", "explicit.initial=\"none\"",
                                                       "explicit.duration=0.03", "explicit.save_every=1.0"])
    case.problem.walls = [Wall("base", (0, 0), (0, 1), friction=0.0), Wall("left", (0, 0), (1, 0), friction=0.0)]
    run = ExplicitRun(case, tmp_path, "key")
    run.start()
    run.run(progress=False)
    e = run.energy
    stored = run.kinetic_energy() + run.elastic_energy() - e.elastic0
    assert abs(e.gravity - stored) < 0.01 * e.gravity
    # the bookkeeping identity of central differences holds to round-off, whatever the time steps were
    assert e.gravity + e.walls - e.internal == pytest.approx(run.kinetic_energy(), rel=1e-10)
    assert e.plastic == pytest.approx(0.0, abs=1e-12)
    assert abs(e.walls) < 1e-3 * e.gravity


def test_viscosity_dissipates_what_the_vibration_loses(tmp_path):
    """The same elastic column with stiffness-proportional damping (beta = 2e-4 s): the viscous stress
    dissipates a good part of the work of gravity, booked as such, and gravity work = kinetic + elastic change + viscous dissipation
    (the material accounts close on the internal work); the stable step shrinks by sqrt(1 + z^2) - z."""
    beta = 2e-4
    overrides = QUICK + ["material.c=1e9", "explicit.initial=\"none\"", "explicit.duration=0.03",
                         "explicit.save_every=1.0"]
    runs = {}
    for viscosity in (0.0, beta):
        case = benchmarks.load("column-collapse", overrides + [f"explicit.viscosity={viscosity}"])
        case.problem.walls = [Wall("base", (0, 0), (0, 1), friction=0.0), Wall("left", (0, 0), (1, 0), friction=0.0)]
        run = runs[viscosity] = ExplicitRun(case, tmp_path / str(viscosity), "key")
        run.start()
        run.run(progress=False)
    plain, damped = runs[0.0], runs[beta]
    zeta = 0.5 * beta * damped.omega
    assert damped.dt == pytest.approx(plain.dt * (np.sqrt(1 + zeta ** 2) - zeta), rel=1e-12)
    e = damped.energy
    assert e.viscous > 0.05 * e.gravity and plain.energy.viscous == 0.0
    stored = damped.kinetic_energy() + damped.elastic_energy() - e.elastic0
    assert abs(e.gravity - stored - e.viscous) < 0.01 * e.gravity
    assert abs(e.internal - (damped.elastic_energy() - e.elastic0 + e.plastic + e.viscous)) < 0.01 * e.gravity


def test_gravity_stage_reaches_the_geostatic_vertical_stress(tmp_path):
    """Behind the gate, at rest: the vertical stress follows rho g (H - y) and nothing moves much (the
    paper's model: no viscosity)."""
    case = benchmarks.load("column-collapse", ["nodes.grid=[31, 16]", "explicit.duration=1e-9", "explicit.viscosity=0"])
    run = ExplicitRun(case, tmp_path, "key")
    run.start()
    run.run(progress=False)
    p = run.frame.moved_points(run.x)
    inner = (p[:, 0] > 0.03) & (p[:, 0] < 0.17) & (p[:, 1] > 0.02) & (p[:, 1] < 0.08)
    expected = -2650.0 * 9.81 * (0.1 - p[inner, 1])
    assert np.abs(run.stress[inner, 1] - expected).max() < 0.05 * 2650 * 9.81 * 0.1
    assert run.stage_residual < case.explicit.stage_tolerance
    assert np.abs(run.x - run.X).max() < 1e-3


def _positions(folder: Path) -> np.ndarray:
    m = meshio.read(folder / "result.vtu")
    return m.points[:, :2] + m.point_data["u"][:, :2]


RESUME = ["nodes.grid=[16, 9]", "explicit.duration=0.06", "explicit.checkpoint_every=40",
          "explicit.save_every=0.02"]


def _cli(*args: str) -> list[str]:
    return [sys.executable, "-m", "ctmrpim.cli", *args]


def test_killed_run_resumes_to_the_same_state(tmp_path):
    """SIGKILL after the first checkpoints, then --resume: the same final state as a run left alone."""
    sets = [a for s in RESUME for a in ("--set", s)]
    whole, killed = tmp_path / "whole", tmp_path / "killed"
    subprocess.run(_cli("run", "column-collapse", *sets, "--out", str(whole), "--quiet"), check=True)
    proc = subprocess.Popen(_cli("run", "column-collapse", *sets, "--out", str(killed), "--quiet"))
    checkpoint = killed / "checkpoint.npz"
    deadline = time.time() + 120
    while time.time() < deadline and proc.poll() is None:
        if checkpoint.is_file() and json.loads(str(np.load(checkpoint)["meta"]))["step"] >= 80:
            break
        time.sleep(0.01)
    assert proc.poll() is None, "the run ended before it could be killed: lengthen RESUME"
    os.kill(proc.pid, signal.SIGKILL)
    proc.wait()
    assert not (killed / "summary.json").exists()
    subprocess.run(_cli("run", "column-collapse", *sets, "--out", str(killed), "--resume", "--quiet"), check=True)
    diff = np.abs(_positions(whole) - _positions(killed)).max()
    assert diff <= 1e-8 * 0.2
    a, b = (json.loads((f / "summary.json").read_text())["dynamics"] for f in (whole, killed))
    assert a["steps"] == b["steps"] and a["rebuilds"] == b["rebuilds"]
    pvd = (killed / "result.pvd").read_text()
    assert pvd.count("<DataSet") == len(list((killed / "series").glob("*.vtu")))


def test_resume_needs_the_same_problem(tmp_path):
    case = benchmarks.load("column-collapse", RESUME)
    with pytest.raises(ProblemError, match="no checkpoint"):
        solve_explicit(case, tmp_path, resume=True)
    other = benchmarks.load("column-collapse", RESUME + ["material.phi=25"])
    assert input_key(case) != input_key(other)


def test_divergence_names_what_where_and_when(tmp_path):
    """A time step far above the stable one: the run stops with the step, time and place, exit 2, no
    summary, and the checkpoint it had stays."""
    out = tmp_path / "bad"
    r = subprocess.run(_cli("run", "column-collapse", "--set", "nodes.grid=[16, 9]", "--set", "explicit.dt=5e-3",
                            "--set", "explicit.initial=\"none\"", "--out", str(out), "--quiet"),
                       capture_output=True, text=True)
    assert r.returncode == 2
    assert "Traceback" not in r.stderr
    assert "step" in r.stderr and "t = " in r.stderr
    assert not (out / "summary.json").exists()


@pytest.mark.parametrize("setting, key", [
    ("explicit.dt=-1", "explicit.dt"), ("explicit.cfl=2", "explicit.cfl"), ("explicit.damping=1", "explicit.damping"),
    ("explicit.rebuild_strain=0", "explicit.rebuild_strain"), ("explicit.detached=\"drop\"", "explicit.detached"),
    ("explicit.initial=\"k0\"", "explicit.initial"), ("explicit.checkpoint_every=1.5", "explicit.checkpoint_every"),
])
def test_bad_explicit_settings(setting, key):
    with pytest.raises(ProblemError) as err:
        benchmarks.load("column-collapse", [setting])
    assert key in err.value.message


def test_walls_need_explicit_dynamics(tmp_path):
    text = benchmarks.path("column-collapse").read_text().replace('analysis = "explicit"', 'analysis = "linear"')
    text = text.replace('model = "mohr-coulomb"', 'model = "linear-elastic"')
    f = tmp_path / "p.toml"
    f.write_text(text)
    from ctmrpim.problem.reader import read_case
    with pytest.raises(ProblemError, match="explicit"):
        read_case(f)


def test_deposit_measures_of_known_shapes():
    from ctmrpim.reference.deposit import curve_distance, failure_line, run_out, slope_angle, surface_profile
    # a trapezoid deposit: 0.1 high at the wall, falling linearly to 0 at x = 0.4
    pts = np.array([[0.0, 0.0], [0.4, 0.0], [0.0, 0.1]])
    edges = np.array([[0, 1], [1, 2], [2, 0]])
    xs = np.linspace(0.0, 0.5, 501)
    h = surface_profile(pts, edges, xs)
    assert np.allclose(h, np.clip(0.1 * (1 - xs / 0.4), 0, None), atol=1e-12)
    assert run_out(xs, h, 0.01) == pytest.approx(0.36, abs=1e-9)
    assert slope_angle(xs, h, 0.04, 0.36) == pytest.approx(np.degrees(np.arctan(0.25)), abs=1e-9)
    nodes = np.array([[0.0, 0.0], [0.0, 0.05], [0.1, 0.0], [0.1, 0.05], [0.1, 0.09]])
    u = np.array([[0, 0], [0, 0], [0, 0], [0, 0], [0.02, 0.0]])
    assert np.allclose(failure_line(nodes, u, 0.005, np.array([0.0, 0.1, 0.3]), 0.01), [[0.0, 0.05], [0.1, 0.05]])
    assert np.allclose(curve_distance(np.array([[0.5, 1.0], [2.0, 0.0]]), np.array([[0.0, 0.0], [1.0, 0.0]])),
                       [1.0, 1.0])


def test_series_writer_round_trip(tmp_path):
    from ctmrpim.io.vtu import SeriesWriter, read_pvd
    writer = SeriesWriter(tmp_path)
    pts = np.array([[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]])
    for t in (0.0, 0.5):
        writer.add(t, pts + t, [("line", np.array([[0, 1], [1, 2], [2, 0]]))], {"u": np.full((3, 3), t)})
    resumed = SeriesWriter(tmp_path, writer.entries)
    resumed.add(1.0, pts, [], {"u": np.zeros((3, 3))})
    entries = read_pvd(tmp_path / "result.pvd")
    assert [t for t, _ in entries] == [0.0, 0.5, 1.0]
    m = meshio.read(entries[1][1])
    assert np.allclose(m.points[:, :2], pts + 0.5) and np.allclose(m.point_data["u"], 0.5)


def test_supports_widen_to_min_nodes_and_singular_points_are_dropped():
    from ctmrpim.discretisation.rpim import shape_functions
    rng = np.random.default_rng(0)
    nodes = rng.random((60, 2))
    far = np.array([[3.0, 3.0]])                   # no node within the radius
    with pytest.raises(ProblemError):
        shape_functions(nodes, far, support_radius=0.3, eta=5.0, polynomial_terms=3, scale=0.1)
    sf = shape_functions(nodes, far, support_radius=0.3, eta=5.0, polynomial_terms=3, scale=0.1, min_nodes=12)
    assert sf.support_sizes[0] == 12
    assert sf.N.sum() == pytest.approx(1.0, abs=1e-6)
    # a point whose support nodes are collinear: dropped (empty row) instead of an error
    line = np.c_[np.linspace(0, 1, 8), np.zeros(8)]
    sf = shape_functions(line, np.array([[0.5, 0.01]]), support_radius=2.0, eta=5.0, polynomial_terms=3,
                         scale=0.1, drop_singular=True)
    assert list(sf.dropped) == [0] and sf.N.nnz == 0


def test_a_node_thrown_off_the_body_is_free_or_stops_the_run(tmp_path):
    case = benchmarks.load("column-collapse", QUICK + ["explicit.detached=\"free\""])
    run = ExplicitRun(case, tmp_path, "key")
    run.dropped_points = 0
    x = run.X.copy()
    x[-1] = [0.5, 0.5]                               # far above and beside the column
    frame = run.lay_frame(x, np.zeros(len(x), bool))
    assert len(x) - 1 not in frame.active and frame.free[-1] and frame.free.sum() == 1
    assert frame.N[:, -1].nnz == 0                  # out of every support: a free particle
    strict = ExplicitRun(benchmarks.load("column-collapse", QUICK + ["explicit.detached=\"stop\""]), tmp_path, "key")
    with pytest.raises(ProblemError, match="left the body"):
        strict.lay_frame(x, np.zeros(len(x), bool))


def test_a_failed_re_tracking_falls_back_to_the_carried_points(tmp_path):
    """Where the alpha shape cannot be traced (a pinch it cannot split), the run goes on with the points
    it carried and tries again at the next rebuild; the failures are counted."""
    case = benchmarks.load("column-collapse", QUICK + ["explicit.initial=\"none\"", "explicit.duration=0.03",
                                                       "explicit.rebuild_strain=0.01", "explicit.relay_strain=0.01",
                                                       "explicit.save_every=1.0"])
    run = ExplicitRun(case, tmp_path, "key")
    run.start()

    def untraceable(x, free):
        raise ProblemError("alpha shape: loop is not simple at node(s) [1]")

    run.lay_frame = untraceable
    run.run(progress=False)
    assert run.rebuilds > 0 and run.relay_failures == run.rebuilds and run.transfers == 0
    assert "not simple" in run.relay_failure
    assert np.isfinite(run.x).all()
