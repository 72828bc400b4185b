# Model against measurements (docs/validation.md): per campaign, every specimen is meshed once
# and solved for the campaign's model and every candidate effect's parameter grid (one job per
# specimen, in parallel); the diagnosis calibrates and ranks the candidates; the ladder re-solves
# the model with the found effects switched on; figures for the report.

import dataclasses
import re

from hdwf.validation.campaign import campaign_plan
from hdwf.common.errors import InputError
from hdwf.validation.measurements import load_measurements

CAMPAIGNS = {name: campaign_plan(name, c, FE) for name, c in config.get("validation", {}).items()}
_SPECIMENS = {}


def campaign_specimens(campaign):
    """The campaign's specimens, read (and checked) once from its measurement file."""
    if campaign not in _SPECIMENS:
        plan = CAMPAIGNS[campaign]
        meas = load_measurements(plan.measurements)   # every problem with file, row and field
        spec = meas.specimens
        for i, r in spec.iterrows():
            if r["unit"] != plan.unit:
                raise InputError(plan.measurements, f"campaign '{campaign}' is for {plan.unit}",
                                 field="unit", value=r["unit"], row=int(i) + 1)
            if not re.fullmatch(r"[A-Za-z0-9_.\-]+", str(r["specimen_id"])):
                raise InputError(plan.measurements, "specimen ids may use letters, digits, '_', '.' and '-' only",
                                 field="specimen_id", value=r["specimen_id"], row=int(i) + 1)
        _SPECIMENS[campaign] = spec
    return _SPECIMENS[campaign]


def specimen_ids(campaign):
    return list(campaign_specimens(campaign)["specimen_id"])


def specimen_row(w):
    spec = campaign_specimens(w.campaign)
    row = spec[spec["specimen_id"] == w.specimen].iloc[0]
    return {k: (float(v) if k.endswith("_mm") else str(v)) for k, v in row.items()
            if k in ("specimen_id", "unit") or k.endswith("_mm")}


def plan_dict(w):
    return dataclasses.asdict(CAMPAIGNS[w.campaign])


wildcard_constraints:
    campaign=_alternatives(list(CAMPAIGNS)),
    specimen=r"[A-Za-z0-9_.\-]+",


rule validation_specimen:
    output:
        "results/validation/{campaign}/tables/{specimen}.parquet",
    params:
        # the specimen's inputs and the campaign's model, not the file: editing the measured
        # values re-runs the diagnosis only, never the solves
        unit=lambda w: CAMPAIGNS[w.campaign].unit,
        specimen=specimen_row,
        settings=lambda w: CAMPAIGNS[w.campaign].settings,
        steps_per_ramp=lambda w: CAMPAIGNS[w.campaign].steps_per_ramp,
        variants=lambda w: CAMPAIGNS[w.campaign].table_variants(),
        repo=REPO_DIR,
    threads: 1
    resources:
        mem_mb=4000,
        runtime=60,
    benchmark:
        "results/validation/{campaign}/benchmarks/{specimen}.tsv"
    log:
        "results/logs/validation_{campaign}_{specimen}.log",
    script:
        "../scripts/validation_specimen.py"


rule validation_diagnosis:
    input:
        measurements=lambda w: CAMPAIGNS[w.campaign].measurements,
        tables=lambda w: expand("results/validation/{campaign}/tables/{specimen}.parquet",
                                campaign=w.campaign, specimen=specimen_ids(w.campaign)),
    output:
        json="results/validation/{campaign}/diagnosis.json",
        points="results/validation/{campaign}/points.parquet",
    params:
        plan=plan_dict,
        repo=REPO_DIR,
    # an effect found before the next round is re-solved near its estimate, every specimen
    threads: 2
    resources:
        mem_mb=8000,
    benchmark:
        "results/validation/{campaign}/benchmarks/diagnosis.tsv"
    log:
        "results/logs/validation_{campaign}_diagnosis.log",
    script:
        "../scripts/validation_diagnosis.py"


rule validation_ladder:
    # one job per campaign (a rung needs one or two solves per specimen, fewer seconds than
    # a job per specimen spends starting up), its specimens in 2 processes
    input:
        measurements=lambda w: CAMPAIGNS[w.campaign].measurements,
        diagnosis="results/validation/{campaign}/diagnosis.json",
        tables=lambda w: expand("results/validation/{campaign}/tables/{specimen}.parquet",
                                campaign=w.campaign, specimen=specimen_ids(w.campaign)),
    output:
        "results/validation/{campaign}/ladder.parquet",
    params:
        unit=lambda w: CAMPAIGNS[w.campaign].unit,
        settings=lambda w: CAMPAIGNS[w.campaign].settings,
        steps_per_ramp=lambda w: CAMPAIGNS[w.campaign].steps_per_ramp,
        repo=REPO_DIR,
    threads: 2
    resources:
        mem_mb=4000,
    benchmark:
        "results/validation/{campaign}/benchmarks/ladder.tsv"
    log:
        "results/logs/validation_{campaign}_ladder.log",
    script:
        "../scripts/validation_ladder.py"


rule validation_figures:
    input:
        diagnosis="results/validation/{campaign}/diagnosis.json",
        points="results/validation/{campaign}/points.parquet",
        ladder="results/validation/{campaign}/ladder.parquet",
    output:
        measured="results/validation/{campaign}/measured_vs_predicted.png",
        residuals="results/validation/{campaign}/residuals.png",
        ladder="results/validation/{campaign}/ladder.png",
    params:
        repo=REPO_DIR,
    log:
        "results/logs/validation_{campaign}_figures.log",
    script:
        "../scripts/validation_figures.py"


rule validation:
    input:
        [f"results/validation/{c}/{name}" for c in CAMPAIGNS
         for name in ("diagnosis.json", "ladder.parquet", "measured_vs_predicted.png")],
