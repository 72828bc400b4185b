"""Bad input is refused with a message naming file, field (and row, value)."""

import shutil
from pathlib import Path

import pytest
import yaml

from hdwf.cli import main
from hdwf.config import load_config, validate_config
from hdwf.common.errors import ConfigError, InputError
from hdwf.study.paper import load_fea_designs

from conftest import DATA, ROOT

SCHEMA = ROOT / "src" / "hdwf" / "config.schema.yaml"


def _config_with(tmp_path, edit):
    config = yaml.safe_load((ROOT / "config.yaml").read_text())
    edit(config)
    path = tmp_path / "my-config.yaml"
    path.write_text(yaml.safe_dump(config))
    return path


def test_shipped_config_is_valid():
    config = load_config(ROOT / "config.yaml", SCHEMA)
    assert config["sobol"]["n_min"] == 65536


@pytest.mark.parametrize("edit, field, value", [
    (lambda c: c["doe"].update(n_designs="many"), "doe.n_designs", "many"),            # wrong type
    (lambda c: c["doe"].update(n_designs=5), "doe.n_designs", 5),                      # below 22
    (lambda c: c["doe"].update(n_designs=100_000), "doe.n_designs", 100_000),          # a DAG no laptop holds
    (lambda c: c["sobol"].update(tolerance=-0.1), "sobol.tolerance", -0.1),            # out of range
    (lambda c: c["sobol"].update(samplers=["monte-carlo"]), "sobol.samplers.0", "monte-carlo"),
    (lambda c: c["studies"]["paper"].update(units=["hd50"]), "studies.paper.units.0", "hd50"),
    (lambda c: c["sobol"].update(n_start=100), "sobol.n_start", 100),                  # not a power of two
    (lambda c: c["fe"].update(effects={"preloud": {"interference_m": 0.1}}), "fe.effects", "preloud"),  # no such effect
    (lambda c: c["fe"].update(effects={"preload": {"interference_m": 0.5}}),                          # out of bounds
     "fe.effects.preload.interference_m", 0.5),
    (lambda c: c["fe"].update(effects={"preload": {"delta": 0.1}}), "fe.effects.preload.delta", "delta"),
    (lambda c: c["fe"]["picture"].update(design="paper-99"), "fe.picture.design", "paper-99"),  # failed at run time
    (lambda c: c["fe"]["picture"].update(study="fe", design="hd42-lhs-01"), "fe.picture.design", "hd42-lhs-01"),
    (lambda c: c["sobol"].update(tolerance=float("nan")), "sobol.tolerance", float("nan")),   # .nan passes bounds
    (lambda c: c["validation"]["demo"]["mesh"].update(refinement=float("nan")),
     "validation.demo.mesh.refinement", float("nan")),
])
def test_bad_config_names_file_field_and_value(tmp_path, edit, field, value):
    path = _config_with(tmp_path, edit)
    with pytest.raises(ConfigError) as exc:
        load_config(path, SCHEMA)
    msg = str(exc.value)
    assert "my-config.yaml" in msg and f"field '{field}'" in msg and repr(value) in msg


def test_unknown_key_is_refused(tmp_path):
    path = _config_with(tmp_path, lambda c: c["sobol"].update(tolerence=0.01))
    with pytest.raises(ConfigError, match="tolerence"):
        load_config(path, SCHEMA)


def test_a_problem_is_blamed_on_the_config_file_that_sets_the_key(tmp_path):
    """Snakemake merges config.yaml, then each --configfile: the error names the file to fix."""
    first = tmp_path / "first.yaml"
    first.write_text("doe:\n  n_designs: 5\n")
    second = tmp_path / "second.yaml"
    second.write_text("sobol:\n  n_start: 64\n")
    config = yaml.safe_load((ROOT / "config.yaml").read_text())
    config["doe"]["n_designs"] = 5
    with pytest.raises(ConfigError) as exc:
        validate_config(config, SCHEMA, [ROOT / "config.yaml", first, second])
    assert exc.value.file == str(first) and exc.value.field == "doe.n_designs"
    config = yaml.safe_load((ROOT / "config.yaml").read_text())
    config["sobol"]["n_start"] = 100  # set by none of the files: it came from --config
    with pytest.raises(ConfigError) as exc:
        validate_config(config, SCHEMA, [ROOT / "config.yaml", first, second])
    assert exc.value.file == "--config (command line)"


