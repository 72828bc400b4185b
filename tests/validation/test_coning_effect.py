"""The coning candidate: the quasi-3D cup offered to a campaign by name, solved by the FE model.

The slow test holds a campaign specimen's coned variants against solves of their own and the
series law: a spring in series adds exactly T/K at each end of the coned test."""

from __future__ import annotations

import math

import numpy as np
import pytest

from hdwf.drive.design import MeshSettings, geometry_of
from hdwf.fe import ModelChanges, solve_lost_motion
from hdwf.validation.effects import model_changes
from hdwf.validation.variants import SolveSetup, candidate_names, plan_variants, solve_specimen

ARCMIN = math.pi / (180 * 60)
# our LHS design hd42-lhs-01 (tests/fe/test_coning_fe.py), a campaign's coarse half mesh
SPECIMEN = {"specimen_id": "s1", "d_mm": 31.0014, "D_mm": 41.9982, "Gr_mm": 0.01113,
            "rFS_mm": 0.01597, "rCS_mm": 0.00244}
MESH = {"elements_over_height": 5, "elements_over_thickness": 3, "symmetry": "half"}


def test_coning_is_offered_by_name_only_on_eight_slices():
    """Eight slice mounts a specimen: ``candidates: all`` leaves it out, a campaign that names it
    gets its grid (c = 0.2, 0.4), each a change of the model on the converged eight slices."""
    assert "coning" not in candidate_names({}) and "thermal" in candidate_names({})
    plan = plan_variants({"preload": {"interference_m": 0.2}}, ["coning"])
    assert [v.get("coning") for v in plan] == [None, {"slope": 0.2}, {"slope": 0.4}]
    ch = model_changes({"coning": {"slope": 0.2}})
    assert (ch.coning_slope, ch.coning_slices) == (0.2, 8)
    assert ch.fe_part() == ch and ch.geometry_part() == ModelChanges().geometry_part()


def test_coning_with_friction_fails_with_its_reason():
    """A coned cup is solved at prescribed twists, frictionless only: no number, a reason."""
    g = geometry_of("hd42", SPECIMEN)
    mesh = MeshSettings.from_mapping(MESH).mesh(g)
    r = solve_lost_motion(g, mesh, 1, changes=ModelChanges(coning_slope=0.2, flank_friction=0.1))
    assert r.status == "failed" and "frictionless" in r.reason and math.isnan(r.lost_motion_arcmin)


@pytest.mark.slow
def test_a_coned_variant_of_a_campaign_table_takes_series_elements_exactly():
    """A preloaded specimen's table (0.2 m) with coning (c = 0.2, eight slices): the coned
    variant solves, and cup torsion in series on the coned cup adds exactly T/K at +T and -T
    (one contact solve, its output twisted by the spring)."""
    fixed = {"preload": {"interference_m": 0.2}}
    K = 6.0e4    # N m / rad
    coned = {**fixed, "coning": {"slope": 0.2}}
    table = solve_specimen(SolveSetup("hd42", MESH, steps_per_ramp=1), SPECIMEN,
                           [fixed, coned, {**coned, "fs_cup_torsion": {"K_Nm_per_rad": K}}])
    assert (table["status"] == "ok").all(), table["status"].unique()
    curves = [g.sort_values("step") for _, g in table.groupby("variant", sort=False)]
    section, cone, cone_cup = (c["twist_arcmin"].to_numpy() for c in curves)
    torque = curves[1]["torque_Nm"].to_numpy()
    np.testing.assert_allclose(cone_cup - cone, (torque - torque[0]) / K / ARCMIN, atol=1e-9)
    assert section[1] > 0 and cone[1] > 0
