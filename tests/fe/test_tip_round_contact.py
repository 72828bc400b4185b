"""Rounded tip corners in the contact solve (``drive_geometry(tip_round_m=...)``)."""

import math

import numpy as np
import pytest

from hdwf.drive.geometry import drive_geometry
from hdwf.drive.mesh import build_mesh
from hdwf.drive.relief import PRELOAD_TIP_RELIEF
from hdwf.fe import LostMotionModel, ModelChanges, solve_lost_motion
from hdwf.fe.contact_rows import tooth_rows

# hd42-lhs-14 of the default target's `fe` study: with sharp tips its Φ changes by 5.7 % from
# the default to the 1.25x finer mesh (docs/fe-model.md, "Mesh convergence")
HD42_LHS14 = ("hd42", 31.006089, 41.995083, 0.019195, 0.003683, 0.001426)
STUDIES_MODEL = ModelChanges(flank_interference_m=0.3, flank_layer_m=3900.0)


def test_second_pass_watches_every_node_of_the_cs_rounds():
    """The CS tips' contact pass takes every CS outline node within rho of the tip circle (a
    round's nodes lie within rho(1 + cos beta) < rho of it), also where rho (0.25 m = 45 um on
    HD 42) reaches deeper than the pass's usual band of 0.05 h (17 um)."""
    g = drive_geometry(*HD42_LHS14, interference_m=0.3, tip_relief=PRELOAD_TIP_RELIEF, tip_round_m=0.25)
    model = LostMotionModel(g, build_mesh(g, 5, 3, symmetry="half"), zone_deg=10.0)
    rows = tooth_rows(model.structure, g, np.zeros(model.nwatch), np.inf)
    cs = model.bodies["cs"]
    outline = np.intersect1d(cs.body_mesh.node_sets["cs_teeth"], cs.watch_nodes)
    depth = np.hypot(*cs.x[:, outline]) - g.r_cs_tip
    round_nodes = outline[(depth > 1e-7) & (depth < g.tip_round)]
    deeper_than_band = round_nodes[np.hypot(*cs.x[:, round_nodes]) - g.r_cs_tip
                                   > 0.05 * (g.r_cs_root - g.r_cs_tip)]
    assert deeper_than_band.size > 0
    assert set(cs.independent(round_nodes)) <= set(rows.slave_nodes[1])


@pytest.mark.slow
def test_rounded_tips_converge_where_sharp_ones_did_not():
    """The studies' model (0.3 m on 3900 modules) on hd42-lhs-14 with the tip corners rounded
    by 0.1 m: Φ on the default and the 1.25x finer mesh within the 2 % the issue asks of every
    `fe` design (measured 0.2387 and 0.2384 arcmin). On other designs the rounds do not help
    (docs/fe-alternatives.md, "Rounded tip corners"): this checks the round's contact, not a cure."""
    g = drive_geometry(*HD42_LHS14, interference_m=0.3, tip_relief=PRELOAD_TIP_RELIEF, tip_round_m=0.1)
    phi = []
    for refinement in (1.0, 1.25):
        r = solve_lost_motion(g, build_mesh(g, 10, 6, refinement, symmetry="half"), steps_per_ramp=5,
                              changes=STUDIES_MODEL)
        assert r.status == "ok", r.reason
        phi.append(r.lost_motion_arcmin)
    assert math.isclose(phi[1], phi[0], rel_tol=0.02)