def test_a_bad_key_name_is_blamed_on_the_config_file_that_holds_it(tmp_path):
    """An unknown effect name in an overlay is reported as field 'fe.effects' with the key as its
    value: the overlay, which holds that key, is named, not a --config that was never given."""
    overlay = tmp_path / "overlay.yaml"
    overlay.write_text("fe:\n  effects:\n    prelaod: {interference_m: 0.3}\n")
    config = yaml.safe_load((ROOT / "config.yaml").read_text())
    config["fe"]["effects"] = {"prelaod": {"interference_m": 0.3}}
    with pytest.raises(ConfigError) as exc:
        validate_config(config, SCHEMA, [ROOT / "config.yaml", overlay])
    assert exc.value.file == str(overlay) and exc.value.field == "fe.effects" and exc.value.value == "prelaod"
    config["fe"]["effects"] = {"prelaod2": {"interference_m": 0.3}}   # in no file: from --config
    with pytest.raises(ConfigError) as exc:
        validate_config(config, SCHEMA, [ROOT / "config.yaml", overlay])
    assert exc.value.file == "--config (command line)"


@pytest.mark.parametrize("overlay, change", [
    ("fe:\n  effects:\n    preload: {interference_mm: 0.3}\n",                  # a bad parameter name
     lambda c: c["fe"]["effects"].update(preload={"interference_mm": 0.3})),
    ("validation:\n  demo:\n    candidates: [thermal, themal]\n",               # a bad name in a list
     lambda c: c["validation"]["demo"].update(candidates=["thermal", "themal"])),
])
def test_a_bad_name_in_an_overlay_is_blamed_on_it(tmp_path, overlay, change):
    path = tmp_path / "overlay.yaml"
    path.write_text(overlay)
    config = yaml.safe_load((ROOT / "config.yaml").read_text())
    change(config)
    with pytest.raises(ConfigError) as exc:
        validate_config(config, SCHEMA, [ROOT / "config.yaml", path])
    assert exc.value.file == str(path), exc.value


def test_a_bad_key_in_the_base_is_blamed_on_it_under_an_overlay_that_does_not_set_it(tmp_path):
    """Mappings merge: an overlay that sets other campaigns' keys does not hide the base's bad one."""
    base, overlay = tmp_path / "base.yaml", tmp_path / "overlay.yaml"
    config = yaml.safe_load((ROOT / "config.yaml").read_text())
    config["validation"]["my camp"] = {"unit": "hd42", "measurements": "data/validation/demo_hd42.csv"}
    base.write_text(yaml.safe_dump(config))
    overlay.write_text("validation:\n  demo:\n    rounds: 2\n")
    config["validation"]["demo"]["rounds"] = 2
    with pytest.raises(ConfigError) as exc:
        validate_config(config, SCHEMA, [base, overlay])
    assert exc.value.file == str(base) and exc.value.value == "my camp"


def _copy_tables(tmp_path):
    dst = tmp_path / "paper"
    shutil.copytree(ROOT / "data" / "paper", dst)
    return dst


def test_table_missing_column(tmp_path):
    d = _copy_tables(tmp_path)
    f = d / "table4_hd42_fea.csv"
    f.write_text(f.read_text().replace("rCS_mm", "r_CS"))
    with pytest.raises(InputError) as exc:
        load_fea_designs(d, "hd42")
    assert "table4_hd42_fea.csv" in str(exc.value) and "field 'rCS_mm'" in str(exc.value)


