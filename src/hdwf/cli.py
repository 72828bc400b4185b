"""The ``hdwf`` command line: small tools around the Snakemake workflow."""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

from .errors import InputError


def _check_config(args) -> int:
    from .config import config_hash, load_config

    config = load_config(args.config, args.schema)
    print(f"{args.config}: valid; config hash {config_hash(config)}")
    return 0


def _provenance(args) -> int:
    from .config import load_config
    from .provenance import provenance

    config = load_config(args.config, args.schema)
    print(json.dumps(provenance(config, Path(args.config).resolve().parent), indent=2))
    return 0


def _synth(args) -> int:
    from .campaign import synthesize
    from .effects import parse_assignment
    from .io import atomic_path

    out = Path(args.out)
    if out.suffix.lower() not in (".csv", ".parquet"):
        raise InputError(out, f"unknown file type '{out.suffix}': write .csv or .parquet", field="--out")
    if out.exists() and not args.force:
        raise InputError(out, "exists; measurement files are never overwritten (use --force to replace it)",
                         field="--out")
    effects: dict[str, dict[str, float]] = {}
    for text in args.effect:
        try:
            name, pname, value = parse_assignment(text)
        except (KeyError, ValueError) as exc:
            raise InputError("command line", str(exc).strip("'\""), field="--effect", value=text) from None
        effects.setdefault(name, {})[pname] = value
    settings = {"elements_over_height": args.elements_over_height,
                "elements_over_thickness": args.elements_over_thickness,
                "refinement": args.refinement, "symmetry": "half"}
    try:
        data = synthesize(args.unit, args.designs, args.seed, args.noise_arcmin, effects, settings,
                          steps_per_ramp=args.steps_per_ramp, jobs=args.jobs)
    except ValueError as exc:
        raise InputError("command line", str(exc)) from None
    with atomic_path(out) as tmp:
        if out.suffix.lower() == ".csv":
            data.to_csv(tmp, index=False, float_format="%.9g")
        else:
            data.to_parquet(tmp, index=False)
    hidden = ", ".join(f"{n}:{p}={v:g}" for n, ps in effects.items() for p, v in ps.items()) or "none"
    print(f"{out}: {args.designs} specimens of {args.unit}, {len(data)} points; effects: {hidden}; "
          f"noise {args.noise_arcmin:g} arcmin (seed {args.seed})")
    return 0


def _effects(args) -> int:
    from .effects import registry

    for eff in registry().values():
        print(f"{eff.name}: {eff.title}{' (in series at the output)' if eff.series else ''}")
        for p in eff.parameters:
            print(f"    {p.name} [{p.unit}] in [{p.lower:g}, {p.upper:g}], realistic {p.realistic:g}"
                  + "".join(f" ({u}: {v:g})" for u, v in p.realistic_by_unit) + f": {p.description}")
        print(f"    signature: {eff.signature}")
    return 0


def _paper_measurements(args) -> int:
    from .io import atomic_path
    from .paper import paper_measurements

    out = Path(args.out)
    if out.exists() and not args.force:
        raise InputError(out, "exists; measurement files are never overwritten (use --force to replace it)",
                         field="--out")
    data = paper_measurements(args.data, args.unit)
    with atomic_path(out) as tmp:
        data.to_csv(tmp, index=False, float_format="%.10g")
    print(f"{out}: {len(data)} specimens of {args.unit} from the paper's Tables 4/5 (lost_motion form)")
    return 0


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(prog="hdwf", description="Harmonic-drive lost-motion study tools.")
    sub = parser.add_subparsers(dest="command", required=True)
    for name, func, help_ in (("check-config", _check_config, "validate a config file against the schema"),
                              ("provenance", _provenance, "print config hash, git commit and package versions")):
        p = sub.add_parser(name, help=help_)
        p.add_argument("config", nargs="?", default="config.yaml")
        p.add_argument("--schema", default="workflow/schemas/config.schema.yaml")
        p.set_defaults(func=func)
    p = sub.add_parser("paper-measurements", help="the paper's Tables 4/5 as a measurement file")
    p.add_argument("--unit", required=True, choices=["hd42", "hd120"])
    p.add_argument("--data", default="data/paper", help="folder of the paper's tables")
    p.add_argument("--out", required=True)
    p.add_argument("--force", action="store_true")
    p.set_defaults(func=_paper_measurements)
    p = sub.add_parser("effects", help="list the candidate physical effects and their parameters")
    p.set_defaults(func=_effects)
    p = sub.add_parser("synth", help="write synthetic lost-motion measurements from the FE model",
                       description="Synthetic measurements (curve form of docs/measurements.md) from the FE "
                                   "model at N Latin-hypercube specimens, with effects switched on and "
                                   "Gaussian noise added.")
    p.add_argument("--unit", required=True, choices=["hd42", "hd120"])
    p.add_argument("--designs", type=int, required=True, help="number of specimens")
    p.add_argument("--seed", type=int, required=True, help="seed of the designs and the noise")
    p.add_argument("--noise-arcmin", type=float, required=True, help="standard deviation of the noise")
    p.add_argument("--effect", action="append", default=[], metavar="NAME:PARAM=VALUE",
                   help="switch an effect on, e.g. tooth_friction:mu=0.08 (repeatable)")
    p.add_argument("--out", required=True, help="output file, .csv or .parquet (never overwritten)")
    p.add_argument("--force", action="store_true", help="replace an existing output file")
    p.add_argument("--elements-over-height", type=int, default=10)
    p.add_argument("--elements-over-thickness", type=int, default=6)
    p.add_argument("--refinement", type=float, default=1.0)
    p.add_argument("--steps-per-ramp", type=int, default=5)
    p.add_argument("--jobs", type=int, default=1, help="processes (one specimen each)")
    p.set_defaults(func=_synth)
    args = parser.parse_args(argv)
    try:
        return args.func(args)
    except InputError as exc:
        print(f"hdwf: error: {exc}", file=sys.stderr)
        return 2


if __name__ == "__main__":
    sys.exit(main())
