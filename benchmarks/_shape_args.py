"""Command-line options for the section's shape alternatives (``drive_geometry`` keywords),
shared by the benchmarks that solve Tables 4/5 or sweep one design."""

from __future__ import annotations

import argparse


def add_shape_arguments(ap: argparse.ArgumentParser) -> None:
    """--deflection, --addendum-frac and --offsets (docs/fe-model.md, "The studies' model")."""
    ap.add_argument("--deflection", type=float, default=1.0,
                    help="DriveGeometry.deflection_coeff: the cam pushes this many w0 (> 1: a deeper cam)")
    ap.add_argument("--addendum-frac", type=float, default=None,
                    help="addendum / tooth height of FS and CS (default the unit's 0.45)")
    ap.add_argument("--offsets", choices=("normal", "radial"), default="normal",
                    help="DriveGeometry.offset_direction: r_FS, r_CS as normal flank offsets or rack shifts")


def shape_of(args: argparse.Namespace) -> dict:
    """The ``drive_geometry`` keywords the options ask for."""
    return {"deflection_coeff": args.deflection, "addendum_frac": args.addendum_frac,
            "offset_direction": args.offsets}
