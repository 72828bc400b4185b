"""The ``hdwf`` command line: small tools around the Snakemake workflow."""

from __future__ import annotations

import argparse
import dataclasses
import json
import math
import os
import sys
from contextlib import contextmanager
from pathlib import Path

from hdwf.common.blas import one_thread_unless_set

one_thread_unless_set()   # before numpy loads: the command's solves run like Snakemake's jobs

from hdwf import __version__  # noqa: E402
from hdwf.common.errors import ConfigError, InputError, SolveFailed  # noqa: E402
from hdwf.common.io import atomic_path, write_parquet  # noqa: E402
from hdwf.common.provenance import config_hash, provenance, tool_provenance  # noqa: E402
from hdwf.config import SCHEMA_PATH, blame, fe_option_bounds, load_config  # noqa: E402
from hdwf.stages.validation import campaign_plan, campaign_specimens  # noqa: E402
from hdwf.study.paper import PAPER_TABLES, paper_measurements  # noqa: E402
from hdwf.validation.detectability import plan_detectability  # noqa: E402
from hdwf.validation.effects import parse_assignment, registry  # noqa: E402
from hdwf.common.jsonsafe import json_safe  # noqa: E402
from hdwf.validation.measurements import MeasurementError, load_measurements, schedule_problems  # noqa: E402
from hdwf.validation.synthesis import design_ranges, format_ranges, parse_range, synth_designs, synthesize  # noqa: E402
from hdwf.validation.variants import SolveSetup  # noqa: E402


def _count(n: int, noun: str) -> str:
    return f"{n} {noun}{'' if n == 1 else 's'}"


def _print_problems(exc: MeasurementError, prefix: str = "") -> None:
    """Every problem of a measurement file on a line of its own (the exception's text stops at 25)."""
    for line in exc.lines:
        print(f"hdwf: error: {prefix}{line}", file=sys.stderr)


def project_root(config_path: str | Path) -> Path:
    """Where a config's relative paths start, as Snakemake reads them: the nearest folder at or above
    the config's that holds a Snakefile (``--configfile configs/x.yaml`` run from the project), else
    the config's own folder."""
    folder = Path(config_path).resolve().parent
    for candidate in (folder, *folder.parents):
        if (candidate / "Snakefile").is_file():
            return candidate
    return folder


def _check_config(args) -> int:
    # a config problem is the file's, as a measurement file's is (exit 1); 2 is for the command line
    try:
        config = load_config(args.config, args.schema)
    except ConfigError as exc:
        print(f"hdwf: error: {exc}", file=sys.stderr)
        if len(args.config) == 1 and exc.field == "(top level)" and "required property" in exc.problem:
            print(f"hdwf: hint: an overlay (a campaign's file) is checked over its base: hdwf check-config config.yaml "
                  f"{args.config[0]}", file=sys.stderr)
        return 1
    print(f"{' + '.join(args.config)}: valid; config hash {config_hash(config)}")
    # each campaign's measurement file as the workflow will read it, before any solve
    root = project_root(args.config[0])
    failed = False
    for name, camp in config.get("validation", {}).items():
        plan = campaign_plan(name, camp, config["fe"])
        try:
            specimens = campaign_specimens(dataclasses.replace(plan, measurements=str(root / plan.measurements)))
        except MeasurementError as exc:
            failed = True
            _print_problems(exc, f"campaign '{name}': ")
            continue
        print(f"campaign '{name}': {plan.measurements}: {_count(len(specimens), 'specimen')} of {plan.unit}: ok")
    # the studies and the report read the paper's tables: a wrong folder fails only at run time
    missing = [table for table in PAPER_TABLES if not (root / config["paper_data"] / table).is_file()]
    if missing:
        failed = True
        error = InputError(blame(args.config, "paper_data"), f"no {', '.join(missing)} in {root / config['paper_data']} (the paper's "
                                        "tables, which the studies and the report read)",
                           field="paper_data", value=config["paper_data"])
        print(f"hdwf: error: {error}", file=sys.stderr)
    else:
        print(f"paper_data: {config['paper_data']}: the paper's {len(PAPER_TABLES)} tables: ok")
    return 1 if failed else 0


