# Shared helpers: which studies, drives and designs exist.

from hdwf.study.paper import FEA_TABLES

STUDIES = config["studies"]
PAPER_STUDIES = [s for s, v in STUDIES.items() if v["source"] == "paper"]
FE_STUDIES = [s for s, v in STUDIES.items() if v["source"] == "fe"]
FE = config["fe"]


def study_units(study):
    return STUDIES[study]["units"]


def design_ids(study, unit):
    """Design ids are known from the config alone, so no checkpoint is needed."""
    if STUDIES[study].get("designs", "paper") == "paper":
        return [f"paper-{i:02d}" for i in range(1, 28)]
    return [f"{unit}-lhs-{i:02d}" for i in range(1, config["doe"]["n_designs"] + 1)]


def _alternatives(names):
    # A wildcard constraint that matches none of the listed names when the list is empty.
    return "|".join(names) if names else "(?!x)x"


wildcard_constraints:
    unit="hd42|hd120",
    study=_alternatives(list(STUDIES)),
    design=r"[A-Za-z0-9_\-]+",
    ref=r"[0-9.]+",
