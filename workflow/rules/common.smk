# Everything the rules compute: which studies, drives, designs and campaigns exist and
# which files each rule reads.  Rule files hold rules only (snakemake --lint).

import dataclasses
import sys

from hdwf.config import design_ids as config_design_ids
from hdwf.stages.validation import campaign_plan, campaign_specimens, specimen_record
from hdwf.study.paper import FEA_TABLES, PAPER_TABLES
from hdwf.validation.measurements import MeasurementError

STUDIES = config["studies"]
PAPER_STUDIES = [s for s, v in STUDIES.items() if v["source"] == "paper"]
FE_STUDIES = [s for s, v in STUDIES.items() if v["source"] == "fe"]
FE = config["fe"]
# how the FE studies mesh a section (MeshSettings); the convergence runs change the refinement only
FE_MESH = {k: FE[k] for k in ("elements_over_height", "elements_over_thickness", "refinement", "symmetry",
                              "flank_refinement")}
# the tooth contact's options (DesignJob), only when set: the default studies' params stay as they were
FE_MESH.update({k: FE[k] for k in ("tip_round_m", "flank_layer_fs_pass_only") if FE.get(k)})
CAMPAIGNS = {name: campaign_plan(name, c, FE) for name, c in config.get("validation", {}).items()}


def paper_file(name):
    """A table of the seed paper (data/paper/ by default); rules read them as declared inputs."""
    return f"{config['paper_data']}/{name}"


PAPER_FILES = [paper_file(name) for name in PAPER_TABLES]


def study_units(study):
    return STUDIES[study]["units"]


def design_ids(study, unit):
    """Design ids are known from the config alone, so no checkpoint is needed."""
    return config_design_ids(config, study, unit)


def _alternatives(names):
    # A wildcard constraint that matches none of the listed names when the list is empty.
    return "|".join(names) if names else "(?!x)x"


# --- FE studies ---------------------------------------------------------------------------------

def fe_study_targets():
    out = []
    for study in FE_STUDIES:
        for unit in study_units(study):
            out += [f"results/{study}/{unit}/{name}" for name in
                    ("lost_motion.parquet", "curves.parquet", "correlation.parquet", "surrogate.json", "sobol.parquet")]
    conv = FE["convergence"]["study"]
    out += [f"results/{conv}/{unit}/convergence.parquet" for unit in study_units(conv)]
    return out


def fe_design_source(w):
    """The paper's Table 4/5 for a study on the paper's points, else our Latin hypercube."""
    if STUDIES[w.study]["designs"] == "paper":
        return paper_file(FEA_TABLES[w.unit])
    return f"results/doe/{w.unit}/designs.parquet"


def convergence_inputs(w):
    """Every design also on the other of the two finest meshes; every k-th also on the third (GCI)."""
    finest, second, coarsest = sorted(FE["convergence"]["refinements"], reverse=True)
    pair_partner = finest if FE["refinement"] == second else second
    designs = design_ids(w.study, w.unit)
    every = FE["convergence"]["representative_every"]
    files = {"default": f"results/{w.study}/{w.unit}/lost_motion.parquet"}
    files["other_meshes"] = [f"results/{w.study}/{w.unit}/convergence/r{pair_partner:g}/{d}.parquet" for d in designs]
    files["other_meshes"] += [f"results/{w.study}/{w.unit}/convergence/r{coarsest:g}/{d}.parquet" for d in designs[::every]]
    return files


# --- validation campaigns -----------------------------------------------------------------------

_SPECIMENS = {}


def specimens_of(campaign):
    """The campaign's specimens, read (and checked) once from its measurement file.

    A bad file stops the run with the loader's message alone: raised from an input function, an
    exception would come wrapped in Snakemake's traceback (SystemExit is let through unwrapped)."""
    if campaign not in _SPECIMENS:
        try:
            _SPECIMENS[campaign] = campaign_specimens(CAMPAIGNS[campaign])
        except MeasurementError as exc:
            plan = CAMPAIGNS[campaign]
            problems = "\n  ".join(exc.lines)    # every one, as hdwf check-measurements gives them
            print(f"MeasurementError in campaign '{campaign}' (validation.{campaign}.measurements): "
                  f"{len(exc.lines)} problem(s):\n  {problems}\nNothing was run. Check the file with: "
                  f"hdwf check-measurements {plan.measurements} --unit {plan.unit} --steps-per-ramp {plan.steps_per_ramp}",
                  file=sys.stderr)
            raise SystemExit(1)
    return _SPECIMENS[campaign]


def specimen_ids(campaign):
    return list(specimens_of(campaign)["specimen_id"])


def specimen_row(w):
    return specimen_record(specimens_of(w.campaign), w.specimen)


def plan_dict(w):
    plan = dataclasses.asdict(CAMPAIGNS[w.campaign])
    # an unset data mesh left out: a campaign that does not use it keeps its params, so its results stand
    if not plan["data_mesh"]:
        del plan["data_mesh"]
    return plan


# --- reports ------------------------------------------------------------------------------------
# Each report rule has one named input per kind of artefact, a list of paths, and the parameter
# `owners`: the same names with, per path, whose artefact it is ([study, unit] or [campaign]).

# What the reports read of each drive of a study: kind -> file under results/{study}/{unit}/.
DRIVE_ARTEFACTS = {
    "lost_motion": "lost_motion.parquet",
    "correlation": "correlation.parquet",
    "correlation_png": "correlation.png",
    "surrogate": "surrogate.json",
    "surrogate_png": "surrogate.png",
    "sobol": "sobol.parquet",
    "sobol_png": "sobol_convergence.png",
}
# What the full report reads of each campaign: kind -> file under results/validation/{campaign}/.
CAMPAIGN_ARTEFACTS = {
    "diagnosis": "diagnosis.json",
    "ladder": "ladder.parquet",
    "measured_png": "measured_vs_predicted.png",
    "residuals_png": "residuals.png",
    "ladder_png": "ladder.png",
    "points": "points.parquet",
}


def study_entries(study, fe_parts):
    """(kind, owner, path) of each artefact of the study; with `fe_parts` also what Part II shows."""
    for unit in study_units(study):
        owner = [study, unit]
        for kind, name in DRIVE_ARTEFACTS.items():
            yield kind, owner, f"results/{study}/{unit}/{name}"
        yield "doe", owner, f"results/doe/{unit}/designs.parquet"
        if not fe_parts:
            continue
        if STUDIES[study]["source"] == "fe":
            yield "curves", owner, f"results/{study}/{unit}/curves.parquet"
        if study == FE["convergence"]["study"]:
            yield "convergence", owner, f"results/{study}/{unit}/convergence.parquet"
        if study == FE["picture"]["study"]:
            yield "deformed_png", owner, f"results/{study}/{unit}/deformed_{FE['picture']['design']}.png"


def campaign_entries(campaign):
    for kind, name in CAMPAIGN_ARTEFACTS.items():
        yield kind, [campaign], f"results/validation/{campaign}/{name}"


def named_inputs(entries):
    """Entries -> the named inputs (kind -> paths) and the owners (kind -> owner per path)."""
    files, owners = {}, {}
    for kind, owner, path in entries:
        files.setdefault(kind, []).append(path)
        owners.setdefault(kind, []).append(owner)
    return files, owners


def study_report_files(wildcards):
    return named_inputs(study_entries(wildcards.study, fe_parts=False))


def full_report_files():
    entries = [e for study in STUDIES for e in study_entries(study, fe_parts=True)]
    entries += [e for campaign in CAMPAIGNS for e in campaign_entries(campaign)]
    return named_inputs(entries)