def _provenance(args) -> int:
    config = load_config(args.config, args.schema)
    print(json.dumps(provenance(config, project_root(args.config[0])), indent=2))
    return 0


def _refuse_existing(out: Path, args, why: str = "") -> None:
    """An existing output file is kept unless --force says otherwise; a folder is never replaced.
    Its folder is checked too, before a long solve, not after it."""
    if out.is_dir():
        raise InputError(out, "is a folder: name the output file", field="--out")
    if (out.exists() or out.is_symlink()) and not args.force:
        raise InputError(out, f"exists; {why}use --force to replace it", field="--out")
    _check_folder(out)


def _check_folder(out: Path) -> None:
    """The nearest existing folder above ``out`` must be a folder this process can write in."""
    parent = out.absolute().parent
    while not parent.exists():
        parent = parent.parent
    if not parent.is_dir():
        raise InputError(out, f"cannot be written: {parent} is a file, not a folder", field="--out")
    if not os.access(parent, os.W_OK | os.X_OK):
        raise InputError(out, f"cannot be written: no permission to write in {parent}", field="--out")


@contextmanager
def _new_output(out: Path, args):
    """``atomic_path`` that replaces only with --force: a file made at ``out`` while a long solve ran
    (after ``_refuse_existing`` looked) is kept too."""
    _check_folder(out)
    try:
        with atomic_path(out, replace=args.force) as tmp:
            yield tmp
    except FileExistsError as exc:
        if not (out.exists() or out.is_symlink()):
            raise InputError(out, f"cannot be written: {_os_reason(exc)}", field="--out") from None
        raise InputError(out, "was made by something else while this ran: it is kept and nothing was written; "
                              "use --force to replace it", field="--out") from None
    except OSError as exc:
        raise InputError(out, f"cannot be written: {_os_reason(exc)}", field="--out") from None


def _os_reason(exc: OSError) -> str:
    """The system's reason and the path it names, e.g. ``No such file or directory (/proc/x)``."""
    where = f" ({exc.filename})" if exc.filename else ""
    return f"{exc.strerror or exc}{where}"


def _solve_setup(args) -> SolveSetup:
    """How the synth/plan solves run (half model) from their options."""
    mesh = {"elements_over_height": args.elements_over_height,
            "elements_over_thickness": args.elements_over_thickness,
            "refinement": args.refinement, "symmetry": "half"}
    return SolveSetup(args.unit, mesh, args.steps_per_ramp, args.jobs, progress=True)


def _bounded(kind: type, low: float, high: float, low_open: bool = False):
    """An argparse type: a finite ``kind`` within [low, high] (low excluded if ``low_open``), the
    same limits the config schema sets, refused with the value named."""
    def parse(text: str):
        try:
            value = kind(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"{text!r} is not {'a whole number' if kind is int else 'a number'}")
        if not math.isfinite(value) or value < low or (low_open and value == low) or value > high:
            span = f"{'(' if low_open else '['}{kind(low)}, {kind(high)}]"
            raise argparse.ArgumentTypeError(f"{text!r} is outside {span}")
        return value
    return parse


def _fe_option(kind: type, name: str):
    """An argparse type bounded as the config schema bounds ``fe.<name>``."""
    return _bounded(kind, *fe_option_bounds(name))


def _specimen_options(p, seed_help: str, noise_help: str) -> None:
    p.add_argument("--unit", required=True, choices=["hd42", "hd120"])
    p.add_argument("--designs", type=_bounded(int, 1, 1000), required=True, help="number of specimens")
    p.add_argument("--seed", type=_bounded(int, 0, 2 ** 32 - 1), required=True, help=seed_help)
    p.add_argument("--noise-arcmin", type=_bounded(float, 0, 60), required=True, help=noise_help)
    p.add_argument("--range", action="append", default=[], metavar="NAME=LOW:HIGH",
                   help="sample this parameter over LOW..HIGH instead of the paper's Table 3 range, e.g. "
                        "rFS_mm=0:0.002 for a batch of accuracy-grade drives (repeatable)")


