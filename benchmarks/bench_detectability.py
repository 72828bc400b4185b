"""Which noise does each candidate effect need to be found? Measured against predicted.

For every candidate effect at its realistic value (and for no effect), the FE model makes
the curves of N HD 42 specimens once (coarse test mesh, as in tests/validation/hidden_setup.py);
Gaussian noise of several levels, with several seeds, is added; each data set is diagnosed
(one round). A row counts how often the effect was named (first, or among the
indistinguishable), how often its parameter came back within 15 %, and whether the
diagnosis's own detectability estimate (``diagnosis.json: detectability``) said this data
could show the effect. The model tables (campaign model and every candidate's grid) are
solved once and shared, as in a campaign.

Usage: .venv/bin/python benchmarks/bench_detectability.py [--specimens 12] [--seeds 3]
       [--noise-pct 2 0.5 0.2 0.1] [--steps-per-ramp 5] [--range rFS_mm=0:0.002 ...]
       [--out detectability.json]
"""

import argparse
import json
import statistics
import tempfile
import time
from pathlib import Path

import numpy as np

from hdwf.common.io import atomic_path
from hdwf.validation.diagnosis import Search, diagnose
from hdwf.validation.effects import registry
from hdwf.validation.measurements import load_measurements
from hdwf.validation.synthesis import add_noise, design_ranges, format_ranges, parse_range, synth_curves, synth_designs
from hdwf.validation.variants import SolveSetup, candidate_names, mean_lost_motion, plan_variants, specimen_solver

UNIT = "hd42"
DESIGN_SEED = 11
SETTINGS = dict(elements_over_height=5, elements_over_thickness=3, refinement=1.0, symmetry="half")


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--specimens", type=int, default=12)
    parser.add_argument("--seeds", type=int, default=3)
    parser.add_argument("--noise-pct", type=float, nargs="+", default=[2.0, 0.5, 0.2, 0.1],
                        help="noise levels in %% of the mean lost motion of the specimens")
    parser.add_argument("--steps-per-ramp", type=int, default=5,
                        help="points per curve = 4 x this + 1")
    parser.add_argument("--range", action="append", default=[], metavar="NAME=LOW:HIGH",
                        help="a batch instead of the paper's design space, e.g. rFS_mm=0:0.002 (repeatable)")
    parser.add_argument("--jobs", type=int, default=2)
    parser.add_argument("--out", type=Path, help="write the rows as JSON here")
    args = parser.parse_args()

    try:
        ranges = {name: (lo, hi) for name, lo, hi in map(parse_range, args.range)}
        design_ranges(UNIT, ranges)
    except ValueError as exc:
        parser.error(f"--range: {exc}")
    t0 = time.perf_counter()
    specimens = synth_designs(UNIT, args.specimens, DESIGN_SEED, ranges)
    plan = plan_variants({})
    setup = SolveSetup(UNIT, SETTINGS, args.steps_per_ramp, args.jobs)
    tables = specimen_solver(setup, specimens)(plan)
    signal = mean_lost_motion(tables)
    print(f"tables: {time.perf_counter() - t0:.0f} s; mean lost motion {signal:.3f} arcmin")

    rows = []
    with tempfile.TemporaryDirectory(prefix="hdwf-detect-") as tmp:
        for effect in [None, *sorted(candidate_names({}))]:   # the ones a campaign tries by default
            hidden = {}
            if effect:
                p = registry()[effect].parameters[0]
                hidden = {effect: {p.name: p.realistic}}
            clean = synth_curves(setup, args.specimens, DESIGN_SEED, hidden, ranges)
            for pct in args.noise_pct:
                noise = pct / 100 * signal
                named = recovered = 0
                predicted, errs, secs = [], [], []
                for seed in range(1, args.seeds + 1):
                    path = Path(tmp) / f"{effect}-{pct}-{seed}.csv"
                    add_noise(clean, noise, seed).to_csv(path, index=False)
                    t1 = time.perf_counter()
                    diag = diagnose(load_measurements(path), tables, Search(max_rounds=1)).to_dict()
                    secs.append(time.perf_counter() - t1)
                    v = diag["verdict"]
                    if effect is None:
                        named += v["missing_effect"] is None        # "named" = rightly silent
                        continue
                    # the estimate itself (noise stated in the data), not could_not_see, which
                    # leaves out effects that were found and so would agree by construction
                    seen = next(c for c in diag["detectability"]["candidates"] if c["effect"] == effect)
                    predicted.append(seen["visible"])
                    if v["missing_effect"] == effect or effect in v["indistinguishable_from"]:
                        named += 1
                        est = next(r for r in diag["ranking"] if r["effect"] == effect)["params"][p.name]
                        errs.append(abs(est / p.realistic - 1))
                        recovered += errs[-1] <= 0.15
                row = {"effect": effect or "none", "noise_pct": pct, "noise_arcmin": noise, "seeds": args.seeds,
                       "named": named, "recovered_15pct": recovered if effect else None,
                       "median_rel_error": statistics.median(errs) if errs else None,
                       "predicted_visible": (sum(predicted) / len(predicted)) if predicted else None,
                       "diagnose_s": statistics.median(secs)}
                if effect:      # the estimate depends on the stated noise only: the same for every seed
                    row.update(expected_rel_sd=seen["expected_rel_sd"], noise_to_show_arcmin=seen["noise_to_show_arcmin"],
                               change_rms_arcmin=seen["change_rms_arcmin"])
                rows.append(row)
                print(json.dumps(row))

    print(f"\nmean lost motion {signal:.3f} arcmin, {args.specimens} specimens of "
          f"{4 * args.steps_per_ramp + 1} points{format_ranges(ranges)}, "
          f"{args.seeds} seeds, "
          f"total {time.perf_counter() - t0:.0f} s\n")
    print("| effect | noise (% / arcmin) | predicted visible | named | within 15 % | expected rel. sd |")
    print("|---|---|---|---|---|---|")
    for r in rows:
        vis = "–" if r["predicted_visible"] is None else f"{r['predicted_visible']:.0%}"
        sd = "–" if r.get("expected_rel_sd") is None else f"{r['expected_rel_sd']:.0%}"
        rec = "–" if r["recovered_15pct"] is None else f"{r['recovered_15pct']}/{r['seeds']}"
        name = f"{r['named']}/{r['seeds']}" + (" silent" if r["effect"] == "none" else "")
        print(f"| {r['effect']} | {r['noise_pct']:g} / {r['noise_arcmin']:.4f} | {vis} | {name} | {rec} | {sd} |")
    if args.out:
        with atomic_path(args.out) as tmp_out:
            tmp_out.write_text(json.dumps({"signal_arcmin": signal, "steps_per_ramp": args.steps_per_ramp, "ranges": ranges,
                                           "rows": rows}, indent=1, default=float))


if __name__ == "__main__":
    np.seterr(all="ignore")
    main()
