"""The `hdwf` command from any folder: packaged schema, one-line errors, --version, closed pipes."""

import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from hdwf import __version__
from hdwf.cli import main
from hdwf.validation.measurements import load_measurements

from conftest import ROOT

HDWF = str(Path(sys.executable).with_name("hdwf"))


def _run(args, cwd):
    return subprocess.run([HDWF, *args], cwd=cwd, capture_output=True, text=True, timeout=120)


def test_check_config_works_outside_the_project(tmp_path):
    run = _run(["check-config", str(ROOT / "config.yaml")], cwd=tmp_path)
    assert run.returncode == 0, run.stderr
    assert "valid; config hash" in run.stdout


@pytest.mark.parametrize("make, says", [
    (lambda d: d / "missing.yaml", "No such file or directory"),
    (lambda d: d, "Is a directory"),
    (lambda d: (d / "binary.yaml").write_bytes(b"\xff\xfe\x00\x81") and d / "binary.yaml", "not a text file"),
])
def test_an_unreadable_config_is_one_line_and_exit_1(tmp_path, capsys, make, says):
    """The file is wrong, not the command: exit 1, as check-measurements gives for a bad file."""
    path = make(tmp_path)
    assert main(["check-config", str(path)]) == 1
    assert capsys.readouterr().err.strip().splitlines() == [f"hdwf: error: {path}: cannot read the config: {says}"]


def test_version(capsys):
    with pytest.raises(SystemExit) as stop:
        main(["--version"])
    assert stop.value.code == 0
    assert capsys.readouterr().out.strip() == f"hdwf {__version__}"


def test_a_closed_pipe_ends_quietly(monkeypatch, capsys):
    """`hdwf effects | head`: exit 1 with nothing on stderr, and what is left of stdout goes to
    /dev/null (so the interpreter's own flush at exit cannot raise again)."""
    read_end, write_end = os.pipe()

    class ClosedPipe:
        def write(self, text):
            raise BrokenPipeError

        def flush(self):
            pass

        def fileno(self):
            return write_end

    monkeypatch.setattr(sys, "stdout", ClosedPipe())
    try:
        assert main(["effects"]) == 1
        assert capsys.readouterr().err == ""
        assert os.path.samestat(os.fstat(write_end), os.stat(os.devnull))
    finally:
        os.close(read_end)
        os.close(write_end)


@pytest.mark.slow
def test_synth_shows_progress_and_writes_the_test_cycle(tmp_path, capsys):
    out = tmp_path / "bench.csv"
    rc = main(["synth", "--unit", "hd42", "--designs", "2", "--seed", "1", "--noise-arcmin", "0",
               "--elements-over-height", "4", "--elements-over-thickness", "2", "--refinement", "0.5",
               "--steps-per-ramp", "2", "--out", str(out)])
    err = capsys.readouterr().err
    assert rc == 0, err
    assert "hd42: 2 specimens, 2 solves" in err and "2/2" in err  # the bar reached the last specimen
    data = pd.read_csv(out)
    # 0 -> +T -> 0 -> -T -> 0 at 2 steps per ramp: 4 x 2 + 1 points per specimen
    assert data.groupby("specimen_id").size().tolist() == [9, 9]
    # HD 42's test torque is 4 % of its rated 24 N m (paper Table 1): 0.96 N m, two steps each way
    first = data[data["specimen_id"] == data["specimen_id"].iloc[0]]
    assert first["torque_Nm"].tolist() == pytest.approx([0, 0.48, 0.96, 0.48, 0, -0.48, -0.96, -0.48, 0])
    # noise-free data state no uncertainty (zero is refused), so the file loads as it is
    assert "u_twist_arcmin" not in data and len(load_measurements(out).specimens) == 2


