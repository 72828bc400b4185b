"""Artefacts: atomic writes, units and provenance in the Parquet metadata."""

import re
from importlib import metadata

import pandas as pd
import pyarrow.parquet as pq
import pytest

from hdwf.stages.paper import paper_lost_motion_stage
from hdwf.study.aggregate import write_lost_motion
from hdwf.common.provenance import config_hash
from hdwf.common.io import arrow_row, atomic_path, read_parquet_meta, write_json, write_parquet
from hdwf.common.provenance import provenance

from conftest import ROOT


def test_failed_write_leaves_previous_file_intact(tmp_path):
    target = tmp_path / "result.json"
    target.write_text("earlier result")
    with pytest.raises(RuntimeError):
        with atomic_path(target) as tmp:
            tmp.write_text("half")
            raise RuntimeError("killed mid-write")
    assert target.read_text() == "earlier result"
    assert [p.name for p in tmp_path.iterdir()] == ["result.json"]  # no temporary left behind


def test_a_write_that_may_not_replace_keeps_a_file_made_meanwhile(tmp_path):
    """`hdwf synth --out m.csv` (no --force) checks m.csv before a solve of minutes; a file made
    there in that time was replaced by the final rename. Without ``replace`` it is kept, the write
    fails with FileExistsError and leaves no temporary; a free name is written as before."""
    target = tmp_path / "m.csv"
    with pytest.raises(FileExistsError):
        with atomic_path(target, replace=False) as tmp:
            tmp.write_text("ours")
            target.write_text("someone else's")    # made while the block ran
    assert target.read_text() == "someone else's"
    assert [p.name for p in tmp_path.iterdir()] == ["m.csv"]
    with atomic_path(tmp_path / "n.csv", replace=False) as tmp:
        tmp.write_text("ours")
    assert (tmp_path / "n.csv").read_text() == "ours" and len(list(tmp_path.iterdir())) == 2


def test_config_hash_ignores_key_order():
    assert config_hash({"a": 1, "b": {"c": 2, "d": 3}}) == config_hash({"b": {"d": 3, "c": 2}, "a": 1})
    assert config_hash({"a": 1}) != config_hash({"a": 2})


def test_lost_motion_schema_units_and_provenance(tmp_path, paper_dir):
    prov = provenance({"x": 1}, ROOT)
    out = paper_lost_motion_stage(paper_dir, "hd42", tmp_path / "lm.parquet", prov)
    schema = pq.read_schema(out)
    assert schema.names[:10] == ["design_id", "d_mm", "D_mm", "Gr_mm", "rFS_mm", "rCS_mm", "phi_plus_arcmin",
                                 "phi_minus_arcmin", "lost_motion_arcmin", "status"]
    assert schema.field("lost_motion_arcmin").metadata[b"unit"] == b"arcmin"
    assert schema.field("d_mm").metadata[b"unit"] == b"mm"
    stored, _ = read_parquet_meta(out)
    assert stored["config_hash"] == config_hash({"x": 1})
    assert stored["packages"]["numpy"] == metadata.version("numpy")
    assert stored["packages"]["hdwf"] == metadata.version("hdwf")
    if (ROOT / ".git").exists():     # a clone (as CI and the README make): its commit
        assert re.fullmatch(r"[0-9a-f]{40}(-dirty)?", stored["git_commit"])
    else:
        assert stored["git_commit"] == "unknown (not a git checkout)"
    df = pd.read_parquet(out)
    assert df["phi_plus_arcmin"].isna().all()  # the paper gives only Φ
    assert (df["status"] == "published").all()


def test_provenance_names_the_library_checkout_when_it_is_not_the_projects(tmp_path):
    """Run from a project whose checkout is not the one ``hdwf`` is imported from, the commit
    names both (the project's alone would not say which code made the artefact); run from the
    library's own checkout, just its commit."""
    import subprocess

    from hdwf.common import provenance as prov_module
    library = prov_module._LIBRARY_ROOT
    if not (library / ".git").exists():
        pytest.skip("hdwf is not imported from a git checkout here")
    project = tmp_path / "project"
    project.mkdir()
    git = ["git", "-C", str(project), "-c", "user.name=t", "-c", "user.email=t@t"]
    subprocess.run(["git", "init", "-q", str(project)], check=True)
    (project / "f").write_text("x")
    subprocess.run(git + ["add", "f"], check=True)
    subprocess.run(git + ["commit", "-qm", "one"], check=True)
    project_commit = prov_module.git_commit(project)
    said = provenance({}, project)["git_commit"]
    assert said == f"{project_commit}; hdwf library {prov_module.git_commit(library)}"
    assert provenance({}, library)["git_commit"] == prov_module.git_commit(library)


