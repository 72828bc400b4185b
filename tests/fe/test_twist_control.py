"""Displacement control: a level solved at a prescribed rim twist (``solver.Twist``).

Coarse half meshes (5 x 3 elements per tooth) of HD 42 at Table 3's nominal point.
"""

from functools import cache

import pytest

from hdwf.drive.geometry import ARCMIN, drive_geometry
from hdwf.drive.mesh import build_mesh
from hdwf.fe import LostMotionModel
from hdwf.fe.changes import ModelChanges
from hdwf.fe.contact_rows import tooth_rows
from hdwf.fe.cycle import mount_wave_generator
from hdwf.fe.preload import PRELOAD_ZONE_DEG
from hdwf.fe.solver import TOL_GAP, Twist

COARSE = {"elements_over_height": 5, "elements_over_thickness": 3}
STUDIES = ModelChanges(flank_interference_m=0.3, flank_layer_m=3900.0)   # config.yaml's fe.effects


@cache
def _mounted(changes: ModelChanges, r_fs: float):
    """The wave generator mounted (teeth ramped in if preloaded), the FS rotation freed."""
    g = drive_geometry("hd42", 31.0, 42.0, 0.015, r_fs, 0.0, **changes.geometry_part())
    model = LostMotionModel(g, build_mesh(g, **COARSE, symmetry="half"), zone_deg=PRELOAD_ZONE_DEG,
                            changes=changes)
    mounted = mount_wave_generator(model, ramp_teeth=g.preloaded)
    if "tooth" not in model.rows:      # (as the torque test does for teeth not ramped in)
        model.rows["tooth"] = tooth_rows(model.structure, g, mounted.solution.u_watch, 0.25 * g.module)
    model.mode_list = model.mode_list + [("fs", "rot")]
    return g, model, mounted.solution.active


def test_a_prescribed_twist_needs_the_torque_that_makes_it():
    """The studies' model (0.3 m preload on a 3900 m flank layer): the twist a torque makes,
    prescribed on a fresh fork of the mounted model, gives that torque back.  Both levels meet
    the gap tolerance, so they may differ by what the tangent stiffness makes of a gap error of
    TOL_GAP at the pitch radius."""
    g, model, active = _mounted(STUDIES, 0.0)
    levels = {}
    for fraction in (0.9, 1.0, -1.0):
        levels[fraction] = model.fork().solve_level(fraction * g.torque, active)
    stiffness = 0.1 * g.torque / (levels[1.0].twist - levels[0.9].twist)      # N mm / rad
    allowed = stiffness * TOL_GAP / g.r_fs_pitch
    for fraction in (1.0, -1.0):
        at = model.fork().solve_level(Twist(levels[fraction].twist), active)
        assert at.twist == pytest.approx(levels[fraction].twist, rel=0, abs=1e-12)
        assert abs(at.torque - fraction * g.torque) < allowed
        assert allowed < 0.05 * g.torque          # the bound is a real one (1.9 % measured)


def test_within_the_backlash_the_rim_turns_without_torque():
    """Bare section with an FS tooth offset (no preload): the teeth have play, and nothing but
    the teeth holds the FS rotation (balls and fit act radially).  The edges of the play are
    the twists a bias torque (0.001 T, load control) reaches; a twist between them needs no
    torque (zero up to the solver's 1e-14 regularisation of unheld modes), a twist beyond an
    edge more than the bias, in its own direction."""
    g, model, active = _mounted(ModelChanges(), 0.02)
    edge = {s: model.fork().solve_level(s * 1e-3 * g.torque, active).twist for s in (1, -1)}
    assert edge[1] - edge[-1] > 0.1 * ARCMIN            # a real play
    inside = model.fork().solve_level(Twist(0.5 * (edge[1] + edge[-1]) + 0.3 * (edge[1] - edge[-1]) / 2), active)
    assert abs(inside.torque) < 1e-5 * g.torque
    for s in (1, -1):
        beyond = model.fork().solve_level(Twist(2 * edge[s]), active)
        assert s * beyond.torque > 1e-3 * g.torque
