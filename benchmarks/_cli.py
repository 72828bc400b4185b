"""Command-line pieces shared by the benchmarks that solve Tables 4/5 or one design: the
section's shape alternatives (``drive_geometry`` keywords) and design variables given as
NAME=value pairs."""

from __future__ import annotations

import argparse

from hdwf import PARAMETER_COLUMNS


def add_shape_arguments(ap: argparse.ArgumentParser) -> None:
    """--deflection, --addendum-frac, --offsets (docs/fe-alternatives.md, "A deeper cam" and
    "Reading r_FS, r_CS as rack shifts") and --tip-round (docs/fe-model.md, "Mesh convergence")."""
    ap.add_argument("--deflection", type=float, default=1.0,
                    help="DriveGeometry.deflection_coeff: the cam pushes this many w0 (> 1: a deeper cam)")
    ap.add_argument("--addendum-frac", type=float, default=None,
                    help="addendum / tooth height of FS and CS (default the unit's 0.45)")
    ap.add_argument("--offsets", choices=("normal", "radial"), default="normal",
                    help="DriveGeometry.offset_direction: r_FS, r_CS as normal flank offsets or rack shifts")
    ap.add_argument("--tip-round", type=float, default=0.0,
                    help="DriveGeometry.tip_round_m: radius of the FS and CS tip corners' round, units of m")


def shape_of(args: argparse.Namespace) -> dict:
    """The ``drive_geometry`` keywords the options ask for."""
    return {"deflection_coeff": args.deflection, "addendum_frac": args.addendum_frac,
            "offset_direction": args.offsets, "tip_round_m": args.tip_round}


def check_names(names) -> None:
    """Refuse names that are not design variables (``hdwf.PARAMETER_COLUMNS``)."""
    unknown = set(names) - set(PARAMETER_COLUMNS)
    if unknown:
        raise SystemExit(f"unknown design variable(s) {sorted(unknown)}; expected {PARAMETER_COLUMNS}")


def assignments(text: str) -> dict[str, float]:
    """``"rFS_mm=0.016,rCS_mm=0"`` -> ``{"rFS_mm": 0.016, "rCS_mm": 0.0}`` (checked names)."""
    pairs = dict(part.split("=", 1) for part in text.split(",") if part)
    check_names(pairs)
    return {k: float(v) for k, v in pairs.items()}