def test_a_tool_installed_from_no_checkout_gives_no_commit(tmp_path, monkeypatch):
    """``hdwf synth`` installed without a checkout (its files in a venv that sits inside some other
    repository): git, asked about that folder, would name the other repository's HEAD; the record
    says the commit is unknown instead."""
    import subprocess

    from hdwf.common import provenance as prov_module
    repo = tmp_path / "other"
    site = repo / ".venv" / "lib" / "python3.11"
    site.mkdir(parents=True)
    git = ["git", "-C", str(repo), "-c", "user.name=t", "-c", "user.email=t@t"]
    subprocess.run(["git", "init", "-q", str(repo)], check=True)
    (repo / "f").write_text("x")
    subprocess.run(git + ["add", "f"], check=True)
    subprocess.run(git + ["commit", "-qm", "one"], check=True)
    assert prov_module.git_commit(site).startswith(prov_module.git_commit(repo)[:40])   # what git would say
    monkeypatch.setattr(prov_module, "_LIBRARY_ROOT", site)
    assert prov_module.tool_provenance({"seed": 1})["git_commit"] == "unknown (hdwf is not run from a git checkout)"


def test_failed_design_never_carries_a_number(tmp_path):
    df = pd.DataFrame({"design_id": ["a", "b"], "d_mm": [31.0, 31.0], "D_mm": [42.0, 42.0], "Gr_mm": [0.01, 0.01],
                       "rFS_mm": [0.0, 0.0], "rCS_mm": [0.0, 0.0], "lost_motion_arcmin": [0.5, 0.7],
                       "status": ["ok", "failed: contact did not converge in 50 iterations"]})
    out = write_lost_motion(df, tmp_path / "lm.parquet", provenance={})
    back = pd.read_parquet(out).set_index("design_id")
    assert back.loc["a", "lost_motion_arcmin"] == 0.5
    assert pd.isna(back.loc["b", "lost_motion_arcmin"])


def test_an_arrow_row_reads_back_as_the_pandas_row_it_replaces(tmp_path):
    """A solve job writes its row as Arrow (no pandas in its process); the aggregation reads it
    with pandas: the same values and dtypes as a row pandas wrote, a failed Φ missing (null, NaN),
    not a number, and the units in the field metadata."""
    row = {"design_id": "hd42-lhs-01", "d_mm": 31.0, "lost_motion_arcmin": float("nan"),
           "status": "failed: contact did not converge", "iterations": 200}
    arrow = write_parquet(arrow_row(row), tmp_path / "arrow.parquet", provenance={"git_commit": "x"})
    panda = write_parquet(pd.DataFrame([row]), tmp_path / "pandas.parquet", provenance={"git_commit": "x"})
    a, b = pd.read_parquet(arrow), pd.read_parquet(panda)
    pd.testing.assert_frame_equal(a, b)
    assert pq.read_table(arrow).column("lost_motion_arcmin").null_count == 1
    assert pq.read_schema(arrow).field("d_mm").metadata == {b"unit": b"mm"}
    assert read_parquet_meta(arrow)[0] == {"git_commit": "x"}


def test_json_artefacts_are_strict_json(tmp_path):
    """A surrogate's leave-one-out Q² is -inf when a design has leverage 1; Python would write
    ``-Infinity``, which no strict JSON reader takes. NaN and inf are written as null, arrays and
    numpy scalars as plain numbers."""
    import json

    import numpy as np
    path = write_json({"q2_loo": -np.inf, "r2": np.float64(0.98), "n": np.int64(27), "phi": np.array([1.5, np.nan])},
                      tmp_path / "s.json")
    text = path.read_text()
    assert json.loads(text, parse_constant=lambda c: pytest.fail(f"non-JSON constant {c}")) == \
        {"q2_loo": None, "r2": 0.98, "n": 27, "phi": [1.5, None]}
