"""benchmarks/run_summary.py: a run's job benchmarks summed by part, and the time cores idled."""

import importlib.util
import os
import re
import sys

import pytest

from conftest import ROOT

spec = importlib.util.spec_from_file_location("run_summary", ROOT / "benchmarks" / "run_summary.py")
run_summary = importlib.util.module_from_spec(spec)
sys.modules["run_summary"] = run_summary     # its dataclasses look their module up
spec.loader.exec_module(run_summary)

HEADER = "s\th:m:s\tmax_rss\tmax_vms\tmax_uss\tmax_pss\tio_in\tio_out\tmean_load\tcpu_time\n"


def _benchmark(results, rel, seconds, end, max_rss=100.0):
    path = results / rel
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(HEADER + f"{seconds}\t0:00:00\t{max_rss}\t0\t0\t0\t0\t0\t0\t0\n")
    os.utime(path, (end, end))


def _rule_benchmarks():
    """Every ``benchmark:`` path of the workflow's rules, its wildcards filled in."""
    text = "\n".join(p.read_text() for p in sorted((ROOT / "workflow" / "rules").glob("*.smk")))
    paths = re.findall(r'benchmark:\s*\n\s*"([^"]+)"', text)
    values = {"study": "fe", "unit": "hd42", "design": "hd42-lhs-01", "ref": "1.25",
              "campaign": "paper_hd42", "specimen": "paper-01"}
    return [re.sub(r"\{(\w+)\}", lambda m: values[m.group(1)], p) for p in paths]


def test_every_rule_benchmark_has_the_part_its_rule_belongs_to():
    paths = _rule_benchmarks()
    assert len(paths) == 17       # one per rule with a benchmark (workflow/rules/*.smk)
    parts = {p: run_summary.part_of(p.removeprefix("results/")) for p in paths}
    assert parts["results/fe/hd42/benchmarks/solve_hd42-lhs-01.tsv"] == "studies"
    assert parts["results/benchmarks/fe_hd42_convergence_r1.25_hd42-lhs-01.tsv"] == "mesh convergence"
    assert parts["results/validation/paper_hd42/benchmarks/paper-01.tsv"] == "specimens paper_hd42"
    assert parts["results/validation/paper_hd42/benchmarks/diagnosis.tsv"] == "diagnosis paper_hd42"
    assert parts["results/validation/paper_hd42/benchmarks/ladder.tsv"] == "ladder paper_hd42"
    assert parts["results/benchmarks/fe_hd42_sobol.tsv"] == "Sobol'"
    # the convergence table, the aggregation and the rest are bookkeeping, not solves
    assert parts["results/benchmarks/fe_hd42_convergence.tsv"] == "other"
    assert sum(v == "other" for v in parts.values()) == 17 - 6


def test_job_seconds_by_part_and_the_time_fewer_jobs_ran_than_cores(tmp_path):
    results = tmp_path / "results"
    t0 = 1.0e9
    # two solves overlapping from 5 to 10 s, then a Sobol' job alone from 20 to 26 s
    _benchmark(results, "fe/hd42/benchmarks/solve_a.tsv", 10.0, t0 + 10, max_rss=500)
    _benchmark(results, "fe/hd120/benchmarks/solve_b.tsv", 15.0, t0 + 20, max_rss=800)
    _benchmark(results, "benchmarks/fe_hd42_sobol.tsv", 6.0, t0 + 26, max_rss=300)
    (results / "fe" / "hd42" / "lost_motion.tsv").write_text("a\tb\n1\t2\n")   # not a benchmark
    run = run_summary.summarise(run_summary.read_jobs(results), cores=2)
    by_part = {p.part: p for p in run.parts}
    assert set(by_part) == {"studies", "Sobol'"}
    assert by_part["studies"].jobs == 2
    assert by_part["studies"].job_seconds == pytest.approx(25.0)
    assert by_part["studies"].median_s == pytest.approx(12.5)
    assert by_part["studies"].max_rss_mb == 800 and by_part["studies"].largest_job.endswith("solve_b.tsv")
    assert run.job_seconds == pytest.approx(31.0)
    # span 0 -> 26 s; two jobs ran only from 5 to 10 s, so fewer than two for 21 s
    assert run.span_s == pytest.approx(26.0)
    assert run.below_cores_s == pytest.approx(21.0)


def test_a_results_folder_without_benchmarks_is_refused(tmp_path):
    (tmp_path / "results").mkdir()
    with pytest.raises(SystemExit, match="no Snakemake benchmark files"):
        run_summary.read_jobs(tmp_path / "results")