def _design_ranges(args) -> dict[str, tuple[float, float]]:
    """The --range options as {column: (low, high)}, checked against the model's support."""
    ranges = {}
    for text in args.range:
        try:
            name, low, high = parse_range(text)
            if name in ranges:
                raise ValueError(f"{name} is given a range twice")
            design_ranges(args.unit, {name: (low, high)})
        except ValueError as exc:
            raise InputError("command line", str(exc), field="--range", value=text) from None
        ranges[name] = (low, high)
    return ranges


def _solve_options(p, elements_over_height: int, elements_over_thickness: int, mesh_is: str) -> None:
    p.add_argument("--elements-over-height", type=_fe_option(int, "elements_over_height"),
                   default=elements_over_height,
                   help=f"elements over a tooth's height (default %(default)s: {mesh_is})")
    p.add_argument("--elements-over-thickness", type=_fe_option(int, "elements_over_thickness"),
                   default=elements_over_thickness,
                   help=f"elements over a tooth's thickness (default %(default)s: {mesh_is})")
    p.add_argument("--refinement", type=_fe_option(float, "refinement"), default=1.0,
                   help="multiplies both element counts (default %(default)s)")
    p.add_argument("--steps-per-ramp", type=_fe_option(int, "steps_per_ramp"), default=5,
                   help="load steps on each ramp of 0 -> +T -> 0 -> -T -> 0 (default %(default)s)")
    p.add_argument("--jobs", type=_bounded(int, 1, 256), default=1,
                   help="processes, one specimen each (default %(default)s)")


def _synth(args) -> int:
    out = Path(args.out)
    if out.suffix.lower() not in (".csv", ".parquet"):
        raise InputError(out, f"unknown file type '{out.suffix}': write .csv or .parquet", field="--out")
    _refuse_existing(out, args, "measurement files are never overwritten: ")
    ranges = _design_ranges(args)
    effects: dict[str, dict[str, float]] = {}
    for text in args.effect:
        try:
            name, pname, value = parse_assignment(text)
        except (KeyError, ValueError) as exc:
            problem = str(exc).strip("'\"").removeprefix(f"--effect {text!r}: ")   # the field and value say that
            raise InputError("command line", problem, field="--effect", value=text) from None
        if pname in effects.get(name, {}):
            raise InputError("command line", f"{name}:{pname} is given twice", field="--effect", value=text)
        effects.setdefault(name, {})[pname] = value
    try:
        data = synthesize(_solve_setup(args), args.designs, args.seed, args.noise_arcmin, effects, ranges)
    except ValueError as exc:
        raise InputError("command line", str(exc)) from None
    with _new_output(out, args) as tmp:
        if out.suffix.lower() == ".csv":
            data.to_csv(tmp, index=False, float_format="%.9g")
        else:   # Parquet carries what made it; a CSV stays plain, as bench files are
            settings = {"unit": args.unit, "designs": args.designs, "seed": args.seed,
                        "noise_arcmin": args.noise_arcmin, "effects": effects,
                        "ranges": {k: list(v) for k, v in ranges.items()},
                        "mesh": _solve_setup(args).mesh, "steps_per_ramp": args.steps_per_ramp}
            write_parquet(data, tmp, provenance=tool_provenance(settings), meta={"hdwf_synth": settings})
    hidden = ", ".join(f"{n}:{p}={v:g}" for n, ps in effects.items() for p, v in ps.items()) or "none"
    batch = format_ranges(ranges)
    print(f"{out}: {args.designs} specimens of {args.unit}{batch}, {len(data)} points; effects: {hidden}; "
          f"noise {args.noise_arcmin:g} arcmin (seed {args.seed})")
    return 0


