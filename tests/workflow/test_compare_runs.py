"""benchmarks/compare_runs.py: two runs' Parquet tables compared exactly, timing columns aside."""

import importlib.util

import pandas as pd

from conftest import ROOT

spec = importlib.util.spec_from_file_location("compare_runs", ROOT / "benchmarks" / "compare_runs.py")
compare_runs = importlib.util.module_from_spec(spec)
spec.loader.exec_module(compare_runs)


def _run(root, phi, solve_s):
    table = root / "results/fe/hd42/lost_motion.parquet"
    table.parent.mkdir(parents=True)
    pd.DataFrame({"design_id": ["a", "b"], "lost_motion_arcmin": phi, "solve_s": solve_s}).to_parquet(table)
    return root


def test_timings_may_differ_a_result_may_not(tmp_path):
    """Two runs of the same code differ in their solve times only: equal. One ulp of Φ apart, or a
    table missing from the second run: reported, since 'every table equal' is what the check claims."""
    a = _run(tmp_path / "a", [0.3098, 0.2517], [9.1, 10.2])
    assert compare_runs.compare(a, _run(tmp_path / "b", [0.3098, 0.2517], [11.0, 12.5])) == (1, [])
    n, problems = compare_runs.compare(a, _run(tmp_path / "c", [0.3098, 0.2517 + 5e-17], [9.1, 10.2]))
    assert n == 1 and len(problems) == 1 and problems[0].startswith("differs: results/fe/hd42/lost_motion.parquet")
    (tmp_path / "d/results").mkdir(parents=True)
    assert compare_runs.compare(a, tmp_path / "d") == (0, [f"missing in {tmp_path / 'd'}: results/fe/hd42/lost_motion.parquet"])
