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
