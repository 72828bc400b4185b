"""The tooth contact of ``workflow/overlays/converged_contact.yaml``: the flank layer on the FS pass
alone, the tip corners rounded 0.1 m, 25 segments a flank (docs/fe-model.md, "Mesh convergence")."""

import math

import pytest

from hdwf.drive.geometry import drive_geometry
from hdwf.drive.mesh import build_mesh
from hdwf.drive.relief import PRELOAD_TIP_RELIEF
from hdwf.fe import ModelChanges, solve_lost_motion

# hd42-lhs-08 of the default target's `fe` study: the largest change of the 25 designs first run
# on this contact (1.24 % at 3900 modules; 1.21 % in the overlay's whole-study run at 3800)
HD42_LHS08 = ("hd42", 31.009931, 41.989324, 0.005939, 0.016476, 0.013379)
CONVERGED = ModelChanges(flank_interference_m=0.3, flank_layer_m=3800.0, flank_layer_fs_pass_only=True)


@pytest.mark.slow
def test_the_converged_contact_holds_phi_within_two_percent_on_a_finer_mesh():
    """Φ on the overlay's mesh (25 segments a flank) and on the 1.25x finer one (30) within the 2 %
    the issue asks of every `fe` design (0.4889 and 0.4951 arcmin at 3900 modules, 0.4800 and 0.4858
    at 3800 in the overlay's run)."""
    g = drive_geometry(*HD42_LHS08, interference_m=0.3, tip_relief=PRELOAD_TIP_RELIEF, tip_round_m=0.1)
    phi = []
    for refinement in (1.0, 1.25):
        mesh = build_mesh(g, 10, 6, refinement, symmetry="half", flank_refinement=2.5)
        r = solve_lost_motion(g, mesh, steps_per_ramp=5, changes=CONVERGED)
        assert r.status == "ok", r.reason
        phi.append(r.lost_motion_arcmin)
    assert math.isclose(phi[0], 0.489, rel_tol=0.06)   # 0.4889 at 3900 modules; 3800 lowers it ~2 %
    assert math.isclose(phi[1], phi[0], rel_tol=0.02)