def test_synth_to_parquet_records_what_made_it(tmp_path, capsys):
    """Parquet stand-in bench data carry their provenance (commit, versions) and the synthesis
    settings, from which the same seed makes the same numbers as the CSV (to its 9 digits)."""
    from hdwf.common.io import read_parquet_meta
    from hdwf.common.provenance import config_hash, git_commit
    argv = ["synth", "--unit", "hd42", "--designs", "1", "--seed", "3", "--noise-arcmin", "0.01",
            "--effect", "thermal:delta_T_K=10", "--range", "rFS_mm=0:0.002", "--elements-over-height", "4",
            "--elements-over-thickness", "2", "--refinement", "0.5", "--steps-per-ramp", "1"]
    assert main([*argv, "--out", str(tmp_path / "b.parquet")]) == 0
    assert main([*argv, "--out", str(tmp_path / "b.csv")]) == 0
    prov, meta = read_parquet_meta(tmp_path / "b.parquet")
    settings = meta["hdwf_synth"]
    assert settings["seed"] == 3 and settings["effects"] == {"thermal": {"delta_T_K": 10.0}}
    assert settings["ranges"] == {"rFS_mm": [0.0, 0.002]} and settings["mesh"]["refinement"] == 0.5
    assert prov["config_hash"] == config_hash(settings) and prov["packages"]["numpy"] == np.__version__
    assert prov["git_commit"] == git_commit(ROOT)     # the checkout hdwf runs from (pip install -e)
    pd.testing.assert_frame_equal(pd.read_parquet(tmp_path / "b.parquet"), pd.read_csv(tmp_path / "b.csv"),
                                  check_exact=False, rtol=1e-8)
    assert len(load_measurements(tmp_path / "b.parquet").specimens) == 1


def test_synth_whose_solve_fails_says_so_without_a_traceback_and_writes_nothing(tmp_path, capsys, monkeypatch):
    """A solve that does not converge (as ``fe.cycle.failed_result`` reports it, here forced) is
    an error line naming the specimen and the reason, exit 1, and no output file."""
    import hdwf.validation.variants as variants
    from hdwf.fe.cycle import failed_result

    monkeypatch.setattr(variants, "solve_lost_motion_variants", lambda geom, mesh, steps, group, shared=None: [
        failed_result(RuntimeError("contact did not converge in 200 iterations"), None, 0.0) for _ in group])
    out = tmp_path / "bench.csv"
    rc = main(["synth", "--unit", "hd42", "--designs", "1", "--seed", "1", "--noise-arcmin", "0",
               "--elements-over-height", "4", "--elements-over-thickness", "2", "--jobs", "1", "--out", str(out)])
    err = capsys.readouterr().err
    assert rc == 1 and not out.exists()
    assert "hdwf: error: synthesis: the FE solve failed for specimen hd42-s001" in err and "Traceback" not in err
    assert "did not converge in 200 iterations" in err and err.rstrip().endswith("(nothing was written)")


@pytest.mark.parametrize("option, value, said", [
    ("--designs", "0", "'0' is outside [1, 1000]"), ("--seed", "-1", "'-1' is outside [0, 4294967295]"),
    ("--noise-arcmin", "inf", "'inf' is outside [0.0, 60.0]"), ("--refinement", "nan", "'nan' is outside (0.0, 4.0]"),
    ("--steps-per-ramp", "0", "'0' is outside [1, 200]"), ("--steps-per-ramp", "201", "'201' is outside [1, 200]"),
    ("--elements-over-height", "1", "'1' is outside [2, 40]"),
    ("--jobs", "0", "'0' is outside [1, 256]"), ("--designs", "two", "'two' is not a whole number")])
def test_synth_and_plan_refuse_options_outside_the_schemas_limits_before_any_solve(tmp_path, capsys, option, value, said):
    """The mesh and load options carry the config schema's limits (a mesh of 0 elements was
    silently clamped, 0 steps wrote a file the loader refuses, 0 designs died in pandas): the
    option and value are named, exit 2, nothing written."""
    base = {"--designs": "2", "--seed": "1", "--noise-arcmin": "0.05"}
    for command in ("synth", "plan"):
        args = {**base, option: value}
        argv = [command, "--unit", "hd42", *[x for kv in args.items() for x in kv]]
        out = tmp_path / "x.csv"
        with pytest.raises(SystemExit) as exc:
            main(argv + (["--out", str(out)] if command == "synth" else []))
        assert exc.value.code == 2 and not out.exists()
        assert f"argument {option}: {said}" in capsys.readouterr().err


DEMO = ROOT / "data" / "validation" / "demo_hd42.csv"


def test_check_measurements_of_a_good_file(capsys):
    assert main(["check-measurements", str(DEMO), "--unit", "hd42"]) == 0
    out = capsys.readouterr()
    assert out.out.strip() == f"{DEMO}: 16 specimens, 336 points, form curve: ok" and not out.err


