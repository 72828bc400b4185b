"""Rule scripts run by hand too (``python workflow/scripts/<rule>.py``), as under Snakemake."""

import os
import subprocess
import sys

import pandas as pd
import pytest

from conftest import DATA, ROOT, copy_workflow


@pytest.mark.slow
def test_a_script_runs_outside_snakemake_from_any_folder(tmp_path):
    project = copy_workflow(tmp_path / "project")
    elsewhere = tmp_path / "elsewhere"
    elsewhere.mkdir()
    run = subprocess.run([sys.executable, str(project / "workflow/scripts/paper_lost_motion.py")], cwd=elsewhere,
                         capture_output=True, text=True, timeout=300)
    assert run.returncode == 0, run.stderr[-3000:]
    # mock_snakemake resolved the rule's output for study=paper, unit=hd42 in the project, not the cwd
    table = pd.read_parquet(project / "results/paper/hd42/lost_motion.parquet")
    published = pd.read_csv(DATA / "table4_hd42_fea.csv")
    assert len(table) == 27
    assert table["lost_motion_arcmin"].tolist() == published["lost_motion_arcmin"].tolist()
    assert "wrote results/paper/hd42/lost_motion.parquet" in (project / "results/logs/paper_hd42_lost_motion.log").read_text()
    assert not any(elsewhere.iterdir())


@pytest.mark.parametrize("script, stage", [("fe_solve.py", "fe_solve"), ("fe_refined_solve.py", "fe_solve"),
                                           ("validation_specimen.py", "validation_specimen")])
def test_a_solve_job_starts_without_pandas(script, stage):
    """Some 240 solve jobs of the default target each start a Python; importing pandas added
    ~0.25 s to every one (docs/fe-model.md, Time), so what these scripts import must not pull it in."""
    source = (ROOT / "workflow/scripts" / script).read_text()
    imports = [line for line in source.splitlines() if line.startswith(("import ", "from "))]
    assert any(f"hdwf.stages.{stage} import" in line for line in imports)
    code = "\n".join(["import sys", f"sys.path.insert(0, {str(ROOT / 'workflow/scripts')!r})", *imports,
                      "print(sorted(m for m in ('pandas', 'matplotlib', 'statsmodels') if m in sys.modules))"])
    run = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert run.returncode == 0, run.stderr[-3000:]
    assert run.stdout.strip() == "[]"


_PARSE_SNAKEFILE = """
import os, sys
from pathlib import Path
from snakemake.api import SnakemakeApi
from snakemake.settings.types import OutputSettings, ResourceSettings
root = Path(sys.argv[1])
with SnakemakeApi(OutputSettings(quiet={"all"})) as api:
    api.workflow(resource_settings=ResourceSettings(cores=1), snakefile=root / "Snakefile", workdir=root).dag()
print(*(os.environ.get(k, "-") for k in ("MALLOC_MMAP_THRESHOLD_", "MALLOC_TRIM_THRESHOLD_", "MALLOC_TOP_PAD_")))
"""


@pytest.mark.parametrize("env, expected", [
    ({}, "33554432 4294967296 268435456"),                                     # the jobs' heap kept
    ({"MALLOC_TOP_PAD_": "1048576"}, "33554432 4294967296 1048576"),           # a user's value wins
    ({"HDWF_KEEP_FREED_MEMORY": "0"}, "- - -"),                                # glibc's own handling
])
def test_the_snakefile_starts_jobs_with_freed_memory_kept(env, expected, tmp_path):
    """glibc reads its MALLOC_* settings when a process starts, so the Snakefile sets them for the
    jobs it starts (docs/fe-model.md, Time: 7.7 % off two study jobs at once)."""
    copy_workflow(tmp_path)
    base = {k: v for k, v in os.environ.items() if not k.startswith("MALLOC_") and k != "HDWF_KEEP_FREED_MEMORY"}
    run = subprocess.run([sys.executable, "-c", _PARSE_SNAKEFILE, str(tmp_path)], env={**base, **env},
                         capture_output=True, text=True, timeout=120)
    assert run.returncode == 0, run.stderr[-3000:]
    assert run.stdout.strip().splitlines()[-1] == expected


