# The paper's Tables 4/5 as the lost-motion table of a `source: paper` study.

rule paper_lost_motion:
    input:
        table=lambda w: paper_file(FEA_TABLES[w.unit]),
    output:
        "results/{study}/{unit}/lost_motion.parquet",
    wildcard_constraints:
        study=_alternatives(PAPER_STUDIES),
    benchmark:
        "results/benchmarks/{study}_{unit}_lost_motion.tsv"
    log:
        "results/logs/{study}_{unit}_lost_motion.log",
    script:
        "../scripts/paper_lost_motion.py"
