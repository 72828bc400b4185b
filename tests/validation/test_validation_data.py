"""The shipped measurement files and the campaign settings of config.yaml."""


import pytest
import yaml

from hdwf.config import validate_config
from hdwf.common.errors import ConfigError
from hdwf.validation.measurements import load_measurements
from hdwf.study.paper import load_fea_designs, paper_measurements

from conftest import DATA, ROOT

SCHEMA = ROOT / "src/hdwf/config.schema.yaml"


@pytest.mark.parametrize("unit", ["hd42", "hd120"])
def test_paper_measurement_files_are_tables_4_and_5(unit):
    """The paper campaign's 'measurements' are exactly the paper's FEA lost motion."""
    shipped = load_measurements(ROOT / f"data/validation/paper_{unit}.csv")
    assert shipped.form == "lost_motion"
    table = load_fea_designs(DATA, unit)
    assert list(shipped.specimens["specimen_id"]) == list(table["design_id"])
    assert shipped.data["lost_motion_arcmin"].to_numpy() == pytest.approx(table["lost_motion_arcmin"].to_numpy(),
                                                                          rel=1e-9)
    assert paper_measurements(DATA, unit).shape == (27, 8)


def test_demo_file_is_a_checked_curve_file():
    demo = load_measurements(ROOT / "data/validation/demo_hd42.csv")
    assert demo.form == "curve" and len(demo.specimens) == 16
    assert (demo.data.groupby("specimen_id")["step"].count() == 21).all()


def _config_with(campaign):
    cfg = yaml.safe_load((ROOT / "config.yaml").read_text())
    cfg["validation"] = {"c": campaign}
    return cfg


@pytest.mark.parametrize("campaign, field", [
    ({"unit": "hd42", "measurements": "x.csv", "effects": {"warp": {"x": 1}}}, "validation.c.effects"),
    ({"unit": "hd42", "measurements": "x.csv", "effects": {"thermal": {"dT": 1}}}, "validation.c.effects.thermal.dT"),
    ({"unit": "hd42", "measurements": "x.csv", "effects": {"thermal": {"delta_T_K": 400}}},
     "validation.c.effects.thermal.delta_T_K"),
    ({"unit": "hd42", "measurements": "x.csv", "candidates": ["thermal", "nope"]}, "validation.c.candidates"),
    ({"unit": "hd7", "measurements": "x.csv"}, "validation.c.unit"),
])
def test_bad_campaign_is_refused_naming_the_key(campaign, field):
    with pytest.raises(ConfigError) as err:
        validate_config(_config_with(campaign), SCHEMA)
    assert f"field '{field}'" in str(err.value)


def test_calibrate_is_accepted():
    cfg = validate_config(_config_with({"unit": "hd42", "measurements": "x.csv",
                                        "effects": {"tooth_friction": {"mu": "calibrate"}}}), SCHEMA)
    assert cfg["validation"]["c"]["rounds"] == 2


def test_the_finer_mesh_demo_file_holds_the_demos_specimens_with_the_meshs_own_change():
    """``demo_hd42_finer_mesh.csv`` is the demo's ``hdwf synth`` run with ``--refinement 1.25``:
    the same seed, so the same specimens, torques and noise draws, only the mesh differs. Its twists
    then differ from the demo's by the mesh's own change, which the default mesh keeps within 2 %
    of Φ on most designs: far above zero (not a copy) and well below 2 % of the data's RMS."""
    import numpy as np

    demo = load_measurements(ROOT / "data/validation/demo_hd42.csv").data
    finer = load_measurements(ROOT / "data/validation/demo_hd42_finer_mesh.csv").data
    same = ["specimen_id", "unit", "d_mm", "D_mm", "Gr_mm", "rFS_mm", "rCS_mm", "step", "torque_Nm", "u_twist_arcmin"]
    assert finer[same].equals(demo[same])
    change = finer["twist_arcmin"].to_numpy() - demo["twist_arcmin"].to_numpy()
    scale = np.sqrt(np.mean(demo["twist_arcmin"].to_numpy() ** 2))
    assert 1e-4 * scale < np.sqrt(np.mean(change ** 2)) < 0.02 * scale


def test_the_finer_mesh_demo_campaign_is_valid_and_hides_the_demos_effects():
    """``workflow/campaigns/demo_finer_mesh.yaml`` merged over config.yaml (as ``--configfile``
    does) passes the schema and hides exactly what the demo hides, on the demo's mesh."""
    from snakemake.utils import update_config

    config = yaml.safe_load((ROOT / "config.yaml").read_text())
    extra = ROOT / "workflow/campaigns/demo_finer_mesh.yaml"
    update_config(config, yaml.safe_load(extra.read_text()))
    validate_config(config, SCHEMA, source=[ROOT / "config.yaml", extra])
    demo, finer = config["validation"]["demo"], config["validation"]["demo_finer_mesh"]
    assert finer["hidden_effects"] == demo["hidden_effects"] and finer["mesh"] == demo["mesh"]
    assert finer["candidates"] == demo["candidates"] and finer["rounds"] == demo["rounds"]
