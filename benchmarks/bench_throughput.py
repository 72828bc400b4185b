"""Throughput of per-design FE solves with 1 and with 2 Snakemake jobs at once.

Runs the first N designs of the `fe_at_paper` HD 42 study once, then times their jobs (mesh
and solve, forced reruns), first with --cores 1, then with --cores 2, each R times,
in a temporary copy of the workflow. Prints medians and the speed-up.
With ``--allocator`` it times --cores 2 instead, alternately with glibc's own handling of freed
memory (``HDWF_KEEP_FREED_MEMORY=0``) and with the Snakefile's (freed arrays kept in the heap),
and prints both medians and the jobs' summed system CPU.
Usage: .venv/bin/python benchmarks/bench_throughput.py [--designs 6] [--repeats 3] [--allocator]
"""

import argparse
import os
import resource
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _workspace import copy_workflow  # noqa: E402
SNAKEMAKE = str(Path(sys.executable).with_name("snakemake"))


def main():
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--designs", type=int, default=6)
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--allocator", action="store_true",
                        help="2 jobs at once with and without the Snakefile's malloc settings")
    args = parser.parse_args()
    with tempfile.TemporaryDirectory(prefix="hdwf-bench-") as tmp:
        tmp = Path(tmp)
        copy_workflow(tmp)
        targets = [f"results/fe_at_paper/hd42/designs/paper-{i:02d}.parquet" for i in range(1, args.designs + 1)]
        subprocess.run([SNAKEMAKE, *targets, "--cores", "2", "--quiet"], cwd=tmp, check=True)
        if args.allocator:
            return compare_allocator(tmp, targets, args)
        times = {1: [], 2: []}
        for _ in range(args.repeats):
            for cores in (1, 2):
                t0 = time.perf_counter()
                subprocess.run([SNAKEMAKE, *targets, "--cores", str(cores), "--quiet", "--forcerun", "fe_solve"],
                               cwd=tmp, check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
                times[cores].append(time.perf_counter() - t0)
    m1, m2 = statistics.median(times[1]), statistics.median(times[2])
    print(f"{args.designs} HD 42 solves; runs (s): 1 job {times[1]}, 2 jobs {times[2]}")
    print(f"median wall time: 1 job {m1:.1f} s, 2 jobs {m2:.1f} s")
    print(f"throughput 2 jobs / 1 job: {m1 / m2:.2f}x")


def compare_allocator(tmp: Path, targets: list[str], args) -> None:
    """Time --cores 2 runs alternately without (0) and with (1) the Snakefile's malloc settings."""
    times, system = {"0": [], "1": []}, {"0": [], "1": []}
    for _ in range(args.repeats):
        for keep in ("0", "1"):
            env = {k: v for k, v in os.environ.items() if not k.startswith("MALLOC_")}
            env["HDWF_KEEP_FREED_MEMORY"] = keep
            before = resource.getrusage(resource.RUSAGE_CHILDREN).ru_stime
            t0 = time.perf_counter()
            subprocess.run([SNAKEMAKE, *targets, "--cores", "2", "--quiet", "--forcerun", "fe_solve"],
                           cwd=tmp, env=env, check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
            times[keep].append(time.perf_counter() - t0)
            system[keep].append(resource.getrusage(resource.RUSAGE_CHILDREN).ru_stime - before)
    print(f"{args.designs} HD 42 solves, 2 jobs at once; runs (s): glibc's own {times['0']}, "
          f"freed memory kept {times['1']}")
    m0, m1 = statistics.median(times["0"]), statistics.median(times["1"])
    s0, s1 = statistics.median(system["0"]), statistics.median(system["1"])
    print(f"median wall time: glibc's own {m0:.1f} s, kept {m1:.1f} s ({(m0 - m1) / m0:+.1%} saved); "
          f"system CPU {s0:.1f} s against {s1:.1f} s")


if __name__ == "__main__":
    main()