def test_table_non_numeric_value(tmp_path):
    d = _copy_tables(tmp_path)
    f = d / "table4_hd42_fea.csv"
    lines = f.read_text().splitlines()
    lines[5] = lines[5].replace("0.1993212189", "0.19x")  # data row 5 = set 5
    f.write_text("\n".join(lines) + "\n")
    with pytest.raises(InputError) as exc:
        load_fea_designs(d, "hd42")
    msg = str(exc.value)
    assert "table4_hd42_fea.csv" in msg and "row 5" in msg and "field 'lost_motion_arcmin'" in msg and "'0.19x'" in msg


def test_table_empty_cell(tmp_path):
    d = _copy_tables(tmp_path)
    f = d / "table5_hd120_fea.csv"
    lines = f.read_text().splitlines()
    cells = lines[2].split(",")
    cells[3] = ""
    lines[2] = ",".join(cells)
    f.write_text("\n".join(lines) + "\n")
    with pytest.raises(InputError, match=r"row 2, field 'Gr_mm'"):
        load_fea_designs(d, "hd120")


def test_plan_command_refuses_bad_input_before_solving(tmp_path, capsys):
    """`hdwf plan`: an existing --out file is kept (no --force), a noise <= 0 is named; both
    are refused before any solve."""
    out = tmp_path / "plan.json"
    out.write_text("keep me")
    rc = main(["plan", "--unit", "hd42", "--designs", "3", "--seed", "1", "--noise-arcmin", "0.05",
               "--out", str(out)])
    assert rc == 2 and out.read_text() == "keep me"
    assert capsys.readouterr().err.strip() == f"hdwf: error: {out}, field '--out': exists; use --force to replace it"
    rc = main(["plan", "--unit", "hd42", "--designs", "3", "--seed", "1", "--noise-arcmin", "0"])
    err = capsys.readouterr().err
    assert rc == 2 and err.strip() == "hdwf: error: command line: noise_arcmin must be > 0, got 0.0"
    csv = tmp_path / "plan.csv"     # the plan is JSON: a .csv of JSON would mislead whoever opens it
    rc = main(["plan", "--unit", "hd42", "--designs", "3", "--seed", "1", "--noise-arcmin", "0.05", "--out", str(csv)])
    assert rc == 2 and not csv.exists()
    assert capsys.readouterr().err.strip() == (f"hdwf: error: {csv}, field '--out': the plan is JSON: "
                                               "name the file .json, not '.csv'")


@pytest.mark.parametrize("text, says", [
    ("rFS_mm=0:0.05", "leaves what the hd42 model supports (0:0.04)"),   # Table 3 span either side
    ("rFS_mm=0.002:0.001", "low <= high"),
    ("x_mm=0:1", "unknown parameter 'x_mm'"),
    ("rFS_mm0:0.002", "expected NAME=LOW:HIGH"),
    ("rFS_mm=nan:0.002", "two finite numbers"),
])
def test_synth_refuses_a_bad_design_range_before_solving(tmp_path, capsys, text, says):
    """`hdwf synth --range`: a range outside the model's support, reversed, of an unknown
    parameter or badly written is named with the option and its value; no file is written."""
    out = tmp_path / "m.csv"
    rc = main(["synth", "--unit", "hd42", "--designs", "2", "--seed", "1", "--noise-arcmin", "0.01",
               "--range", text, "--out", str(out)])
    err = capsys.readouterr().err
    assert rc == 2 and f"field '--range', value '{text}'" in err and says in err, err
    assert not out.exists()


def test_plan_refuses_a_design_range_given_twice(capsys):
    """The same parameter twice in `hdwf plan --range` would silently keep the last one."""
    rc = main(["plan", "--unit", "hd42", "--designs", "2", "--seed", "1", "--noise-arcmin", "0.05",
               "--range", "rFS_mm=0:0.002", "--range", "rFS_mm=0:0.001"])
    err = capsys.readouterr().err
    assert rc == 2 and "field '--range', value 'rFS_mm=0:0.001'" in err and "twice" in err, err