_MESH_PARAMS = """
import json, sys
from pathlib import Path
from types import SimpleNamespace
from snakemake.api import SnakemakeApi
from snakemake.settings.types import ConfigSettings, OutputSettings, ResourceSettings
root = Path(sys.argv[1])
with SnakemakeApi(OutputSettings(quiet={"all"})) as api:
    wf = api.workflow(resource_settings=ResourceSettings(cores=1), snakefile=root / "Snakefile", workdir=root,
                      config_settings=ConfigSettings(configfiles=[root / sys.argv[2]]))
    wf.dag()
    rules = wf._workflow
    solve = dict(rules.get_rule("fe_solve").params.items())["settings"]
    refined = dict(rules.get_rule("fe_refined_solve").params.items())["settings"](SimpleNamespace(ref="1.25"))
print(json.dumps([solve, refined]))
"""


def test_the_flank_division_of_the_config_reaches_every_study_mesh(tmp_path):
    """`fe.flank_refinement` (workflow/overlays/fine_flanks.yaml) must reach the study's solves
    and its convergence runs alike: were it lost on either, the 1.25x check would compare two
    different flank divisions (25 against 12 segments) and call it a mesh's convergence."""
    import json

    copy_workflow(tmp_path)
    run = subprocess.run([sys.executable, "-c", _MESH_PARAMS, str(tmp_path), "workflow/overlays/fine_flanks.yaml"],
                         capture_output=True, text=True, timeout=120)
    assert run.returncode == 0, run.stderr[-3000:]
    solve, refined = json.loads(run.stdout.strip().splitlines()[-1])
    assert solve == {"elements_over_height": 10, "elements_over_thickness": 6, "refinement": 1.0,
                     "symmetry": "half", "flank_refinement": 2.5}
    assert refined == {**solve, "refinement": 1.25}


def test_the_converged_contact_reaches_every_study_solve(tmp_path):
    """workflow/overlays/converged_contact.yaml: its tip round and one-pass layer must reach the
    solves and the convergence runs alike (a 1.25x run on sharp tips would not check the contact the
    studies solve), and the default config must leave the solves' params as they were (no rerun of
    a finished study)."""
    import json

    from hdwf.stages.fe_solve import DesignJob

    copy_workflow(tmp_path)
    runs = {}
    for overlay in ("workflow/overlays/converged_contact.yaml", "workflow/overlays/hd42_only.yaml"):
        run = subprocess.run([sys.executable, "-c", _MESH_PARAMS, str(tmp_path), overlay],
                             capture_output=True, text=True, timeout=120)
        assert run.returncode == 0, run.stderr[-3000:]
        runs[overlay] = json.loads(run.stdout.strip().splitlines()[-1])
    solve, refined = runs["workflow/overlays/converged_contact.yaml"]
    assert solve == {"elements_over_height": 10, "elements_over_thickness": 6, "refinement": 1.0,
                     "symmetry": "half", "flank_refinement": 2.5, "tip_round_m": 0.1,
                     "flank_layer_fs_pass_only": True}
    assert refined == {**solve, "refinement": 1.25}
    default_solve, _ = runs["workflow/overlays/hd42_only.yaml"]
    assert set(default_solve) == {"elements_over_height", "elements_over_thickness", "refinement", "symmetry",
                                  "flank_refinement"}
    table = tmp_path / "designs.parquet"
    import pyarrow as pa
    import pyarrow.parquet as pq
    pq.write_table(pa.table({"design_id": ["a"], "d_mm": [31.0], "D_mm": [42.0], "Gr_mm": [0.015],
                             "rFS_mm": [0.0], "rCS_mm": [0.0]}), table)
    effects = {"preload": {"interference_m": 0.3}, "flank_layer": {"thickness_m": 3800.0}}
    _, changes, geom = DesignJob(table, "a", "hd42", solve, 5, effects).model()
    assert (changes.flank_layer_fs_pass_only, geom.tip_round_m, geom.interference_m) == (True, 0.1, 0.3)
    _, changes, geom = DesignJob(table, "a", "hd42", default_solve, 5, effects).model()
    assert (changes.flank_layer_fs_pass_only, geom.tip_round_m) == (False, 0.0)
