"""The study through a real Slurm cluster: one design's designs -> mesh-and-solve chain submitted
with `snakemake --profile profiles/slurm` gives the same Φ as the local run.

Brings no cluster up itself: `tools/slurm-cluster up` does (docs/slurm.md). Without a usable
cluster the test skips, saying why, unless HDWF_REQUIRE_SLURM=1 (CI), where it fails instead.
"""

import importlib.util
import os
import re
import shutil
import subprocess
import sys
from pathlib import Path

import pandas as pd
import pytest

from conftest import copy_workflow

SNAKEMAKE = str(Path(sys.executable).with_name("snakemake"))
DESIGN = "paper-08"
TARGET = f"results/fe_at_paper/hd42/designs/{DESIGN}.parquet"
PHI = ["phi_plus_arcmin", "phi_minus_arcmin", "lost_motion_arcmin"]
SUBMITTED = re.compile(r"Job \d+ has been submitted with SLURM jobid (\d+) \(log: (\S+)\)")


def _why_no_slurm():
    """Why this machine cannot run the test's Slurm jobs, or None when it can."""
    if importlib.util.find_spec("snakemake_executor_plugin_slurm") is None:
        return "snakemake-executor-plugin-slurm is not installed in this Python"
    if shutil.which("sinfo") is None:
        return "no `sinfo` on PATH: Slurm is not installed (`tools/slurm-cluster up` installs and starts one)"
    try:
        run = subprocess.run(["sinfo", "-h", "-N", "-o", "%N %t"], capture_output=True, text=True, timeout=30)
    except subprocess.TimeoutExpired:
        return "`sinfo` did not answer in 30 s (is slurmctld running? `tools/slurm-cluster status`)"
    if run.returncode != 0:
        return f"`sinfo` failed: {run.stderr.strip()[-300:]} (`tools/slurm-cluster up` starts a cluster)"
    states = [line.split() for line in run.stdout.splitlines() if line.strip()]
    if not any(s[1] in ("idle", "mix") for s in states if len(s) == 2):
        return f"no idle Slurm node (sinfo: {run.stdout.strip() or 'no nodes'}); `tools/slurm-cluster up` starts one"
    return None


@pytest.fixture
def slurm_cluster():
    reason = _why_no_slurm()
    if reason is None:
        return
    if os.environ.get("HDWF_REQUIRE_SLURM") == "1":
        pytest.fail(f"HDWF_REQUIRE_SLURM=1 but {reason}")
    pytest.skip(reason)


def _workspace(path):
    """A copy of the workflow with the profile, configured for one coarse FE study on one drive."""
    import yaml

    path.mkdir()
    copy_workflow(path, extra=("profiles/slurm",))
    config = yaml.safe_load((path / "config.yaml").read_text())
    study = config["studies"]["fe_at_paper"]
    config["studies"] = {"fe_at_paper": {**study, "units": ["hd42"]}}
    config["fe"].update(elements_over_height=4, elements_over_thickness=3, steps_per_ramp=1)
    config["fe"]["convergence"]["study"] = "fe_at_paper"
    config["fe"]["picture"].update(study="fe_at_paper", design=DESIGN)
    config["validation"] = {}
    (path / "config.yaml").write_text(yaml.safe_dump(config))
    return path


def _job_fields(jobid):
    run = subprocess.run(["scontrol", "show", "job", "-o", jobid], capture_output=True, text=True, timeout=30)
    assert run.returncode == 0, f"Slurm does not know job {jobid}: {run.stderr}"
    return dict(re.findall(r"(\w+)=(\S*)", run.stdout))


def _cancel_jobs_in(ws):
    """Cancel what a killed run left queued or running in Slurm (its jobs' working directory is ws)."""
    run = subprocess.run(["squeue", "-h", "-o", "%i %Z"], capture_output=True, text=True, timeout=30)
    ids = [i for i, _, wd in (line.partition(" ") for line in run.stdout.splitlines()) if wd == str(ws)]
    if ids:
        subprocess.run(["scancel", *ids], timeout=30)


@pytest.mark.slow
@pytest.mark.e2e
def test_one_design_through_slurm_matches_the_local_run(tmp_path, slurm_cluster):
    local_ws, slurm_ws = _workspace(tmp_path / "local"), _workspace(tmp_path / "slurm")
    # the local run goes on alongside the Slurm run, which mostly waits for the queue
    local_log = tmp_path / "local.log"
    with local_log.open("w") as out:
        local = subprocess.Popen([SNAKEMAKE, "--cores", "1", TARGET], cwd=local_ws, text=True, stdout=out,
                                 stderr=subprocess.STDOUT)
        try:
            # the profile as users run it, keeping the Slurm logs of successful jobs for the proof below;
            # the timeout (about 2 min are needed) catches a run that never sees its jobs finish
            slurm = subprocess.run(
                [SNAKEMAKE, "--profile", str(slurm_ws / "profiles/slurm"), "--slurm-keep-successful-logs", TARGET],
                cwd=slurm_ws, capture_output=True, text=True, timeout=300)
        except subprocess.TimeoutExpired:
            _cancel_jobs_in(slurm_ws)
            raise
        finally:
            local.wait(timeout=300)
    slurm_out = slurm.stdout + slurm.stderr
    assert local.returncode == 0, local_log.read_text()[-3000:]
    assert slurm.returncode == 0, slurm_out[-3000:]

    # Each FE job ran as a Slurm job: submitted by sbatch (the plugin says so), known to slurmctld
    # as completed in this workspace, and its Slurm log holds the job's own Snakemake output.
    submitted = dict(SUBMITTED.findall(slurm_out))
    by_rule = {}
    for jobid, log in submitted.items():
        rule = Path(log).relative_to(slurm_ws.resolve() / ".snakemake/slurm_logs").parts[0]
        by_rule[rule.removeprefix("rule_")] = (jobid, Path(log))
    assert "fe_solve" in by_rule, slurm_out[-3000:]
    for rule in ("fe_solve",):     # the one FE job (mesh and solve)
        jobid, log = by_rule[rule]
        job = _job_fields(jobid)
        assert job["JobState"] == "COMPLETED" and job["ExitCode"] == "0:0", job
        assert Path(job["WorkDir"]).resolve() == slurm_ws.resolve(), job
        assert job["Comment"] == f"rule_{rule}_wildcards_fe_at_paper_hd42_{DESIGN}", job
        assert log.name == f"{jobid}.log" and f"rule {rule}:" in log.read_text(), log

    # ... and gave the same Φ, to the last bit.
    row_local = pd.read_parquet(local_ws / TARGET).iloc[0]
    row_slurm = pd.read_parquet(slurm_ws / TARGET).iloc[0]
    assert row_local["design_id"] == row_slurm["design_id"] == DESIGN
    assert row_slurm["status"] == "ok"
    for col in PHI:
        assert row_slurm[col] == row_local[col], (col, row_slurm[col], row_local[col])