def test_synth_refuses_an_effect_parameter_given_twice(tmp_path, capsys):
    """`--effect tooth_friction:mu=0.05 --effect tooth_friction:mu=0.08` kept the last value and
    wrote a file whose hidden effect was not the one first typed."""
    out = tmp_path / "m.csv"
    rc = main(["synth", "--unit", "hd42", "--designs", "2", "--seed", "1", "--noise-arcmin", "0.01",
               "--effect", "tooth_friction:mu=0.05", "--effect", "tooth_friction:mu=0.08", "--out", str(out)])
    err = capsys.readouterr().err
    assert rc == 2 and not out.exists()
    assert err.strip() == ("hdwf: error: command line, field '--effect', value 'tooth_friction:mu=0.08': "
                           "tooth_friction:mu is given twice")


@pytest.mark.parametrize("command", [["plan", "--unit", "hd42", "--designs", "2", "--seed", "1", "--noise-arcmin", "0.05"],
                                     ["paper-measurements", "--unit", "hd42"]])
def test_an_output_that_is_a_folder_is_refused_even_with_force(tmp_path, capsys, command):
    """--out naming a folder with --force got as far as the rename (after every solve) and
    failed there with a traceback; the folder and what is in it are kept."""
    folder = tmp_path / "results.json"
    folder.mkdir()
    (folder / "keep").write_text("keep me")
    rc = main([*command, "--out", str(folder), "--force"])
    assert rc == 2 and (folder / "keep").read_text() == "keep me"
    assert capsys.readouterr().err.strip() == f"hdwf: error: {folder}, field '--out': is a folder: name the output file"


@pytest.mark.parametrize("command", [["plan", "--unit", "hd42", "--designs", "2", "--seed", "1", "--noise-arcmin", "0.05"],
                                     ["synth", "--unit", "hd42", "--designs", "2", "--seed", "1", "--noise-arcmin", "0.05"]])
def test_an_output_under_a_file_is_refused_before_any_solve(tmp_path, capsys, monkeypatch, command):
    """--out data.csv/x.csv, data.csv a file, was found only after every solve, and then reported
    as a file "made by something else while this ran". Now it is refused first, naming the file."""
    import hdwf.cli as cli

    def no_solve(*args, **kwargs):
        raise AssertionError("solved before the output was checked")

    monkeypatch.setattr(cli, "synthesize", no_solve)
    monkeypatch.setattr(cli, "plan_detectability", no_solve)
    blocker = tmp_path / "data.csv"
    blocker.write_text("keep me")
    out = blocker / ("x.json" if command[0] == "plan" else "x.csv")
    rc = main([*command, "--out", str(out)])
    assert rc == 2 and blocker.read_text() == "keep me"
    assert capsys.readouterr().err.strip() == (f"hdwf: error: {out}, field '--out': cannot be written: "
                                               f"{blocker} is a file, not a folder")


def test_an_output_that_cannot_be_written_is_an_input_error_not_a_traceback(tmp_path, capsys):
    """A folder the system refuses (here /proc) ended in a FileNotFoundError traceback after the
    work; it is an error on --out, exit 2, and nothing is left behind."""
    out = Path("/proc/hdwf-test/m.csv")
    rc = main(["paper-measurements", "--unit", "hd42", "--data", str(DATA), "--out", str(out)])
    err = capsys.readouterr().err.strip()
    assert rc == 2 and err.startswith(f"hdwf: error: {out}, field '--out': cannot be written: ") and not out.exists()
    assert err.endswith("(/proc/hdwf-test)")   # the path the system refused, not only its reason


def test_an_output_folder_without_write_permission_is_refused_before_the_work(tmp_path, capsys, monkeypatch):
    """Root may write anywhere, so the check is made to see a folder it may not write in."""
    import hdwf.cli as cli

    monkeypatch.setattr(cli.os, "access", lambda path, mode: False)
    out = tmp_path / "m.csv"
    rc = main(["paper-measurements", "--unit", "hd42", "--data", str(DATA), "--out", str(out)])
    assert rc == 2 and not out.exists()
    assert capsys.readouterr().err.strip() == (f"hdwf: error: {out}, field '--out': cannot be written: "
                                               f"no permission to write in {tmp_path}")


