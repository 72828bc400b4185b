"""CI must prove what a newcomer runs: .ci/run holds the README's test command verbatim."""

import re

from conftest import ROOT


def _quick_start_commands() -> list[str]:
    readme = (ROOT / "README.md").read_text()
    section = readme.split("## Quick start", 1)[1].split("\n## ", 1)[0]
    blocks = re.findall(r"```sh\n(.*?)\n```", section, flags=re.S)
    return [b.strip() for b in blocks if b.startswith("python3.11 -m venv")]


def test_ci_runs_the_readme_test_command():
    commands = _quick_start_commands()
    assert len(commands) == 2  # exactly two: install and run the main job; install and run the tests
    main_job, tests = commands
    assert main_job.endswith(".venv/bin/snakemake --cores 2")
    assert tests.endswith(".venv/bin/python -m pytest -q -n 2")
    assert tests in (ROOT / ".ci" / "run").read_text()


def test_both_commands_install_with_the_constraints_file():
    for command in _quick_start_commands():
        assert "-c constraints.txt" in command
    assert (ROOT / "constraints.txt").is_file()
