"""Shared by the rule scripts: log to the rule's log file, collect provenance, and build a
``snakemake`` object when a script is run by hand (``mock_snakemake``, as PyPSA-Eur does)."""

import logging
import os
from pathlib import Path

from hdwf.common.blas import one_thread_unless_set

# Snakemake gives a job the rule's one BLAS thread; a script run by hand would get one per core,
# which spin against any other work. Set before numpy loads (the scripts import this module first).
one_thread_unless_set()

from hdwf.common.provenance import provenance  # noqa: E402

PROJECT_ROOT = Path(__file__).resolve().parents[2]


def setup(snakemake):
    """Log to the rule's log file; return the provenance stamped on every artefact.

    The git commit is read from the checkout this script lives in, found from the script's own
    path, so no rule passes an absolute path as a parameter (a moved project plans no reruns).
    """
    logging.basicConfig(filename=snakemake.log[0], level=logging.INFO, force=True,
                        format="%(asctime)s %(levelname)s %(message)s")
    # scikit-fem logs every assembly at INFO: four lines a body, thousands in a campaign's log
    logging.getLogger("skfem").setLevel(logging.WARNING)
    return provenance(snakemake.config, PROJECT_ROOT)


def folder_of(paths) -> Path:
    """The one folder that holds the given input file(s): a rule declares the files it reads (so
    an edit re-runs it) and the library is given their folder."""
    paths = [paths] if isinstance(paths, (str, os.PathLike)) else list(paths)
    folders = {Path(p).parent for p in paths}
    if len(folders) != 1:
        raise ValueError(f"inputs {paths} are not in one folder")
    return folders.pop()


def mock_snakemake(rule: str, configfiles: list[str] | None = None, **wildcards):
    """The ``snakemake`` object Snakemake would give the script of ``rule`` for ``wildcards``.

    Lets a script run outside Snakemake (``python workflow/scripts/fe_solve.py``) to debug one
    step: the Snakefile is parsed with the project's config (and ``configfiles``) and the job is
    built for the given wildcards.  Like Snakemake, it leaves the script in the project root, so
    relative paths resolve from any folder it was started in.  Its inputs must exist (run
    Snakemake up to the rule first).
    """
    from snakemake.api import SnakemakeApi
    from snakemake.dag import DAG
    from snakemake.jobs import Job
    from snakemake.script import Snakemake
    from snakemake.settings.types import ConfigSettings, OutputSettings, ResourceSettings

    with SnakemakeApi(OutputSettings(quiet={"all"})) as api:
        workflow_api = api.workflow(
            resource_settings=ResourceSettings(cores=1),
            config_settings=ConfigSettings(configfiles=[Path(f).resolve() for f in configfiles or []]),
            snakefile=PROJECT_ROOT / "Snakefile", workdir=PROJECT_ROOT)
        workflow_api.dag()  # sets the workflow's DAG settings, which a Job needs
        workflow = workflow_api._workflow
        job = Job(workflow.get_rule(rule), DAG(workflow, rules=[workflow.get_rule(rule)]), wildcards)
        smk = Snakemake(job.input, job.output, job.params, job.wildcards, job.threads, job.resources,
                        job.log, workflow.config, job.rule.name, None)
    os.chdir(PROJECT_ROOT)  # the API returns to the caller's folder; Snakemake runs scripts here
    for f in [*smk.log, *smk.output]:
        Path(f).parent.mkdir(parents=True, exist_ok=True)
    return smk
