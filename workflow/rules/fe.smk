# Our FE model: per-design mesh and solve (one core each, 2 jobs at once on 2 cores), then
# aggregation into the study's lost_motion.parquet and curves.parquet, and mesh convergence.

rule fe_designs:
    input:
        fe_design_source,
    output:
        "results/{study}/{unit}/designs.parquet",
    wildcard_constraints:
        study=_alternatives(FE_STUDIES),
    params:
        designs=lambda w: STUDIES[w.study]["designs"],
    benchmark:
        "results/benchmarks/{study}_{unit}_designs.tsv"
    log:
        "results/logs/{study}_{unit}_designs.log",
    script:
        "../scripts/fe_designs.py"


rule fe_solve:
    # mesh and solve in one job: the mesh takes a second or two, less than a job spends starting
    input:
        "results/{study}/{unit}/designs.parquet",
    output:
        msh="results/{study}/{unit}/mesh/{design}.msh",
        row="results/{study}/{unit}/designs/{design}.parquet",
        curve="results/{study}/{unit}/designs/{design}_curve.parquet",
    params:
        settings=FE_MESH,
        steps_per_ramp=FE["steps_per_ramp"],
        effects=FE["effects"],
    threads: 1
    # before the convergence runs (priority 0): the statistics wait for these, the report alone
    # for those, so the stages after the solves run while the convergence runs fill the cores
    priority: 1
    resources:
        mem_mb=4000,
        runtime=30,
    benchmark:
        "results/{study}/{unit}/benchmarks/solve_{design}.tsv"
    log:
        "results/logs/{study}_{unit}_solve_{design}.log",
    script:
        "../scripts/fe_solve.py"


rule fe_aggregate:
    input:
        rows=lambda w: expand("results/{study}/{unit}/designs/{design}.parquet", study=w.study, unit=w.unit,
                              design=design_ids(w.study, w.unit)),
        curves=lambda w: expand("results/{study}/{unit}/designs/{design}_curve.parquet", study=w.study,
                                unit=w.unit, design=design_ids(w.study, w.unit)),
    output:
        lost_motion="results/{study}/{unit}/lost_motion.parquet",
        curves="results/{study}/{unit}/curves.parquet",
    wildcard_constraints:
        study=_alternatives(FE_STUDIES),
    params:
        effects=FE["effects"],
        calibrated_on=FE.get("calibrated_on"),
    priority: 2
    benchmark:
        "results/benchmarks/{study}_{unit}_aggregate.tsv"
    log:
        "results/logs/{study}_{unit}_aggregate.log",
    script:
        "../scripts/fe_aggregate.py"


rule fe_refined_solve:
    # Mesh-convergence runs: mesh and solve one design at another refinement (mesh not stored).
    input:
        "results/{study}/{unit}/designs.parquet",
    output:
        "results/{study}/{unit}/convergence/r{ref}/{design}.parquet",
    params:
        settings=lambda w: {**FE_MESH, "refinement": float(w.ref)},
        steps_per_ramp=FE["steps_per_ramp"],
        effects=FE["effects"],
    threads: 1
    resources:
        mem_mb=4000,
        runtime=45,  # a 1.25x mesh takes about 1.4x the default's solve
    benchmark:
        "results/benchmarks/{study}_{unit}_convergence_r{ref}_{design}.tsv"
    log:
        "results/logs/{study}_{unit}_convergence_r{ref}_{design}.log",
    script:
        "../scripts/fe_refined_solve.py"


rule fe_convergence:
    input:
        unpack(convergence_inputs),
    output:
        "results/{study}/{unit}/convergence.parquet",
    wildcard_constraints:
        study=_alternatives(FE_STUDIES),
    params:
        refinement=FE["refinement"],
    benchmark:
        "results/benchmarks/{study}_{unit}_convergence.tsv"
    log:
        "results/logs/{study}_{unit}_convergence.log",
    script:
        "../scripts/fe_convergence.py"


rule fe_deformed:
    # One design solved again keeping every node's displacement, for the report's picture.
    input:
        "results/{study}/{unit}/designs.parquet",
    output:
        png=report("results/{study}/{unit}/deformed_{design}.png", caption="../report/deformed.rst",
                   category="{study}", subcategory="{unit}"),
        fields="results/{study}/{unit}/deformed_{design}.npz",
    params:
        settings=FE_MESH,
        steps_per_ramp=FE["steps_per_ramp"],
        effects=FE["effects"],
    threads: 1
    resources:
        mem_mb=4000,
        runtime=30,
    benchmark:
        "results/benchmarks/{study}_{unit}_deformed_{design}.tsv"
    log:
        "results/logs/{study}_{unit}_deformed_{design}.log",
    script:
        "../scripts/fe_deformed.py"
