# Shared helpers: which studies and drives exist, where the repository is (for provenance).

REPO_DIR = workflow.basedir
STUDIES = config["studies"]
PAPER_STUDIES = [s for s, v in STUDIES.items() if v["source"] == "paper"]


def study_units(study):
    return STUDIES[study]["units"]


def _alternatives(names):
    # A wildcard constraint that matches none of the listed names when the list is empty.
    return "|".join(names) if names else "(?!x)x"


wildcard_constraints:
    unit="hd42|hd120",
    study=_alternatives(list(STUDIES)),
