"""The preload candidate: a variant that reshapes the teeth, meshed on its own, offered by name only."""

from __future__ import annotations

import numpy as np
import pytest

from hdwf.drive.design import MeshSettings, geometry_of
from hdwf.drive.relief import PRELOAD_TIP_RELIEF
from hdwf.fe import ModelChanges, solve_lost_motion
from hdwf.fe.solver import TOL_GAP
from hdwf.study.convergence import twist_resolution_arcmin
from hdwf.validation.effects import model_changes
from hdwf.validation.variants import SolveSetup, candidate_names, plan_variants, solve_specimen

# HD 42, Table 3's nominal bearing, r_FS = r_CS = 5 µm: a rigid clearance of 10 µm per flank
SPECIMEN = {"specimen_id": "s1", "d_mm": 31.0, "D_mm": 42.0, "Gr_mm": 0.015, "rFS_mm": 0.005, "rCS_mm": 0.005}
MESH = {"elements_over_height": 5, "elements_over_thickness": 3, "symmetry": "half"}


def test_preload_is_offered_by_name_only():
    """A design value: ``candidates: all`` leaves it out, a campaign that names it gets its grid."""
    assert "preload" not in candidate_names({}) and "thermal" in candidate_names({})
    plan = plan_variants({}, ["preload"])
    assert plan[0] == {} and [v["preload"]["interference_m"] for v in plan[1:]] == pytest.approx([0.05, 0.1, 0.15, 0.2, 0.25, 0.3])


def test_a_reshaping_change_needs_its_geometry():
    """The solve cannot thicken the teeth of a mesh it is given: it refuses, naming the field."""
    g = geometry_of("hd42", SPECIMEN)
    changes = model_changes({"preload": {"interference_m": 0.1}})
    assert changes.geometry_part() == {"interference_m": 0.1, "tip_relief": PRELOAD_TIP_RELIEF}
    with pytest.raises(ValueError, match="interference_m"):
        solve_lost_motion(g, MeshSettings.from_mapping(MESH).mesh(g), 1, changes=changes)


@pytest.mark.slow
def test_preload_variants_equal_their_own_solves_and_take_the_clearance_up():
    """``solve_specimen`` meshes the first preloaded outline whole and the next ones' FS only, on
    the same CS and rings, assembled and factorised once: each variant's twists equal a solve of
    that geometry on its own whole mesh (the first exactly; the others to the contact tolerance,
    tol / r_b per twist of each solve: their FS meshes agree to round-off and their columns come
    from shared responses), and the baseline beside them is unchanged. Past δ·m = r_FS + r_CS (10 µm,
    0.056 m) the rigid clearance 2 (r_FS + r_CS − δ m) / r_b is negative: no play is left, Φ is
    elastic only, below a tenth of the baseline's 3.4 arcmin of play; and Φ falls as the teeth
    thicken."""
    setup = SolveSetup("hd42", MESH, steps_per_ramp=1)
    variants = [{}, {"preload": {"interference_m": 0.05}}, {"preload": {"interference_m": 0.1}}]
    table = solve_specimen(setup, SPECIMEN, variants).to_pandas()
    assert (table["status"] == "ok").all(), table["status"].unique()
    phi = {}
    for key, part in table.groupby("variant", sort=False):
        effects = {} if key == "baseline" else {"preload": {"interference_m": float(key.split("=")[1])}}
        changes = model_changes(effects)
        g = geometry_of("hd42", SPECIMEN, **changes.geometry_part())
        alone = solve_lost_motion(g, MeshSettings.from_mapping(MESH).mesh(g), 1, changes=changes)
        if key == "preload:interference_m=0.1":     # the outline that took the shared bodies
            tol = twist_resolution_arcmin(TOL_GAP, g.r_cs_base) / 2   # two solves, tol / r_b each
            np.testing.assert_allclose(part["twist_arcmin"].to_numpy(), alone.twist_arcmin, rtol=0, atol=tol)
        else:
            assert np.array_equal(part["twist_arcmin"].to_numpy(), alone.twist_arcmin), key
        phi[key] = alone.lost_motion_arcmin
    base, mid, locked = phi["baseline"], phi["preload:interference_m=0.05"], phi["preload:interference_m=0.1"]
    assert base == pytest.approx(3.4, rel=0.15)
    assert base > mid > locked and locked < 0.1 * base
    assert ModelChanges().geometry_part() == {"interference_m": 0.0, "tip_relief": 0.0}
