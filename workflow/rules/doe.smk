# Our own optimal space-filling Latin hypercube per drive (Table 3 bounds).

rule doe:
    input:
        bounds=paper_file("table3_bounds.csv"),
    output:
        "results/doe/{unit}/designs.parquet",
    params:
        n=config["doe"]["n_designs"],
        seed=config["doe"]["seed"],
        optimization=config["doe"]["optimization"],
    benchmark:
        "results/benchmarks/doe_{unit}.tsv"
    log:
        "results/logs/doe_{unit}.log",
    script:
        "../scripts/doe.py"
