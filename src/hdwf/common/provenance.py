"""What produced an artefact: config hash, git commit and the versions of the packages used."""

from __future__ import annotations

import platform
import subprocess
from importlib import metadata
from pathlib import Path

from hdwf.config import config_hash

_PACKAGES = ("hdwf", "snakemake", "numpy", "scipy", "pandas", "scikit-fem", "gmsh", "SALib",
             "statsmodels", "pyarrow", "matplotlib", "typst")


def package_versions() -> dict[str, str]:
    versions = {}
    for name in _PACKAGES:
        try:
            versions[name] = metadata.version(name)
        except metadata.PackageNotFoundError:
            versions[name] = "not installed"
    return versions


def git_commit(repo_dir: str | Path = ".") -> str:
    """The checked-out commit, suffixed ``-dirty`` when tracked files differ from it."""
    try:
        commit = subprocess.run(["git", "-C", str(repo_dir), "rev-parse", "HEAD"], capture_output=True,
                                text=True, check=True, timeout=10).stdout.strip()
        dirty = subprocess.run(["git", "-C", str(repo_dir), "status", "--porcelain", "--untracked-files=no"],
                               capture_output=True, text=True, check=True, timeout=10).stdout.strip()
        return commit + ("-dirty" if dirty else "")
    except (OSError, subprocess.SubprocessError):
        return "unknown (not a git checkout)"


def provenance(config: dict, repo_dir: str | Path = ".") -> dict:
    return {
        "config_hash": config_hash(config),
        "git_commit": git_commit(repo_dir),
        "python": platform.python_version(),
        "packages": package_versions(),
    }
