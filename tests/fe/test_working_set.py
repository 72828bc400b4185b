"""The gaps of an active-set iterate from projected columns equal G applied to the displacement."""

from types import SimpleNamespace

import numpy as np
import pytest
import scipy.sparse as sp

from hdwf.fe.working_set import ProjectedColumns, WorkingSet

NWATCH, NROWS = 60, 25


class _Structure:
    """A stand-in with a dense SPD compliance: K^-1 G^T and its twist q^T K^-1 G^T."""

    def __init__(self, rng):
        A = rng.standard_normal((NWATCH, NWATCH))
        self.compliance = A @ A.T + NWATCH * np.eye(NWATCH)
        self.twist = rng.standard_normal(NWATCH)

    def compliance_columns(self, G):
        X = self.compliance @ G.toarray().T
        return X, self.twist @ X


def _rows(rng, nnz_per_row=3):
    """Sparse rows like contact rows: a handful of watch entries each."""
    r = np.repeat(np.arange(NROWS), nnz_per_row)
    c = rng.integers(0, NWATCH, r.size)
    return sp.csr_matrix((rng.standard_normal(r.size), (r, c)), shape=(NROWS, NWATCH))


def test_projected_columns_give_the_gaps_of_the_displacement_as_the_set_grows_and_is_refreshed():
    """Linearity: G (sum_k p_k x_k) = sum_k p_k (G x_k), whichever columns were projected when.
    Checked after the first pairs, after more enter (only the new columns are projected), and
    after a refresh renews some columns (a stale projection would keep the old numbers)."""
    rng = np.random.default_rng(7)
    structure = _Structure(rng)
    G = _rows(rng)
    rows = {"tooth": SimpleNamespace(G=G)}
    ws = WorkingSet(NWATCH)
    projected = ProjectedColumns(G)

    def check(positions):
        weights = rng.standard_normal(positions.size)
        direct = G @ ws.store.combine(positions, weights)
        np.testing.assert_allclose(projected.combine(ws, positions, weights), direct,
                                   rtol=1e-12, atol=1e-12 * np.abs(direct).max())

    ws.add(structure, rows, [("tooth", i) for i in range(6)])
    check(np.array([0, 2, 5]))
    ws.add(structure, rows, [("tooth", i) for i in range(6, 15)])
    check(np.array([1, 7, 9, 14]))
    assert projected.store.size == 15

    moved = rows["tooth"].G.tolil()
    moved[3, :] = 0.0
    moved[3, 11] = 2.5                      # pair 3 re-linearised on another node
    rows["tooth"] = SimpleNamespace(G=moved.tocsr())
    generation = ws.generation
    assert ws.refresh(structure, rows, "tooth") is not None
    assert ws.generation == generation + 1
    check(np.array([3, 4, 12]))


def test_compliance_among_the_pairs_is_exactly_symmetric_as_it_grows_and_is_refreshed():
    """The solver cuts its active blocks from ``WorkingSet.compliance`` without symmetrising
    them, for a Cholesky factor: the columns are made slightly unsymmetric (1e-9 of C, as
    back-substituted columns are to round-off) and the kept matrix must still be symmetric to
    the last bit, and G C G^T of the symmetric C to the size of that perturbation."""
    rng = np.random.default_rng(11)
    structure = _Structure(rng)
    skew = rng.standard_normal((NWATCH, NWATCH))
    C_sym = structure.compliance
    C_unsym = C_sym + 1e-9 * np.abs(C_sym).max() * (skew - skew.T)
    structure.compliance_columns = lambda Gr: (C_unsym @ Gr.toarray().T,
                                               structure.twist @ C_unsym @ Gr.toarray().T)
    G = _rows(rng)
    rows = {"tooth": SimpleNamespace(G=G)}
    ws = WorkingSet(NWATCH)

    def check():
        Gw = ws.normal_rows.toarray()
        reference = Gw @ C_sym @ Gw.T
        assert np.array_equal(ws.compliance, ws.compliance.T)
        np.testing.assert_allclose(ws.compliance, reference, rtol=0, atol=1e-7 * np.abs(reference).max())

    ws.add(structure, rows, [("tooth", i) for i in range(6)])
    check()
    ws.add(structure, rows, [("tooth", i) for i in range(6, 15)])
    check()
    moved = G.tolil()
    moved[3, :] = 0.0
    moved[3, 11] = 2.5
    rows["tooth"] = SimpleNamespace(G=moved.tocsr())
    assert ws.refresh(structure, rows, "tooth") is not None
    check()


@pytest.mark.slow
def test_solver_gaps_are_those_of_its_displacement_and_a_fork_solves_alike():
    """On a preloaded coarse HD 42 section at the test torque (every tooth pair a candidate,
    the FS rotation a free mode): the gaps a level returns equal g0 + G u + s p of the
    displacement it returns (the iterate never forms u, the level's result does), to 1e-9 mm; the projection is kept from one level to the next
    on the same rows; a fork (copied projection) solves the next level to the same forces as
    the model it was forked from (the same state, so the same iterates)."""
    from hdwf.drive.geometry import drive_geometry
    from hdwf.drive.mesh import build_mesh
    from hdwf.fe import LostMotionModel
    from hdwf.fe.contact_rows import stack_rows
    from hdwf.fe.cycle import mount_wave_generator

    g = drive_geometry("hd42", 31.0, 42.0, 0.015, 0.0, 0.0, interference_m=0.2)
    model = LostMotionModel(g, build_mesh(g, elements_over_height=5, elements_over_thickness=3,
                                          symmetry="half"), zone_deg=90.0)
    mounted = mount_wave_generator(model, ramp_teeth=True)
    model.mode_list = model.mode_list + [("fs", "rot")]      # the torque test's stage 2
    level = model.solve_level(g.torque, mounted.solution.active)
    stacked = stack_rows(model.rows)
    tooth = np.array([k == "tooth" for k, _ in level.pair_ids])
    assert tooth.sum() > 100 and (level.normal_force[tooth] > 0).sum() > 20
    gap = stacked.g0 + stacked.G @ level.u_watch + stacked.compliance * level.normal_force
    np.testing.assert_allclose(level.gap[tooth], gap[tooth], rtol=0, atol=1e-9)

    kept = model.solver.projected
    fork = model.fork()
    assert fork.solver.projected is not kept and fork.solver.projected.store.size == kept.store.size
    again = model.solve_level(g.torque, level.active)
    assert model.solver.projected is kept
    forked = fork.solve_level(g.torque, level.active)
    np.testing.assert_allclose(forked.normal_force, again.normal_force, rtol=0,
                               atol=1e-9 * again.normal_force.max())