def test_a_dangling_link_at_out_is_an_existing_output(tmp_path, capsys):
    """A symbolic link to nowhere is not "absent": it is kept without --force (before, the
    command solved everything and ended in a FileExistsError traceback)."""
    out = tmp_path / "m.csv"
    out.symlink_to(tmp_path / "gone" / "m.csv")
    rc = main(["paper-measurements", "--unit", "hd42", "--data", str(DATA), "--out", str(out)])
    assert rc == 2 and out.is_symlink()
    assert "field '--out': exists; measurement files are never overwritten" in capsys.readouterr().err


def test_paper_measurements_keeps_a_file_made_at_out_while_it_ran(tmp_path, capsys, monkeypatch):
    """The --out check comes before the work; a file made there meanwhile (another run, a user)
    was replaced by the final rename. Now it is kept and the command says so, exit 2."""
    import hdwf.cli as cli

    out = tmp_path / "m.csv"
    real = cli.paper_measurements

    def slow(data, unit):
        out.write_text("made meanwhile")
        return real(data, unit)

    monkeypatch.setattr(cli, "paper_measurements", slow)
    rc = main(["paper-measurements", "--unit", "hd42", "--data", str(DATA), "--out", str(out)])
    assert rc == 2 and out.read_text() == "made meanwhile" and [p.name for p in tmp_path.iterdir()] == ["m.csv"]
    assert capsys.readouterr().err.strip() == (f"hdwf: error: {out}, field '--out': was made by something else while "
                                               "this ran: it is kept and nothing was written; use --force to replace it")
    assert main(["paper-measurements", "--unit", "hd42", "--data", str(DATA), "--out", str(out), "--force"]) == 0
    assert out.read_text().startswith("specimen_id,")


def test_a_config_and_its_overlay_merge_key_by_key_and_a_bad_key_is_blamed_on_its_file(tmp_path):
    """``load_config([base, overlay])`` merges as Snakemake merges --configfile (nested keys kept
    from the base unless the overlay sets them), and a bad value names the overlay that sets it."""
    overlay = tmp_path / "overlay.yaml"
    overlay.write_text("fe:\n  steps_per_ramp: 3\n")
    base = load_config(ROOT / "config.yaml", SCHEMA)
    merged = load_config([ROOT / "config.yaml", overlay], SCHEMA)
    assert merged["fe"]["steps_per_ramp"] == 3 and merged["fe"]["effects"] == base["fe"]["effects"]
    overlay.write_text("fe:\n  steps_per_ramp: 0\n")
    with pytest.raises(ConfigError) as exc:
        load_config([ROOT / "config.yaml", overlay], SCHEMA)
    assert str(exc.value).startswith(f"{overlay}, field 'fe.steps_per_ramp', value 0:")


@pytest.mark.parametrize("text, field, unexpected", [("sobl:\n  x: 1\n", "sobl", "'sobl'"),
                                                     ("doe:\n  n_design: 3\n", "doe.n_design", "'n_design'"),
                                                     ("fe:\n  7: 3\n", "fe.7", "7")])
def test_an_unknown_key_of_an_overlay_is_blamed_on_the_overlay_by_its_full_name(tmp_path, text, field, unexpected):
    """A misspelt top-level key of an overlay was blamed on '--config (command line)', which the
    user never gave, as field '(top level)'; the field is now the key itself, in the overlay."""
    overlay = tmp_path / "overlay.yaml"
    overlay.write_text(text)
    with pytest.raises(ConfigError) as exc:
        load_config([ROOT / "config.yaml", overlay], SCHEMA)
    assert str(exc.value).startswith(f"{overlay}, field '{field}': Additional properties are not allowed "
                                     f"({unexpected} was unexpected)")


