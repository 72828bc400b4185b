# Model against measurements (docs/validation.md): per campaign, every specimen is meshed once
# and solved for the campaign's model and every candidate effect's parameter grid (one job per
# specimen, in parallel); the diagnosis calibrates and ranks the candidates; the ladder re-solves
# the model with the found effects switched on; figures for the report.

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
    threads: 1
    priority: 1
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
    # an effect found before the next round is re-solved near its estimate, every specimen.
    # One core and a priority: a two-core job would wait until both cores are free at once,
    # which a queue of one-core solves never leaves, and so run last and alone
    threads: 1
    priority: 2
    resources:
        mem_mb=8000,
        runtime=120,  # some 160 re-solves: 3.6 min on this project's 2-core machine
    benchmark:
        "results/validation/{campaign}/benchmarks/diagnosis.tsv"
    log:
        "results/logs/validation_{campaign}_diagnosis.log",
    script:
        "../scripts/validation_diagnosis.py"


rule validation_ladder:
    # one job per campaign (a rung needs one or two solves per specimen, fewer seconds than
    # a job per specimen spends starting up); one core, as the diagnosis
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
    threads: 1
    priority: 2
    resources:
        mem_mb=4000,
        runtime=60,
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
        measured=report("results/validation/{campaign}/measured_vs_predicted.png", caption="../report/validation.rst",
                        category="validation", subcategory="{campaign}"),
        residuals=report("results/validation/{campaign}/residuals.png", caption="../report/validation.rst",
                         category="validation", subcategory="{campaign}"),
        ladder=report("results/validation/{campaign}/ladder.png", caption="../report/validation.rst",
                      category="validation", subcategory="{campaign}"),
    priority: 2
    benchmark:
        "results/benchmarks/validation_{campaign}_figures.tsv"
    log:
        "results/logs/validation_{campaign}_figures.log",
    script:
        "../scripts/validation_figures.py"


rule validation:
    input:
        [f"results/validation/{c}/{name}" for c in CAMPAIGNS
         for name in ("diagnosis.json", "ladder.parquet", "measured_vs_predicted.png")],