def test_check_measurements_refuses_a_point_beyond_the_campaigns_test_torque(tmp_path, capsys):
    """The loader accepts a torque up to 1.5 T, a campaign only up to a quarter step beyond T:
    the command checks as the campaign would (its steps per ramp, default 5), or said 'ok' to a
    file the workflow then refused."""
    data = pd.read_csv(DEMO)
    data.loc[data["step"] == 5, "torque_Nm"] = 1.0176          # the demo's +T steps (0.96 N m) pushed past it
    path = tmp_path / "beyond.csv"
    data.to_csv(path, index=False)
    assert main(["check-measurements", str(path), "--unit", "hd42"]) == 1
    err = capsys.readouterr().err
    assert "field 'torque_Nm', value 1.0176: beyond the campaign model's test torque" in err and "steps_per_ramp 5" in err
    assert main(["check-measurements", str(path), "--unit", "hd42", "--steps-per-ramp", "1"]) == 0


def test_check_measurements_prints_every_problem_and_exits_1(tmp_path, capsys):
    data = pd.read_csv(DEMO)
    data["u_twist_arcmin"] = data["u_twist_arcmin"].astype(float)
    data.loc[1, "u_twist_arcmin"] = 0.0                               # row 2
    data.loc[24, "twist_arcmin"] = 1e9                                # row 25
    data.loc[42:62, "torque_Nm"] = -data.loc[42:62, "torque_Nm"]      # rows 43-63: hd42-s003 flipped
    path = tmp_path / "bench.csv"
    data.to_csv(path, index=False)
    assert main(["check-measurements", str(path), "--unit", "hd42"]) == 1
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 3 and all(line.startswith(f"hdwf: error: {path}, row ") for line in err), err
    assert "row 2, field 'u_twist_arcmin', value 0.0: zero uncertainty" in err[0]
    assert "row 25, field 'twist_arcmin', value 1000000000.0: implausibly large" in err[1]
    assert "row 43, field 'torque_Nm': specimen 'hd42-s003': twist falls as torque rises" in err[2]


@pytest.mark.parametrize("make, says", [
    (lambda d: DEMO, f"{DEMO}, row 1, field 'unit', value 'hd42': specimen 'hd42-s001' is not of hd120"),
    (lambda d: d / "missing.csv", "missing.csv: cannot read the measurement file: No such file or directory"),
    (lambda d: (d / "empty.parquet").write_bytes(b"") or d / "empty.parquet",
     "empty.parquet: cannot read the measurement file: empty file"),
])
def test_check_measurements_refuses_with_exit_1(tmp_path, capsys, make, says):
    path = make(tmp_path)
    assert main(["check-measurements", str(path), "--unit", "hd120"]) == 1
    err = capsys.readouterr().err.strip().splitlines()
    assert err[0].startswith("hdwf: error: ") and says in err[0], err


def test_check_measurements_usage_error_exits_2(capsys):
    with pytest.raises(SystemExit) as stop:
        main(["check-measurements", str(DEMO), "--unit", "hd50"])
    assert stop.value.code == 2 and "invalid choice: 'hd50'" in capsys.readouterr().err


def test_check_config_checks_every_campaign_file(tmp_path, capsys):
    project = tmp_path / "project"
    (project / "data/validation").mkdir(parents=True)
    config = (ROOT / "config.yaml").read_text()
    (project / "config.yaml").write_text(config)
    for f in (ROOT / "data/validation").glob("*.csv"):
        (project / "data/validation" / f.name).write_bytes(f.read_bytes())
    (project / "data/paper").symlink_to(ROOT / "data/paper")
    assert main(["check-config", str(project / "config.yaml")]) == 0
    out = capsys.readouterr().out
    assert "campaign 'demo': data/validation/demo_hd42.csv: 16 specimens of hd42: ok" in out
    demo = pd.read_csv(project / "data/validation/demo_hd42.csv")
    demo.loc[4, "twist_arcmin"] = -1e9
    demo.to_csv(project / "data/validation/demo_hd42.csv", index=False)
    assert main(["check-config", str(project / "config.yaml")]) == 1
    err = capsys.readouterr().err
    assert "campaign 'demo'" in err and "row 5, field 'twist_arcmin', value -1000000000.0" in err


