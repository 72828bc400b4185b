"""`snakemake --lint` is clean but for the one lint the README justifies (no conda/container)."""

import re
import subprocess
import sys
from pathlib import Path

from conftest import ROOT

SNAKEMAKE = str(Path(sys.executable).with_name("snakemake"))
JUSTIFIED = {"Specify a conda environment or container for each rule."}


def test_lint_leaves_only_the_justified_lint():
    run = subprocess.run([SNAKEMAKE, "--lint"], cwd=ROOT, capture_output=True, text=True, timeout=300)
    text = run.stdout + run.stderr
    titles = set(re.findall(r"^    \* (.+?):?$", text, flags=re.M))
    assert titles == JUSTIFIED, text[-3000:]
    assert "conda" in (ROOT / "README.md").read_text().split("snakemake --lint", 1)[1][:1500]


def test_every_rule_a_cluster_runs_asks_for_its_memory_and_time():
    """Under the Slurm profile a rule that is not a ``localrules:`` rule is its own sbatch job: without
    ``mem_mb`` and ``runtime`` it gets the profile's 2000 MB and 20 min, which a finer-mesh solve or a
    campaign's diagnosis (some 160 re-solves) can outgrow, and Slurm kills it."""
    local = set(re.search(r"^localrules:(.+)$", (ROOT / "Snakefile").read_text(), flags=re.M).group(1)
                .replace(",", " ").split())
    rules = {}
    for smk in sorted((ROOT / "workflow" / "rules").glob("*.smk")):
        for name, body in re.findall(r"^rule (\w+):\n((?:[ \t]+.*\n|\n)*)", smk.read_text(), flags=re.M):
            rules[name] = body
    remote = {name: body for name, body in rules.items() if name not in local}
    assert {"fe_solve", "fe_refined_solve", "validation_diagnosis"} <= set(remote)
    missing = {name for name, body in remote.items()
               if not re.search(r"^\s+mem_mb=\d+", body, flags=re.M) or not re.search(r"^\s+runtime=\d+", body, flags=re.M)}
    assert not missing, f"rules run on the cluster without mem_mb and runtime: {sorted(missing)}"
