# Correlation, quadratic surrogate and Sobol' indices of one study and drive.

rule correlation:
    input:
        "results/{study}/{unit}/lost_motion.parquet",
    output:
        table="results/{study}/{unit}/correlation.parquet",
        figure=report("results/{study}/{unit}/correlation.png", caption="../report/correlation.rst",
                      category="{study}", subcategory="{unit}"),
    priority: 2
    benchmark:
        "results/benchmarks/{study}_{unit}_correlation.tsv"
    log:
        "results/logs/{study}_{unit}_correlation.log",
    script:
        "../scripts/correlation.py"


rule surrogate:
    input:
        lost_motion="results/{study}/{unit}/lost_motion.parquet",
        bounds=paper_file("table3_bounds.csv"),
    output:
        model="results/{study}/{unit}/surrogate.json",
        figure=report("results/{study}/{unit}/surrogate.png", caption="../report/surrogate.rst",
                      category="{study}", subcategory="{unit}"),
    params:
        bounds_source=lambda w: STUDIES[w.study]["surrogate_bounds"],
    priority: 2
    benchmark:
        "results/benchmarks/{study}_{unit}_surrogate.tsv"
    log:
        "results/logs/{study}_{unit}_surrogate.log",
    script:
        "../scripts/surrogate.py"


rule sobol:
    input:
        surrogate="results/{study}/{unit}/surrogate.json",
        bounds=paper_file("table3_bounds.csv"),
    output:
        table="results/{study}/{unit}/sobol.parquet",
        figure=report("results/{study}/{unit}/sobol_convergence.png", caption="../report/sobol.rst",
                      category="{study}", subcategory="{unit}"),
    params:
        settings={k: v for k, v in config["sobol"].items() if k != "samplers"},
        samplers=config["sobol"]["samplers"],
    priority: 2
    resources:
        mem_mb=2000,
        runtime=20,
    benchmark:
        "results/benchmarks/{study}_{unit}_sobol.tsv"
    log:
        "results/logs/{study}_{unit}_sobol.log",
    script:
        "../scripts/sobol.py"
