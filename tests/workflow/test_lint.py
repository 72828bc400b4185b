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
