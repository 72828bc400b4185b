"""The coning candidate: the quasi-3D cup offered to a campaign by name, solved by the FE model.

The slow test holds a campaign specimen's coned variant against a solve of its own and the
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
                           [fixed, coned, {**coned, "fs_cup_torsion": {"K_Nm_per_rad": K}}]).to_pandas()
    assert (table["status"] == "ok").all(), table["status"].unique()
    curves = [g.sort_values("step") for _, g in table.groupby("variant", sort=False)]
    section, cone, cone_cup = (c["twist_arcmin"].to_numpy() for c in curves)
    torque = curves[1]["torque_Nm"].to_numpy()
    np.testing.assert_allclose(cone_cup - cone, (torque - torque[0]) / K / ARCMIN, atol=1e-9)
    # the campaign's coned variant is the coned cup's own solve (not the section's, not slope 0)
    ch = model_changes(coned)
    geom = geometry_of("hd42", SPECIMEN, **ch.geometry_part())
    own = solve_lost_motion(geom, MeshSettings.from_mapping(MESH).mesh(geom), 1, changes=ch)
    assert own.status == "ok", own.reason
    np.testing.assert_allclose(cone, own.twist_arcmin, rtol=0, atol=1e-9)
    # ... which the check above tells from the section's: locked by the 0.2 m preload the cone moves
    # the twists at +-T by about 1e-4 arcmin (Phi 0.0234 against 0.0232), far beyond its 1e-9
    assert np.abs(cone - section).max() > 1e-5 and section[1] > 0


def test_the_shipped_coning_campaigns_are_valid_and_tabulate_coning_on_the_preload():
    """``workflow/campaigns/paper_coning.yaml`` merged over config.yaml (as ``--configfile``
    does) passes the schema, and each campaign's table holds its preloaded model, coning at
    c = 0.2 and 0.4 on that preload, and the other two candidates' grids."""
    import yaml
    from snakemake.utils import update_config

    from hdwf.config import SCHEMA_PATH, validate_config
    from hdwf.stages.validation import campaign_plan

    from conftest import ROOT

    config = yaml.safe_load((ROOT / "config.yaml").read_text())
    extra = ROOT / "workflow/campaigns/paper_coning.yaml"
    update_config(config, yaml.safe_load(extra.read_text()))
    validate_config(config, SCHEMA_PATH, source=[ROOT / "config.yaml", extra])
    for name, preload in (("paper_hd42_coning", 0.222), ("paper_hd120_coning", 0.186)):
        variants = campaign_plan(name, config["validation"][name], config["fe"]).table_variants()
        assert variants[0] == {"preload": {"interference_m": preload}}
        assert all(v["preload"] == {"interference_m": preload} for v in variants)
        assert [v["coning"]["slope"] for v in variants if "coning" in v] == pytest.approx([0.2, 0.4])
        assert {n for v in variants for n in v} == {"preload", "coning", "fs_cup_torsion", "cs_housing"}


def test_a_grid_value_failed_on_some_specimens_is_dropped_and_named():
    """Calibration needs every specimen at a grid value: a value that failed on some is dropped,
    the note names it and how many specimens failed; with no value left the candidate is not
    calibrated, and the note says why (not that every solve failed)."""
    import pandas as pd

    from hdwf.validation.calibration import responses
    from hdwf.validation.variants import variant_key

    fixed = {"preload": {"interference_m": 0.2}}
    variants = [fixed] + [{**fixed, "coning": {"slope": c}} for c in (0.2, 0.4)] \
        + [{**fixed, "oldham_play": {"play_arcsec": a}} for a in (7.5, 15.0, 22.5, 30.0)]
    failed = {("s1", "coning", 0.2), ("s2", "coning", 0.2), ("s3", "coning", 0.4), ("s1", "oldham_play", 30.0)}
    rows = []
    for sid in ("s1", "s2", "s3"):
        for v in variants:
            extra = [(n, next(iter(p.values()))) for n, p in v.items() if n != "preload"]
            bad = bool(extra) and (sid, *extra[0]) in failed
            for step, frac in enumerate((0.0, 1.0, 0.0, -1.0, 0.0)):
                rows.append({"specimen_id": sid, "variant": variant_key(v), "step": step, "torque_Nm": 0.96 * frac,
                             "twist_arcmin": float("nan") if bad else 0.2 * frac, "status": "failed: x" if bad else "ok",
                             "ball_pressure_max_MPa": 900.0})
    table = pd.DataFrame(rows)
    obs = pd.DataFrame({"specimen_id": ["s1", "s2", "s3"], "D": [0.4, 0.5, 0.6], "quantity": "lost_motion",
                        "u_D": float("nan")})
    notes = {}
    resp = responses(table, obs, fixed, ["coning", "oldham_play"], notes)
    assert "coning" not in resp and "oldham_play" in resp
    assert notes["coning"] == ("solve failed at slope = 0.2 (2 specimens), 0.4 (1 specimens): "
                               "no grid value solved for every specimen; not calibrated")
    assert notes["oldham_play"].startswith("solve failed at play_arcsec = 30 (1 specimens)")
    assert resp["oldham_play"].t.size == 4      # off and the three values that solved
