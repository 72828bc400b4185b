# Correlation, quadratic surrogate and Sobol' indices of one study and drive.

rule correlation:
    input:
        "results/{study}/{unit}/lost_motion.parquet",
    output:
        table="results/{study}/{unit}/correlation.parquet",
        figure="results/{study}/{unit}/correlation.png",
    params:
    log:
        "results/logs/{study}_{unit}_correlation.log",
    script:
        "../scripts/correlation.py"


rule surrogate:
    input:
        lost_motion="results/{study}/{unit}/lost_motion.parquet",
        bounds=f"{config['paper_data']}/table3_bounds.csv",
    output:
        model="results/{study}/{unit}/surrogate.json",
        figure="results/{study}/{unit}/surrogate.png",
    params:
        bounds_source=lambda w: STUDIES[w.study]["surrogate_bounds"],
        data_dir=config["paper_data"],
    log:
        "results/logs/{study}_{unit}_surrogate.log",
    script:
        "../scripts/surrogate.py"


rule sobol:
    input:
        "results/{study}/{unit}/surrogate.json",
    output:
        table="results/{study}/{unit}/sobol.parquet",
        figure="results/{study}/{unit}/sobol_convergence.png",
    params:
        settings={k: v for k, v in config["sobol"].items() if k != "samplers"},
        samplers=config["sobol"]["samplers"],
        data_dir=config["paper_data"],
    log:
        "results/logs/{study}_{unit}_sobol.log",
    script:
        "../scripts/sobol.py"