def test_an_overlay_clears_the_studies_effects_with_null_and_an_empty_mapping_is_refused(tmp_path):
    """Overlays merge mapping into mapping (as Snakemake's --configfile), so `effects: {}` kept the
    preload and flank layer on and said nothing: the bare section a user asked for was never
    solved. null clears the mapping; {} over a non-empty mapping is an error naming the fix."""
    base = load_config(ROOT / "config.yaml", SCHEMA)
    assert base["fe"]["effects"], "the default studies' model has effects to clear"
    overlay = tmp_path / "bare.yaml"
    overlay.write_text("fe:\n  effects: null\n")
    assert load_config([ROOT / "config.yaml", overlay], SCHEMA)["fe"]["effects"] == {}
    overlay.write_text("fe:\n  effects: {}\n")
    with pytest.raises(ConfigError) as exc:
        load_config([ROOT / "config.yaml", overlay], SCHEMA)
    assert str(exc.value).startswith(f"{overlay}, field 'fe.effects', value {{}}: an empty mapping in an overlay")
    assert str(exc.value).endswith("write null to clear it")
    overlay.write_text("validation:\n  demo:\n    effects: {}\n")   # empty over empty: nothing to clear
    assert load_config([ROOT / "config.yaml", overlay], SCHEMA)["validation"]["demo"]["effects"] == {}
    overlay.write_text("doe: {}\n")   # null would not clear doe (no {} default): {} there is harmless, not refused
    assert load_config([ROOT / "config.yaml", overlay], SCHEMA)["doe"] == base["doe"]


def test_an_empty_config_file_is_refused_as_snakemake_refuses_it(tmp_path):
    """check-config called an empty overlay valid; Snakemake stops on it ('keys at top level')."""
    empty = tmp_path / "empty.yaml"
    empty.write_text("")
    with pytest.raises(ConfigError) as exc:
        load_config([ROOT / "config.yaml", empty], SCHEMA)
    assert str(exc.value).startswith(f"{empty}: the file is empty")


def test_every_relation_problem_is_listed_not_only_the_first(tmp_path):
    """The rules the schema cannot express stopped at the first problem: a user fixed one, ran
    again and met the next. All are now listed after the first (which names field and value), and
    a wrong picture study does not also raise a KeyError for its design."""
    def edit(c):
        c["sobol"].update(n_start=100)                                        # not a power of two
        c["fe"].update(effects={"preloud": {"interference_m": 0.1}})          # no such effect
        c["fe"]["picture"].update(study="paper")                              # not an fe study
    with pytest.raises(ConfigError) as exc:
        load_config(_config_with(tmp_path, edit), SCHEMA)
    msg = str(exc.value)
    assert "field 'fe.effects', value 'preloud': unknown effect" in msg and "(and 2 more problem(s): " in msg
    assert "fe.picture.study: must name an fe study" in msg
    assert "sobol.n_start: must be a power of two" in msg


def test_paper_measurements_outside_the_project_says_where_the_tables_are(tmp_path, capsys, monkeypatch):
    """Run outside the project folder, --data's default data/paper is not there: the error says
    to run it in the project or give --data, instead of naming a missing table file."""
    monkeypatch.chdir(tmp_path)
    rc = main(["paper-measurements", "--unit", "hd42", "--out", str(tmp_path / "t4.csv")])
    assert rc == 2 and not (tmp_path / "t4.csv").exists()
    assert capsys.readouterr().err.strip() == ("hdwf: error: data/paper, field '--data': no such folder: run this in the "
                                               "project folder, or give --data the folder of the paper's tables")


@pytest.mark.parametrize("hidden, field, value", [
    ({"thermo": {"delta_T_K": 12}}, "validation.demo.hidden_effects", "thermo"),
    ({"thermal": {"delta_T": 12}}, "validation.demo.hidden_effects.thermal.delta_T", "delta_T"),
])
def test_a_hidden_effect_the_registry_does_not_know_is_refused_with_its_field(hidden, field, value):
    """The report would hold the finding against an effect no campaign can name: refused at start-up,
    naming the campaign's field and the bad key."""
    config = yaml.safe_load((ROOT / "config.yaml").read_text())
    config["validation"]["demo"]["hidden_effects"] = hidden
    with pytest.raises(ConfigError) as exc:
        validate_config(config, SCHEMA, [ROOT / "config.yaml"])
    assert exc.value.field == field and exc.value.value == value
