"""CI must prove what a newcomer runs: .ci/run holds the README's test command verbatim, and every
hdwf command line the README and docs give is accepted by the CLI as written."""

import re
import shlex

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


def _documented_hdwf_commands() -> list[tuple[str, str]]:
    """Every whole `hdwf ...` command line in README.md and docs/*.md: inline spans (which may wrap)
    and lines of code blocks (joined over their backslash continuations) that name a drive
    (`--unit hd42`), as every command that solves or reads data does. A synopsis with a
    placeholder ([--out ...], FILE) or an option named in prose is not a command and is left out."""
    found = []
    for path in [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]:
        text = path.read_text()
        spans = re.findall(r"`((?:\.venv/bin/)?hdwf [^`]+)`", text)
        for block in re.findall(r"```[a-z]*\n(.*?)```", text, flags=re.S):
            joined = re.sub(r"\\\n\s*", " ", block)
            spans += [line.split("#", 1)[0] for line in joined.splitlines()
                      if re.match(r"\s*(\.venv/bin/)?hdwf ", line)]
        for span in spans:
            command = " ".join(span.split())
            if re.search(r"--unit hd", command) and not re.search(r"\[|\.\.\.|…|\b[A-Z]{3,}\b", command):
                found.append((path.name, command))
    return found


def test_every_documented_hdwf_command_line_is_accepted():
    """A command the docs give must parse as written: `hdwf plan ... --steps-per-ramp 100` in
    docs/validation.md was refused for a while when the CLI took its limits by hand."""
    from hdwf.cli import build_parser

    commands = _documented_hdwf_commands()
    assert any("--steps-per-ramp 100" in c for _, c in commands)   # the one that was refused
    parser = build_parser()
    for doc, command in commands:
        argv = shlex.split(command)[1:]
        try:
            parser.parse_args(argv)
        except SystemExit:
            raise AssertionError(f"{doc}: `{command}` is refused by the CLI") from None


def test_every_configfile_the_readme_names_is_shipped_and_valid():
    """`--configfile hd42.yaml` in the README named a file nobody had: a newcomer met a raw
    FileNotFoundError. Every overlay the README runs is shipped and valid over config.yaml."""
    from hdwf.config import SCHEMA_PATH, load_config

    readme = (ROOT / "README.md").read_text()
    overlays = sorted(set(re.findall(r"--configfile (\S+\.yaml)", readme)))
    assert "workflow/overlays/hd42_only.yaml" in overlays and "workflow/overlays/bare_section.yaml" in overlays
    for overlay in overlays:   # raises ConfigError naming the overlay if one is not valid
        load_config([ROOT / "config.yaml", ROOT / overlay], SCHEMA_PATH)
    bare = load_config([ROOT / "config.yaml", ROOT / "workflow/overlays/bare_section.yaml"], SCHEMA_PATH)
    assert bare["fe"]["effects"] == {}
    one_drive = load_config([ROOT / "config.yaml", ROOT / "workflow/overlays/hd42_only.yaml"], SCHEMA_PATH)
    assert {s: one_drive["studies"][s]["units"] for s in ("fe", "fe_at_paper")} == {"fe": ["hd42"], "fe_at_paper": ["hd42"]}
