"""Where a finished workflow run spent its time: its jobs' Snakemake benchmarks summed by part.

Reads every job benchmark (``*.tsv``) under a project's ``results/`` and prints, per part of
the default target (the FE studies' solves, their mesh-convergence solves, each campaign's
specimens, diagnosis and ladder, the Sobol' jobs, the rest): jobs, job-seconds (the sum of
the benchmarks' wall time ``s``), the median job and the largest ``max_rss``. Then the run as a
whole: its span (first job start to last job end, a start being the benchmark file's
modification time minus its ``s``, as Snakemake writes the file when the job ends) and how long
fewer jobs ran than ``--cores``. Job-seconds are what the cores had to do; when they never
idle, the span is job-seconds / cores.

Usage: .venv/bin/python benchmarks/run_summary.py [PROJECT_ROOT] [--cores 2]
"""

from __future__ import annotations

import argparse
import re
import statistics
from dataclasses import dataclass
from pathlib import Path

import pandas as pd

# a benchmark's path under results/ -> its part (first match wins); each names the rule's
# ``benchmark:`` pattern of workflow/rules/*.smk
PARTS = (
    ("studies", re.compile(r"^[^/]+/[^/]+/benchmarks/solve_[^/]+\.tsv$")),
    ("mesh convergence", re.compile(r"^benchmarks/[^/]+_convergence_r[^/]+\.tsv$")),
    ("diagnosis {0}", re.compile(r"^validation/([^/]+)/benchmarks/diagnosis\.tsv$")),
    ("ladder {0}", re.compile(r"^validation/([^/]+)/benchmarks/ladder\.tsv$")),
    ("specimens {0}", re.compile(r"^validation/([^/]+)/benchmarks/[^/]+\.tsv$")),
    ("Sobol'", re.compile(r"^benchmarks/[^/]+_sobol\.tsv$")),
)
OTHER = "other"


@dataclass(frozen=True)
class Job:
    """One job's benchmark: where it lies under results/, its part, wall time, end and memory."""
    path: str
    part: str
    seconds: float
    end: float          # the benchmark file's modification time (epoch seconds)
    max_rss_mb: float

    @property
    def start(self) -> float:
        return self.end - self.seconds


@dataclass(frozen=True)
class PartSummary:
    part: str
    jobs: int
    job_seconds: float
    median_s: float
    max_rss_mb: float
    largest_job: str


@dataclass(frozen=True)
class RunSummary:
    parts: list[PartSummary]
    job_seconds: float
    span_s: float
    below_cores_s: float      # seconds of the span with fewer jobs running than cores
    cores: int


def part_of(relative: str) -> str:
    """The part of a benchmark at ``relative`` (a path under results/, with forward slashes)."""
    for name, pattern in PARTS:
        m = pattern.match(relative)
        if m:
            return name.format(*m.groups())
    return OTHER


def read_jobs(results: Path) -> list[Job]:
    """Every job benchmark under ``results`` (a Snakemake benchmark file: one header, one row per
    repeat; the first row is the run)."""
    jobs = []
    for path in sorted(results.rglob("*.tsv")):
        frame = pd.read_csv(path, sep="\t")
        if "s" not in frame.columns or frame.empty:
            continue   # not a Snakemake benchmark
        rel = path.relative_to(results).as_posix()
        rss = float(frame["max_rss"].iloc[0]) if "max_rss" in frame.columns else float("nan")
        jobs.append(Job(rel, part_of(rel), float(frame["s"].iloc[0]), path.stat().st_mtime, rss))
    if not jobs:
        raise SystemExit(f"{results}: no Snakemake benchmark files (*.tsv with a column 's')")
    return jobs


def time_below(jobs: list[Job], cores: int) -> tuple[float, float]:
    """The span of ``jobs`` and the seconds of it during which fewer than ``cores`` ran."""
    events = sorted([(j.start, 1) for j in jobs] + [(j.end, -1) for j in jobs])
    running, below, last = 0, 0.0, events[0][0]
    for t, step in events:
        if running < cores:
            below += t - last
        running, last = running + step, t
    return events[-1][0] - events[0][0], below


def summarise(jobs: list[Job], cores: int) -> RunSummary:
    parts = []
    for part in sorted({j.part for j in jobs}, key=lambda p: (p == OTHER, p)):
        mine = [j for j in jobs if j.part == part]
        largest = max(mine, key=lambda j: j.max_rss_mb)
        parts.append(PartSummary(part, len(mine), sum(j.seconds for j in mine),
                                 statistics.median(j.seconds for j in mine), largest.max_rss_mb, largest.path))
    span, below = time_below(jobs, cores)
    return RunSummary(parts, sum(j.seconds for j in jobs), span, below, cores)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("root", nargs="?", default=".", help="the project root whose results/ to read")
    ap.add_argument("--cores", type=int, default=2, help="the --cores the run was given")
    a = ap.parse_args()
    run = summarise(read_jobs(Path(a.root) / "results"), a.cores)
    print(f"{'part':<28} {'jobs':>5} {'job-s':>8} {'median s':>9} {'max_rss GB':>11}  largest job")
    for p in run.parts:
        print(f"{p.part:<28} {p.jobs:>5} {p.job_seconds:>8.0f} {p.median_s:>9.1f} {p.max_rss_mb / 1024:>11.2f}  {p.largest_job}")
    print(f"{'all':<28} {sum(p.jobs for p in run.parts):>5} {run.job_seconds:>8.0f}")
    print(f"span {run.span_s / 60:.2f} min (first job start to last job end); fewer than {run.cores} jobs "
          f"running for {run.below_cores_s:.0f} s; job-seconds / cores = {run.job_seconds / run.cores / 60:.2f} min")


if __name__ == "__main__":
    main()
