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


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(prog="hdwf", description="Harmonic-drive lost-motion study tools.")
    sub = parser.add_subparsers(dest="command", required=True)
    for name, func, help_ in (("check-config", _check_config, "validate a config file against the schema"),
                              ("provenance", _provenance, "print config hash, git commit and package versions")):
        p = sub.add_parser(name, help=help_)
        p.add_argument("config", nargs="?", default="config.yaml")
        p.add_argument("--schema", default="workflow/schemas/config.schema.yaml")
        p.set_defaults(func=func)
    args = parser.parse_args(argv)
    try:
        return args.func(args)
    except InputError as exc:
        print(f"hdwf: error: {exc}", file=sys.stderr)
        return 2


if __name__ == "__main__":
    sys.exit(main())
