"""Small-strain Mohr-Coulomb equilibrium on any discretisation (Section 2.1.3), shared by both methods.

Loads are applied in increments (:mod:`ctmrpim.solvers.load_stepping`); within an increment
Newton-Raphson iterates on the strain increment from the last converged state,

    sigma = return_map(sigma_n, B (U - U_n)),   F_int = B^T (w sigma),   K = B^T diag(w D_ep) B,

with D_ep the consistent tangent of the return map (:mod:`ctmrpim.materials.mohr_coulomb`),
non-symmetric for a non-associated flow (psi < phi), so the linear solves use LU factors (SuperLU, or a banded
LU for CTM-RPIM's Newton tangents: :meth:`PlasticSystem._factorise`). The history is
committed only when an increment converges; a cut-back restarts from the committed state.

:class:`PlasticSystem` holds that equilibrium on any discretisation that supplies the gradient
operator G and the point weights: the CTM-RPIM solver (:mod:`ctmrpim.solvers.elastoplastic`) and the
scikit-fem reference use the same one, with the same material class and the same iteration, chosen by
``loading.tangent``:

- ``"consistent"``: Newton on the consistent tangent, rebuilt every iteration as the elastic stiffness
  plus a correction summed over the plastic points only (footing: 84 s -> 54 s for the whole run when it was
  first done so). Reusing a stale plastic tangent (modified Newton) is unsafe: it is nearly singular in directions
  where the current state is elastic, and the compressed Tresca block then diverges in its first increment.
  Where the consistent tangent is exactly singular (apex returns), that iteration's step is the elastic
  stiffness's (:meth:`PlasticSystem._safeguarded`);
- ``"elastic"``: the elastic stiffness, assembled and factorised once for the whole analysis (it does
  not change with the strength reduction), each step Anderson-mixed with the last ones
  (:class:`ctmrpim.solvers.load_stepping.Anderson`). Measured on the 1928-node slope under gravity (16
  increments, tolerance 1e-4): 171 iterations in 8.9 s, against 57 consistent-tangent iterations with 30
  tangents in 25.4 s. Where it gives up near a limit (a strength-reduction level, a limit load), the increment is
  re-checked by Newton on the consistent tangent from its last iterate before the failure counts
  (:func:`ctmrpim.solvers.load_stepping.step_loads`, ``recheck_assemble``).
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, Callable

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla
from threadpoolctl import threadpool_limits

from ctmrpim.errors import ProblemError
from ctmrpim.materials.mohr_coulomb import ELASTIC, MohrCoulomb, plastic_strain_increment
from ctmrpim.materials.mohr_coulomb_kernel import consistent_tangent, small_strain_update
from ctmrpim.problem.settings import Loading
from ctmrpim.solvers.banded_lu import BandedLU
from ctmrpim.solvers.load_stepping import LoadPath, step_loads
from ctmrpim.solvers.weak_form import internal_force, tangent
from ctmrpim.timing import Timer

#: (4 x 3): the first Piola stress layout (xX, xY, yX, yY) from (sxx, syy, sxy) - small strain, P = sigma
TO_P = np.array([[1.0, 0, 0], [0, 0, 1], [0, 0, 1], [0, 1, 0]])
#: (3 x 4): the engineering strain (exx, eyy, gxy) from the displacement gradient (xX, xY, yX, yY)
FROM_GRAD = np.array([[1.0, 0, 0, 0], [0, 0, 0, 1], [0, 1, 1, 0]])


#: SuperLU's diagonal pivot threshold: the tangent is structurally symmetric, and preferring the diagonal
#: pivots of the symmetric ordering factorises it faster than partial pivoting (footing: 54 s -> 47 s for
#: the whole run); 0.1 still swaps a pivot that has become tiny against its column (a plastic tangent
#: can be near-singular).
PIVOT_THRESHOLD = 0.1
#: Anderson mixing depth of the iteration steps (see :class:`ctmrpim.solvers.load_stepping.Anderson`).
ANDERSON = 10


def block_rows(G: sp.bsr_matrix, points: np.ndarray) -> sp.bsr_matrix:
    """The block rows ``points`` of a block-sparse G (one block row of 4 per point), still block-sparse
    (a CSR row slice makes the tangent's products three times slower)."""
    counts = np.diff(G.indptr)[points]
    indptr = np.concatenate([[0], np.cumsum(counts)])
    take = np.repeat(G.indptr[points] - indptr[:-1], counts) + np.arange(indptr[-1])
    rows = G.blocksize[0]
    return sp.bsr_matrix((G.data[take], G.indices[take], indptr), shape=(rows * len(points), G.shape[1]))


@dataclass
class PlasticSystem:
    """Small-strain Mohr-Coulomb equilibrium G^T (w sigma) = F_ext on a fixed discretisation.

    ``G`` (4m x 2n, block-sparse) gives the displacement gradient at the m points from interleaved
    dofs, ``w`` the point weights (thickness included); ``dead`` and ``body`` are the external force
    vectors of the loads and of gravity at full value. The committed state (U, stress at the points)
    is the last converged one."""

    G: sp.bsr_matrix
    w: np.ndarray
    fixed: np.ndarray
    fixed_values: np.ndarray
    dead: Callable[[float], np.ndarray]     # load factor -> F of the tractions and point loads
    body: np.ndarray                        # gravity at full value
    material: MohrCoulomb                   # its E and nu give the elastic stiffness
    U: np.ndarray = field(init=False)
    stress: np.ndarray = field(init=False)
    region: np.ndarray = field(init=False)
    plastic_strain: np.ndarray = field(init=False)   # (m, 4) xx, yy, xy (tensor), zz
    tangent: str = "consistent"             # "consistent" (Newton) or "elastic" (see the module)
    tangents: int = 0                       # tangents built
    factorisations: int = 0                 # LU factorisations (a tangent equal to the last one reuses them)
    safeguarded_steps: int = 0              # iterations whose singular consistent tangent gave way to the elastic one
    clock: Timer = field(default_factory=Timer)   # seconds per phase of the iterations
    test: sp.bsr_matrix | None = None       # ctm-vci: G of the corrected test gradients (Petrov-Galerkin)
    dirichlet: Any = None                   # ctm-vci: its Dirichlet consistency term (RecoveredDirichletTerm)
    products: Any = None                    # compiled products over the points (CTM-RPIM's PointProducts), if any
    nodes: np.ndarray | None = None         # (n, 2) where the dofs 2i, 2i + 1 sit, for the band's ordering, if known

    def __post_init__(self) -> None:
        # G~^T for the sparse products; the compiled ones read G's pattern transposed themselves
        self.GT = None if self.products is not None else (self.G if self.test is None else self.test).T
        self.U = np.zeros(self.G.shape[1])
        self.stress = np.zeros((len(self.w), 4))
        self.region = np.zeros(len(self.w), dtype=np.int8)
        self.plastic_strain = np.zeros((len(self.w), 4))
        self.free = np.setdiff1d(np.arange(self.G.shape[1]), self.fixed)
        self._K: sp.csr_matrix | None = None
        self._K_elastic: sp.csr_matrix | None = None
        self._lu = None
        self._lu_elastic = None             # the elastic stiffness's factors, for the safeguarded steps
        self._band: BandedLU | bool | None = None   # the banded LU of the elastic pattern (False: SuperLU)

    def strain_increment(self, U: np.ndarray) -> np.ndarray:
        """(m, 3) exx, eyy, gxy at the points from the committed dofs to the interleaved dofs U (2n,)."""
        if self.products is not None:
            return self.products.gradient(U - self.U) @ FROM_GRAD.T
        return (self.G @ (U - self.U)).reshape(-1, 4) @ FROM_GRAD.T

    def trial_state(self, material: MohrCoulomb, U: np.ndarray) -> tuple[np.ndarray, ...]:
        """(U, stress, region, plastic strain) at U from the committed state, laid out as a snapshot."""
        de = self.strain_increment(U)
        stress, region = self._return_map(material, de)
        return U.copy(), stress, region, self.plastic_strain + plastic_strain_increment(material, de, stress - self.stress)

    def _return_map(self, material: MohrCoulomb, de: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(stress, region) at the points after the strain increments ``de`` (m, 3) from the committed stress: the
        compiled return where there is no tension cut-off (:func:`~ctmrpim.materials.mohr_coulomb_kernel.
        small_strain_update`, equal to the numpy form to round-off), else the numpy form."""
        if material.tension is None:
            return small_strain_update(material, self.stress, de)
        return material.update(self.stress, de)

    def _material_tangent(self, material: MohrCoulomb, points: np.ndarray, de: np.ndarray) -> np.ndarray:
        """(k, 3, 3) consistent tangent of the return at the ``points`` (k,) by their strain increments ``de``
        (k, 3): compiled where there is no tension cut-off (:func:`~ctmrpim.materials.mohr_coulomb_kernel.
        consistent_tangent`, the same complex steps), else the numpy form."""
        if material.tension is None:
            return consistent_tangent(material, self.stress[points], de)
        return material.tangent(self.stress[points], de)

    def commit(self, material: MohrCoulomb, U: np.ndarray) -> None:
        """Make the trial state at U (2n,) under ``material`` the committed one."""
        self.U, self.stress, self.region, self.plastic_strain = self.trial_state(material, U)

    def external_force(self, load_factor: float) -> np.ndarray:
        """(2n,) F_ext at ``load_factor``: the loads and gravity, both scaled by it."""
        return self.dead(load_factor) + load_factor * self.body

    def elastic_stiffness(self) -> sp.csr_matrix:
        """The elastic stiffness (built on first use; E and nu never change: the strength reduction
        divides c and tan(phi) only)."""
        if self._K_elastic is None:
            D = self.material.D("strain")
            A = np.broadcast_to(TO_P @ D @ FROM_GRAD, (len(self.w), 4, 4))
            # the compiled pass where there is one: its interleaved node pattern is what the plastic corrections add to
            self._K_elastic = (tangent(self.G, A, self.w, self.GT) if self.products is None
                               else self.products.tangent(A))
            if self.consistent:
                self._K_elastic = self._K_elastic - self.dirichlet.stiffness(self.G, np.ascontiguousarray(A))
        return self._K_elastic

    @property
    def consistent(self) -> bool:
        """Whether a Dirichlet consistency term acts (ctm-vci with constrained edges)."""
        return self.dirichlet is not None and self.dirichlet.active

    def _internal(self, stress: np.ndarray) -> np.ndarray:
        """G~^T (w sigma), less the Dirichlet consistency term's force where there is one."""
        P = stress[:, :3] @ TO_P.T
        if self.products is not None:
            f = self.products.force(P)
        else:
            f = internal_force(self.G, P, self.w, self.GT)
        return f - self.dirichlet.force(P) if self.consistent else f

    def internal_force(self) -> np.ndarray:
        """G^T (w sigma) of the committed stress (with the reactions at the fixed dofs)."""
        return self._internal(self.stress)

    def snapshot(self) -> tuple[np.ndarray, ...]:
        """Copies of the committed (U, stress, region, plastic strain), for :meth:`restore`."""
        return self.U.copy(), self.stress.copy(), self.region.copy(), self.plastic_strain.copy()

    def restore(self, state: tuple[np.ndarray, ...]) -> None:
        """Make a :meth:`snapshot` the committed state again."""
        self.U, self.stress, self.region, self.plastic_strain = (a.copy() for a in state)

    def assemble(self, material: MohrCoulomb, U: np.ndarray, load_factor: float, matrix: str | None = None
                 ) -> tuple[np.ndarray, np.ndarray, sp.csr_matrix]:
        """(F_ext (2n,), F_int (2n,), K (2n x 2n)) at the trial U (2n,); K is the elastic stiffness or the
        consistent tangent, as ``matrix`` says (default: the system's ``tangent``)."""
        with self.clock.measure("return mapping"):
            de = self.strain_increment(U)
            stress, region = self._return_map(material, de)
        with self.clock.measure("internal force"):
            f_ext = self.external_force(load_factor)
            f_int = self._internal(stress)
        with self.clock.measure("tangent"):
            self.elastic_stiffness()
            if (matrix or self.tangent) == "elastic":
                if self._K is None:
                    self.tangents += 1
                self._K = self._K_elastic
            else:
                # K = K_elastic + the plastic points' correction: its product runs over those points only
                plastic = np.flatnonzero(region != ELASTIC)
                self._K = self._K_elastic          # its factors are kept while no point is plastic
                if len(plastic):
                    dD = self._material_tangent(material, plastic, de[plastic]) - material.D("strain")[None]
                    self._K = self._plastic_tangent(plastic, dD)
                self.tangents += 1
        return f_ext, f_int, self._K

    def _plastic_tangent(self, plastic: np.ndarray, dD: np.ndarray) -> sp.csr_matrix:
        """K_elastic + the correction of the ``plastic`` points (k,) with D_ep - D = ``dD`` (k, 3, 3): by the compiled
        point-wise pass of the ``products`` where there are (CTM-RPIM's), else by sparse products over the plastic
        points' rows of G; less a Dirichlet consistency term's part, over the points it reaches."""
        dA = TO_P[None] @ dD @ FROM_GRAD[None]
        K = None if self.products is None else self.products.corrected(self._K_elastic, plastic, dD)
        if K is None:
            Gp = block_rows(self.G, plastic)
            GTp = Gp.T if self.test is None else block_rows(self.test, plastic).T
            K = self._K_elastic + tangent(Gp, dA, self.w[plastic], GTp)
        if not self.consistent:
            return K
        near = self.dirichlet.reaches[plastic]       # the plastic points whose stress the term recovers
        return K - self.dirichlet.stiffness(block_rows(self.G, plastic[near]), dA[near], plastic[near])

    def solve(self, K: sp.csr_matrix, residual: np.ndarray) -> np.ndarray:
        """du (2n,) with K du = ``residual`` (2n,) at the free dofs and du = 0 at the fixed ones, reusing the LU
        factors of K (2n x 2n) while K is unchanged.

        The safeguard: a consistent tangent whose LU finds a pivot exactly zero, or whose step is not finite,
        is replaced for this iteration by the elastic stiffness (:meth:`_safeguarded`); only a singular
        elastic stiffness is bad input (constraints that leave a rigid-body motion free)."""
        if K is self._K_elastic:          # factorised once, also between the re-check's Newton tangents
            with self.clock.measure("factorisation"):
                factors = self._elastic_factors()
            with self.clock.measure("substitution"):
                return self._solve_free(factors, residual)
        with self.clock.measure("factorisation"):
            if self._lu is None or self._lu[0] is not K:
                try:
                    self._lu = (K, self._factorise(K))
                except RuntimeError:
                    return self._safeguarded(residual)
                self.factorisations += 1
        with self.clock.measure("substitution"):
            du = self._solve_free(self._lu[1], residual)
        if not np.all(np.isfinite(du)):
            return self._safeguarded(residual)
        return du

    def _factorise(self, K: sp.csr_matrix, banded: bool = True):
        """LU factors of K (2n x 2n) at the free dofs; RuntimeError where a pivot is exactly zero.

        A row or column without a non-zero entry (dofs whose every point returned to the apex: D_ep = 0) is
        refused here, before SuperLU sees it: SuperLU's pivoting reads an uninitialised index on such a
        column and crashes the interpreter now and then (scipy 1.11, segmentation fault in ``splu``) instead
        of reporting the singular factor. Measured on the coarse phi = 20 deg footing by FE P2: every one of
        the 49 tangents SuperLU found exactly singular had such rows or columns, none of the 142 regular ones.

        Where the elastic stiffness's band is narrow against its rows (meshfree supports), a Newton tangent on
        its pattern is factorised by the banded LU instead (:mod:`ctmrpim.solvers.banded_lu`), whose zero pivot on
        such a row is its RuntimeError. Not a non-symmetric elastic stiffness (``banded`` False): its factors serve
        every iteration of the elastic-stiffness iteration, and the LU band's substitution is about twice SuperLU's
        work (8.4 against 4.5 MFlop on the 1928-node slope); a symmetric one takes the band's Cholesky
        (:meth:`_elastic_factors`)."""
        if banded and self._banded() and self._band.fits(K):
            return self._band.factorise(K)
        Kff = K[self.free][:, self.free].tocsc()
        magnitude = abs(Kff)
        if magnitude.max(axis=0).nnz < Kff.shape[1] or magnitude.max(axis=1).nnz < Kff.shape[0]:
            raise RuntimeError("Factor is exactly singular: a row or column of the tangent is zero")
        return spla.splu(Kff, permc_spec="MMD_AT_PLUS_A", diag_pivot_thresh=PIVOT_THRESHOLD,
                         options={"SymmetricMode": True})

    @staticmethod
    def _unconstrained(exc: Exception) -> ProblemError:
        return ProblemError(f"the elastic stiffness is singular ({exc}): the constraints do not stop every "
                            "rigid-body motion, or part of the body is detached", key="constraint")

    def _safeguarded(self, residual: np.ndarray) -> np.ndarray:
        """du (2n,) from the elastic stiffness, for an iteration whose consistent tangent is singular.

        The consistent tangent of perfect plasticity loses rank where points return to the apex (D_ep = 0
        there: every strain increment leaves sigma = c cot(phi)) or where a whole element's points sit on
        one yield plane with its flow unresisted (a mechanism the element can follow freely); a finite
        element whose quadrature points all do so leaves its dofs without stiffness. Those states occur in
        Newton's trial iterates past a limit point long before the increment is judged, so the step of
        that iteration is taken with the elastic stiffness (regular once constrained, factorised once): the
        step the elastic-stiffness iteration (``tangent = "elastic"``) takes, slower to converge but never
        singular. The next iteration tries the consistent tangent again, and the increment converges, or is cut
        back as any other, by the load stepping's criteria. Counted in ``safeguarded_steps``."""
        self.safeguarded_steps += 1
        return self._solve_free(self._elastic_factors(), residual)

    def _solve_free(self, factors: Any, rhs: np.ndarray) -> np.ndarray:
        """(2n,) the solution of the free dofs' system whose ``factors`` are given, for ``rhs`` (2n,); zero at the
        fixed dofs."""
        x = np.zeros_like(rhs)
        x[self.free] = factors.solve(rhs[self.free])
        return x

    def _elastic_factors(self):
        """The factors of the constrained elastic stiffness, computed once (a singular one is a model error): the
        banded Cholesky where the weak form is symmetric (Bubnov-Galerkin, no consistency term) and the band is
        narrow (:meth:`~ctmrpim.solvers.banded_lu.BandedLU.cholesky`: its substitution, which every iteration of the
        elastic-stiffness iteration does, is half SuperLU's), else SuperLU's LU."""
        if self._lu_elastic is None:
            K = self.elastic_stiffness()
            band = self._banded()
            if band and self.test is None and not self.consistent:
                try:
                    self._lu_elastic = band.cholesky(K)
                except RuntimeError as exc:
                    raise self._unconstrained(exc) from None
            else:
                try:
                    self._lu_elastic = self._factorise(K, banded=False)
                except RuntimeError as exc:
                    raise self._unconstrained(exc) from None
            self.factorisations += 1
        return self._lu_elastic

    def _banded(self) -> BandedLU | bool:
        """The band of the elastic stiffness's pattern, laid out on first use, or False where it is not narrow
        against the rows (:attr:`~ctmrpim.solvers.banded_lu.BandedLU.worthwhile`)."""
        if self._band is None:
            band = BandedLU(self.elastic_stiffness(), self.free, self.nodes)
            self._band = band if band.worthwhile else False
        return self._band

    def iteration_counts(self) -> dict[str, Any]:
        """Tangents built, factorisations and the seconds spent in each phase of the iterations."""
        return {"tangents": self.tangents, "factorisations": self.factorisations,
                "safeguarded_steps": self.safeguarded_steps,
                "iteration_seconds": {k: round(v, 3) for k, v in self.clock.phases.items()}}

    def run(self, loading: Loading, material_at: Callable[[float], MohrCoulomb],
            load_at: Callable[[float], float], on_converged: Callable[[float, np.ndarray], dict[str, Any]],
            fixed_values: np.ndarray | None = None, stop_on_failure: bool = False,
            judge: Callable[[float, np.ndarray, float, np.ndarray], tuple[str | None, dict]] | None = None,
            recheck: bool = False, stop: Callable[[float, np.ndarray], str | None] | None = None,
            resolution: float = 0.0) -> LoadPath:
        """Step a path parameter t from 0 to 1 from the committed state: the material is
        ``material_at(t)`` and the loads are at ``load_at(t)`` times their full value (a load ramp,
        or a strength-reduction stage at constant load); ``judge``, ``recheck``, ``stop`` and ``resolution`` as in
        :func:`~ctmrpim.solvers.load_stepping.step_loads`."""
        if self.tangent != "elastic":
            self._K = None

        def assemble(U: np.ndarray, t: float):
            return self.assemble(material_at(t), U, load_at(t))

        def assemble_consistent(U: np.ndarray, t: float):
            return self.assemble(material_at(t), U, load_at(t), "consistent")

        def converged(t: float, U: np.ndarray) -> dict[str, Any]:
            self.commit(material_at(t), U)
            return on_converged(t, U)

        # one BLAS thread: the iteration's dense work is small (Anderson's least squares on 10 columns, banded
        # solves), and OpenBLAS's threads spin-wait for a busy core (measured under load: the least squares of
        # the 1928-node slope 9-28 ms on two threads, 1.1 ms on one, 40 % of the search's time)
        with threadpool_limits(1):
            return step_loads(len(self.U), loading, self.fixed,
                              self.fixed_values if fixed_values is None else fixed_values, assemble, self.solve,
                              converged, U0=self.U, stop_on_failure=stop_on_failure, anderson=ANDERSON,
                              judge=judge, recheck=recheck, snapshot=self.snapshot, restore=self.restore,
                              recheck_assemble=assemble_consistent if self.tangent == "elastic" else None,
                              stop=stop, resolution=resolution)

    def elastic_response(self, F: np.ndarray) -> np.ndarray:
        """U (2n,) of the elastic stiffness under the forces F (2n,), zero at the fixed dofs."""
        return self._solve_free(self._elastic_factors(), F)