def test_check_config_names_a_paper_data_folder_without_the_papers_tables(tmp_path, capsys):
    """The studies and the report read the paper's tables from ``paper_data``: a missing folder
    passed check-config and failed only when Snakemake planned the run."""
    config = tmp_path / "config.yaml"
    config.write_text((ROOT / "config.yaml").read_text())
    (tmp_path / "data").mkdir()
    (tmp_path / "data" / "validation").symlink_to(ROOT / "data" / "validation")
    assert main(["check-config", str(config)]) == 1
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith(f"hdwf: error: {config}, field 'paper_data', value 'data/paper': "
                                               "no table1_drives.csv, table2_bearings.csv"), err
    (tmp_path / "data" / "paper").symlink_to(ROOT / "data" / "paper")
    assert main(["check-config", str(config)]) == 0
    assert "paper_data: data/paper: the paper's 6 tables: ok" in capsys.readouterr().out


def test_check_config_reads_a_config_kept_in_a_subfolder_from_the_project_root(tmp_path, capsys):
    """`snakemake --configfile configs/mine.yaml` reads `data/...` from the project folder; check-config
    looked beside the config (configs/data/...) and refused a config the workflow runs."""
    (tmp_path / "Snakefile").write_text("")
    (tmp_path / "data").mkdir()
    for name in ("paper", "validation"):
        (tmp_path / "data" / name).symlink_to(ROOT / "data" / name)
    (tmp_path / "configs").mkdir()
    config = tmp_path / "configs" / "mine.yaml"
    config.write_text((ROOT / "config.yaml").read_text())
    assert main(["check-config", str(config)]) == 0, capsys.readouterr().err
    out = capsys.readouterr().out
    assert "paper_data: data/paper: the paper's 6 tables: ok" in out
    assert "campaign 'demo': data/validation/demo_hd42.csv: 16 specimens of hd42: ok" in out


def test_check_config_merges_an_overlay_over_its_base_as_snakemake_does(capsys):
    """A campaign kept in its own file (workflow/campaigns/paper_coning.yaml, run with --configfile)
    is an overlay: alone it lacks the base's keys, and the command says how to check it; given
    after its base, it is merged key by key and its campaigns are checked with the base's."""
    overlay = str(ROOT / "workflow/campaigns/paper_coning.yaml")
    assert main(["check-config", overlay]) == 1
    err = capsys.readouterr().err.strip().splitlines()
    assert "'paper_data' is a required property (and 4 more problem(s)" in err[0] and "'fe' is a required" in err[0]
    assert err[1] == f"hdwf: hint: an overlay (a campaign's file) is checked over its base: hdwf check-config config.yaml {overlay}"
    assert main(["check-config", str(ROOT / "config.yaml"), overlay]) == 0
    out = capsys.readouterr().out
    assert "campaign 'paper_hd42_coning': data/validation/paper_hd42.csv: 27 specimens of hd42: ok" in out
    assert "campaign 'demo': data/validation/demo_hd42.csv: 16 specimens of hd42: ok" in out   # the base's too


def test_check_measurements_without_a_drive_checks_the_file_alone(tmp_path, capsys):
    """docs/measurements.md: --unit adds a campaign's checks; without it the file's own drives are
    taken (the demo is of HD 42, so --unit hd120 refuses it and no --unit accepts it), and a count
    of one reads in the singular."""
    assert main(["check-measurements", str(DEMO)]) == 0
    assert capsys.readouterr().out.strip() == f"{DEMO}: 16 specimens, 336 points, form curve: ok"
    assert main(["check-measurements", str(DEMO), "--unit", "hd120"]) == 1
    one = tmp_path / "one.csv"
    pd.read_csv(DEMO).head(1).drop(columns=["step", "torque_Nm", "twist_arcmin", "u_twist_arcmin"]).assign(
        lost_motion_arcmin=1.0).to_csv(one, index=False)
    capsys.readouterr()
    assert main(["check-measurements", str(one)]) == 0
    assert capsys.readouterr().out.strip() == f"{one}: 1 specimen, 1 point, form lost_motion: ok"


def test_a_config_that_is_not_a_mapping_is_named_as_such(tmp_path, capsys):
    """A YAML list at the top level cannot be merged with another config: one line, exit 1."""
    path = tmp_path / "list.yaml"
    path.write_text("- a\n- b\n")
    assert main(["check-config", str(ROOT / "config.yaml"), str(path)]) == 1
    assert capsys.readouterr().err.strip() == (f"hdwf: error: {path}: the top level must be keys and values "
                                               "(a mapping), not a list")
