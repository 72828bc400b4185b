"""What produced an artefact: config hash, git commit and the versions of the packages used."""

from __future__ import annotations

import hashlib
import json
import platform
import subprocess
from importlib import metadata
from pathlib import Path

_PACKAGES = ("hdwf", "snakemake", "numpy", "scipy", "pandas", "scikit-fem", "gmsh", "SALib",
             "statsmodels", "pyarrow", "matplotlib", "typst")


def config_hash(config: dict) -> str:
    """SHA-256 of the canonical JSON of a config: same config, same hash, whatever the key order."""
    canonical = json.dumps(config, sort_keys=True, separators=(",", ":"), default=str)
    return hashlib.sha256(canonical.encode()).hexdigest()


def package_versions() -> dict[str, str]:
    """Installed versions of the packages that shape the results."""
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


# the checkout this library was imported from (src/hdwf/common/provenance.py -> its root)
_LIBRARY_ROOT = Path(__file__).resolve().parents[3]


def provenance(config: dict, repo_dir: str | Path = ".") -> dict:
    """What every artefact records: config hash, git commit, Python and package versions.

    The commit is the project's (``repo_dir``); when the ``hdwf`` running is imported from
    another checkout (an install from elsewhere), that checkout's commit is added, since the
    project's alone would not say which code made the artefact.
    """
    commit = git_commit(repo_dir)
    if _LIBRARY_ROOT != Path(repo_dir).resolve() and (_LIBRARY_ROOT / ".git").exists():
        commit += f"; hdwf library {git_commit(_LIBRARY_ROOT)}"
    return _record(config, commit)


def tool_provenance(settings: dict) -> dict:
    """``provenance`` of a file a command writes outside any project (``hdwf synth``): its
    settings stand for the config, and the commit is that of the checkout ``hdwf`` runs from.
    An install that is no checkout (``pip install .``) has no commit to give: git, asked about
    the folder it sits in, would name whatever repository holds that folder."""
    if (_LIBRARY_ROOT / ".git").exists():
        return _record(settings, git_commit(_LIBRARY_ROOT))
    return _record(settings, "unknown (hdwf is not run from a git checkout)")


def _record(config: dict, commit: str) -> dict:
    return {
        "config_hash": config_hash(config),
        "git_commit": commit,
        "python": platform.python_version(),
        "packages": package_versions(),
    }
