"""Wall time of one validation campaign of N specimens, every candidate diagnosed, through
diagnosis.json and the ladder (`snakemake --cores 2`), at the study's default mesh.

The measurement file is synthesised first (not timed) with `hdwf synth` at the same mesh,
with a hidden effect; each run then works in a fresh copy of the workflow with an empty
results/, so nothing is reused between runs. The per-specimen benchmark files give the
time of each specimen job.
The diagnosis job's time includes the re-solves of an effect found before round 2.
Usage: .venv/bin/python benchmarks/bench_campaign.py [--specimens 27] [--runs 1]
"""

import argparse
import json
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import pandas as pd
import yaml

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _workspace import copy_workflow  # noqa: E402
BIN = Path(sys.executable).parent


def one_run(data: Path, n: int) -> tuple[float, dict, list[float], dict[str, float]]:
    with tempfile.TemporaryDirectory(prefix="hdwf-bench-") as tmp:
        tmp = Path(tmp)
        copy_workflow(tmp)
        shutil.copy(data, tmp / "data/validation/bench.csv")
        cfg = yaml.safe_load((tmp / "config.yaml").read_text())
        cfg["validation"] = {"bench": {"unit": "hd42", "measurements": "data/validation/bench.csv"}}
        (tmp / "config.yaml").write_text(yaml.safe_dump(cfg))
        t0 = time.perf_counter()
        subprocess.run([str(BIN / "snakemake"), "--cores", "2",
                        "results/validation/bench/diagnosis.json", "results/validation/bench/ladder.parquet",
                        "--quiet"],
                       cwd=tmp, check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        wall = time.perf_counter() - t0
        diag = json.loads((tmp / "results/validation/bench/diagnosis.json").read_text())
        times = {p.stem: float(pd.read_csv(p, sep="\t")["s"].iloc[0])
                 for p in (tmp / "results/validation/bench/benchmarks").glob("*.tsv")}
        # the diagnosis job includes the re-solves before round 2; the ladder its own solves
        stages = {k: times.pop(k) for k in ("diagnosis", "ladder") if k in times}
        return wall, diag, list(times.values()), stages


def main():
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--specimens", type=int, default=27)
    parser.add_argument("--runs", type=int, default=1)
    args = parser.parse_args()
    with tempfile.TemporaryDirectory(prefix="hdwf-bench-data-") as d:
        data = Path(d) / "bench.csv"
        subprocess.run([str(BIN / "hdwf"), "synth", "--unit", "hd42", "--designs", str(args.specimens),
                        "--seed", "7", "--noise-arcmin", "0.05", "--effect", "thermal:delta_T_K=10",
                        "--jobs", "2", "--out", str(data)], check=True)
        results = [one_run(data, args.specimens) for _ in range(args.runs)]
    walls = [r[0] for r in results]
    _, diag, jobs, stages = results[-1]
    print("runs (s):", " ".join(f"{t:.1f}" for t in walls))
    print(f"median: {statistics.median(walls):.1f} s for {args.specimens} specimens, "
          f"{len(diag['ranking'])} candidates, {len(diag['rounds'])} round(s)")
    print(f"specimen job (s): median {statistics.median(jobs):.1f}, max {max(jobs):.1f}; "
          + ", ".join(f"{k} job {v:.1f} s" for k, v in stages.items()))
    print("re-solved before the next round:", diag.get("refinement") or "nothing")
    print("verdict:", diag["verdict"]["text"], "| found:", diag["verdict"]["found_in_order"])


if __name__ == "__main__":
    main()
