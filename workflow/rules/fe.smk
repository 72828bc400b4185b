# Our FE model: per-design mesh -> solve (one core each, 2 jobs at once on 2 cores), then
# aggregation into the study's lost_motion.parquet and curves.parquet, and mesh convergence.

def _fe_design_source(w):
    if STUDIES[w.study]["designs"] == "paper":
        return f"{config['paper_data']}/{FEA_TABLES[w.unit]}"
    return f"results/doe/{w.unit}/designs.parquet"


rule fe_designs:
    input:
        _fe_design_source,
    output:
        "results/{study}/{unit}/designs.parquet",
    wildcard_constraints:
        study=_alternatives(FE_STUDIES),
    params:
        designs=lambda w: STUDIES[w.study]["designs"],
        data_dir=config["paper_data"],
    log:
        "results/logs/{study}_{unit}_designs.log",
    script:
        "../scripts/fe_designs.py"


rule fe_mesh:
    input:
        "results/{study}/{unit}/designs.parquet",
    output:
        msh="results/{study}/{unit}/mesh/{design}.msh",
        npz="results/{study}/{unit}/mesh/{design}.npz",
    params:
        settings={k: FE[k] for k in ("elements_over_height", "elements_over_thickness", "refinement", "symmetry")},
    threads: 1
    log:
        "results/logs/{study}_{unit}_mesh_{design}.log",
    script:
        "../scripts/fe_mesh.py"


rule fe_solve:
    input:
        designs="results/{study}/{unit}/designs.parquet",
        mesh="results/{study}/{unit}/mesh/{design}.npz",
    output:
        row="results/{study}/{unit}/designs/{design}.parquet",
        curve="results/{study}/{unit}/designs/{design}_curve.parquet",
    params:
        steps_per_ramp=FE["steps_per_ramp"],
    threads: 1
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
        settings=lambda w: {"elements_over_height": FE["elements_over_height"],
                            "elements_over_thickness": FE["elements_over_thickness"], "refinement": float(w.ref),
                            "symmetry": FE["symmetry"]},
        steps_per_ramp=FE["steps_per_ramp"],
    threads: 1
    resources:
        mem_mb=4000,
    log:
        "results/logs/{study}_{unit}_convergence_r{ref}_{design}.log",
    script:
        "../scripts/fe_refined_solve.py"


def _convergence_inputs(w):
    """Every design also on the other of the two finest meshes; every k-th also on the third (GCI)."""
    finest, second, coarsest = sorted(FE["convergence"]["refinements"], reverse=True)
    pair_partner = finest if FE["refinement"] == second else second
    designs = design_ids(w.study, w.unit)
    every = FE["convergence"]["representative_every"]
    files = {"default": f"results/{w.study}/{w.unit}/lost_motion.parquet"}
    files["other_meshes"] = [f"results/{w.study}/{w.unit}/convergence/r{pair_partner:g}/{d}.parquet" for d in designs]
    files["other_meshes"] += [f"results/{w.study}/{w.unit}/convergence/r{coarsest:g}/{d}.parquet" for d in designs[::every]]
    return files


rule fe_convergence:
    input:
        unpack(_convergence_inputs),
    output:
        "results/{study}/{unit}/convergence.parquet",
    wildcard_constraints:
        study=_alternatives(FE_STUDIES),
    params:
        refinement=FE["refinement"],
    log:
        "results/logs/{study}_{unit}_convergence.log",
    script:
        "../scripts/fe_convergence.py"


rule fe_deformed:
    # One design solved again keeping every node's displacement, for the report's picture.
    input:
        "results/{study}/{unit}/designs.parquet",
    output:
        png="results/{study}/{unit}/deformed_{design}.png",
        fields="results/{study}/{unit}/deformed_{design}.npz",
    params:
        settings={k: FE[k] for k in ("elements_over_height", "elements_over_thickness", "refinement", "symmetry")},
        steps_per_ramp=FE["steps_per_ramp"],
    threads: 1
    log:
        "results/logs/{study}_{unit}_deformed_{design}.log",
    script:
        "../scripts/fe_deformed.py"
