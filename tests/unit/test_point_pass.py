"""The explicit step's compiled point pass (ctmrpim.solvers.explicit.point_pass): the internal force it scatters on
its way is, to the bit, the force the step computes on its own from the state the pass leaves (so a run that
takes it repeats a resumed run, which starts with the step's own), also where the step inverts points."""
from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from ctmrpim import benchmarks
from ctmrpim.materials.objective_stress_kernels import weighted_first_piola
from ctmrpim.solvers.explicit.point_pass import point_pass
from ctmrpim.solvers.explicit.run import ExplicitRun
from ctmrpim.solvers.explicit.state import input_key


@pytest.mark.parametrize("amplitude", [1e-4, 0.5])        # a small move; one that inverts points
def test_the_pass_scatters_the_force_of_the_state_it_leaves(tmp_path: Path, amplitude: float) -> None:
    case = benchmarks.load("column-collapse", ["nodes.grid=[26, 11]", "explicit.duration=1e-9"])
    run = ExplicitRun(case, tmp_path, input_key(case))
    run.start()
    run.run(progress=False)                     # the gravity stage: a stress that yields in places
    fr = run.frame
    assert len(fr.compiled_gradient().scatter_blocks) > 1        # blocks on threads, their sums added
    rng = np.random.default_rng(7)
    d = amplitude * run.d_c * rng.standard_normal(run.x.shape)
    viscous = 1e3 * rng.standard_normal(run.stress.shape)
    upd = point_pass(fr, run.x - fr.x + d, run.F, run.stress, run.plastic, viscous, run.material, 2.0, True,
                     force=True)
    assert (amplitude > 0.1) == bool(upd.inverted.any())
    w = fr.w.copy()
    w[upd.inverted] = 0.0                      # as the step drops them
    wP = np.empty((len(w), 4))
    weighted_first_piola(upd.stress, upd.viscous, True, upd.F, w, wP)
    assert np.array_equal(upd.force, fr.weighted_force(wP))
    ref = fr.compiled_gradient().force(wP)     # and it is the force (the gather's sums, other round-off)
    assert np.allclose(upd.force, ref, rtol=0, atol=1e-12 * np.abs(ref).max())
