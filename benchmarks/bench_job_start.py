"""How long a rule script's imports take: what every job of that rule spends before its work.

For each script, runs a fresh Python that executes the script's own ``import``/``from`` lines
(with ``workflow/scripts`` on the path, as Snakemake runs it) and then Snakemake's script
module, R times, alternating between the scripts; prints the median, min and max wall time and
which heavy libraries the imports pulled in (docs/fe-model.md, Time). Warm file cache: the first
round is not counted.

Usage: .venv/bin/python benchmarks/bench_job_start.py [--repeats 7] [script.py ...]
(default: the per-design and per-specimen solve scripts, and one stage that needs pandas)
"""

from __future__ import annotations

import argparse
import statistics
import subprocess
import sys
import time

from _workspace import ROOT

SCRIPTS = ROOT / "workflow" / "scripts"
DEFAULT = ("fe_solve.py", "fe_refined_solve.py", "validation_specimen.py", "fe_aggregate.py")
HEAVY = ("pandas", "scipy.optimize", "matplotlib", "statsmodels")


def import_code(script: str) -> str:
    """Python that imports what ``script`` imports, then reports the heavy libraries loaded."""
    source = (SCRIPTS / script).read_text()
    imports = [line for line in source.splitlines() if line.startswith(("import ", "from "))]
    return "\n".join(["import sys", f"sys.path.insert(0, {str(SCRIPTS)!r})", *imports, "import snakemake.script",
                      f"print(','.join(m for m in {HEAVY!r} if m in sys.modules))"])


def time_once(code: str) -> tuple[float, str]:
    t0 = time.perf_counter()
    run = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    return time.perf_counter() - t0, run.stdout.strip()


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("scripts", nargs="*", default=DEFAULT)
    ap.add_argument("--repeats", type=int, default=7)
    args = ap.parse_args()
    missing = [s for s in args.scripts if not (SCRIPTS / s).is_file()]
    if missing:
        raise SystemExit(f"no such script in {SCRIPTS}: {missing}")
    codes = {s: import_code(s) for s in args.scripts}
    times: dict[str, list[float]] = {s: [] for s in args.scripts}
    loaded = {}
    for round_ in range(args.repeats + 1):
        for s, code in codes.items():
            t, loaded[s] = time_once(code)
            if round_:
                times[s].append(t)
    print(f"{'script':<26} {'median s':>8} {'min s':>6} {'max s':>6}  heavy libraries imported")
    for s in args.scripts:
        ts = times[s]
        print(f"{s:<26} {statistics.median(ts):8.3f} {min(ts):6.3f} {max(ts):6.3f}  {loaded[s] or '-'}")


if __name__ == "__main__":
    main()