def _effects(args) -> int:
    for eff in registry().values():
        notes = (" (in series at the output)" if eff.series else "") + (" (offered by name only)" if eff.named_only else "")
        print(f"{eff.name}: {eff.title}{notes}")
        for p in eff.parameters:
            print(f"    {p.name} [{p.unit}] in [{p.lower:g}, {p.upper:g}], realistic {p.realistic:g}"
                  + "".join(f" ({u}: {v:g})" for u, v in p.realistic_by_unit) + f": {p.description}")
        print(f"    signature: {eff.signature}")
    return 0


def _plan(args) -> int:
    out = Path(args.out) if args.out else None
    if out is not None:
        if out.suffix.lower() != ".json":
            raise InputError(out, f"the plan is JSON: name the file .json, not '{out.suffix}'", field="--out")
        _refuse_existing(out, args)
    ranges = _design_ranges(args)
    try:
        specimens = synth_designs(args.unit, args.designs, args.seed, ranges)
        plan = plan_detectability(_solve_setup(args), specimens, args.noise_arcmin)
    except ValueError as exc:
        raise InputError("command line", str(exc)) from None
    batch = format_ranges(ranges)
    print(f"{plan.n_specimens} specimens of {args.unit}{batch} (mean lost motion {plan.mean_lost_motion_arcmin:.3f} "
          f"arcmin), {plan.n_points} points, noise {args.noise_arcmin:g} arcmin per point:")
    width = max([16, *(len(c.effect) for c in plan.candidates)])
    print(f"  {'effect':<{width}} {'realistic':>12} {'change RMS':>11} {'noise to show':>14} {'to calibrate':>13} "
          f"{'sd':>7}  visible")
    for c in plan.candidates:
        sd = c.expected_rel_sd
        print(f"  {c.effect:<{width}} {c.realistic:>12.4g} {c.change_rms_arcmin:>11.4f} "
              f"{c.noise_to_show_arcmin:>14.4f} {c.noise_to_calibrate_arcmin:>13.4f} "
              f"{(f'{100 * sd:.0f} %' if sd < 10 else '>1000 %'):>7}  {'yes' if c.visible else 'no'}")
    print("  (arcmin; noise to show: ΔBIC -10; to calibrate: parameter within 15 % at two sd)")
    if out is not None:
        with _new_output(out, args) as tmp:
            Path(tmp).write_text(json.dumps(json_safe(plan.to_dict()), indent=1))
        print(f"{out}: written")
    return 0


def _paper_measurements(args) -> int:
    out = Path(args.out)
    _refuse_existing(out, args, "measurement files are never overwritten: ")
    if not Path(args.data).is_dir():
        raise InputError(args.data, "no such folder: run this in the project folder, or give --data the folder "
                                    "of the paper's tables", field="--data")
    data = paper_measurements(args.data, args.unit)
    with _new_output(out, args) as tmp:
        data.to_csv(tmp, index=False, float_format="%.10g")
    print(f"{out}: {len(data)} specimens of {args.unit} from the paper's Tables 4/5 (lost_motion form)")
    return 0


def _check_measurements(args) -> int:
    # every problem on a line of its own, and exit 1: the file is wrong, not the command (that is 2)
    try:
        m = load_measurements(args.file, unit=args.unit)
        problems = schedule_problems(m, args.steps_per_ramp)
        if problems:
            raise MeasurementError(args.file, problems)
    except MeasurementError as exc:
        _print_problems(exc)
        return 1
    print(f"{args.file}: {_count(len(m.specimens), 'specimen')}, {_count(len(m.data), 'point')}, form {m.form}: ok")
    return 0


def build_parser() -> argparse.ArgumentParser:
    """The ``hdwf`` command line: every subcommand with its options and limits."""
    parser = argparse.ArgumentParser(prog="hdwf", description="Harmonic-drive lost-motion study tools.")
    parser.add_argument("--version", action="version", version=f"hdwf {__version__}")
    sub = parser.add_subparsers(dest="command", required=True)
    for name, func, help_ in (("check-config", _check_config, "validate a config file, the paper's tables and every "
                               "campaign's measurements (the config files are named from the current folder; the "
                               "paths inside them start at the nearest folder holding a Snakefile, as in the "
                               "workflow)"),
                              ("provenance", _provenance, "print config hash, git commit and package versions")):
        p = sub.add_parser(name, help=help_, description=help_[0].upper() + help_[1:] + ".")
        p.add_argument("config", nargs="*", default=["config.yaml"],
                       help="config files, merged in order as Snakemake merges --configfile overlays "
                            "(e.g. config.yaml workflow/campaigns/paper_coning.yaml); default config.yaml")
        p.add_argument("--schema", default=str(SCHEMA_PATH))
        p.set_defaults(func=func)
    p = sub.add_parser("paper-measurements", help="the paper's Tables 4/5 as a measurement file")
    p.add_argument("--unit", required=True, choices=["hd42", "hd120"])
    p.add_argument("--data", default="data/paper", help="folder of the paper's tables")
    p.add_argument("--out", required=True)
    p.add_argument("--force", action="store_true")
    p.set_defaults(func=_paper_measurements)
    p = sub.add_parser("check-measurements", help="check a measurement file as a campaign for a drive would",
                       description="Reads a measurement file (docs/measurements.md) with every check of the "
                                   "loader and of a campaign for --unit, solving nothing; prints one line per "
                                   "problem and exits 1, or a summary and exits 0.")
    p.add_argument("file", help="a .csv or .parquet measurement file")
    p.add_argument("--unit", choices=["hd42", "hd120"],
                   help="the drive the file is for: adds a campaign's checks (every specimen of it, ids that "
                        "can name files); without it the file's own drives are taken")
    p.add_argument("--steps-per-ramp", type=_fe_option(int, "steps_per_ramp"), default=5,
                   help="the campaign's load steps per ramp: a curve point beyond its test torque by more than "
                        "a quarter of a step is refused (default 5, the config's)")
    p.set_defaults(func=_check_measurements)
    p = sub.add_parser("effects", help="list the candidate physical effects and their parameters")
    p.set_defaults(func=_effects)
    p = sub.add_parser("synth", help="write synthetic lost-motion measurements from the FE model",
                       description="Synthetic measurements (curve form of docs/measurements.md) from the FE "
                                   "model at N Latin-hypercube specimens, with effects switched on and "
                                   "Gaussian noise added.")
    _specimen_options(p, "seed of the designs and the noise", "standard deviation of the noise")
    p.add_argument("--effect", action="append", default=[], metavar="NAME:PARAM=VALUE",
                   help="switch an effect on, e.g. tooth_friction:mu=0.08 (repeatable)")
    p.add_argument("--out", required=True, help="output file, .csv or .parquet (never overwritten)")
    p.add_argument("--force", action="store_true", help="replace an existing output file")
    _solve_options(p, 10, 6, "the FE studies' mesh; give a campaign on such data the mesh they were made with")
    p.set_defaults(func=_synth)
    p = sub.add_parser("plan", help="before measuring: which effects could a test show at a given noise",
                       description="Solves the model and every candidate's grid at N Latin-hypercube "
                                   "specimens (as a campaign would) and prints, per candidate at its "
                                   "realistic value, the change it makes and whether a test with this noise "
                                   "per point could show it (docs/validation.md).")
    _specimen_options(p, "seed of the designs", "standard deviation of one reading")
    p.add_argument("--out", help="also write the table as JSON here (never overwritten)")
    p.add_argument("--force", action="store_true", help="replace an existing output file")
    _solve_options(p, 5, 3, "the shipped campaigns' coarse mesh")
    p.set_defaults(func=_plan)
    return parser


def main(argv=None) -> int:
    """Run the ``hdwf`` command ``argv`` (default: the process's arguments); its exit status."""
    args = build_parser().parse_args(argv)
    try:
        return args.func(args)
    except InputError as exc:
        print(f"hdwf: error: {exc}", file=sys.stderr)
        return 2
    except SolveFailed as exc:
        print(f"hdwf: error: {exc} (nothing was written)", file=sys.stderr)
        return 1
    except BrokenPipeError:
        # the reader went away (e.g. `hdwf effects | head`): stop quietly, as a Unix tool does
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        return 1


if __name__ == "__main__":
    sys.exit(main())
