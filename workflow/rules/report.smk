# The PDF reports, typeset with typst from the artefacts only (hdwf.stages.report, hdwf.report).
# Each report rule has one named input per kind of artefact, a list of paths, and the parameter
# `owners`: the same names with, per path, whose artefact it is ([study, unit] or [campaign]).

rule study_report:
    input:
        unpack(lambda w: study_report_files(w)[0]),
        paper_data=PAPER_FILES,
    output:
        report("results/{study}/report.pdf", caption="../report/report.rst", category="reports"),
    params:
        owners=lambda w: study_report_files(w)[1],
        study_config=lambda w: STUDIES[w.study],
    benchmark:
        "results/benchmarks/{study}_report.tsv"
    log:
        "results/logs/{study}_report.log",
    script:
        "../scripts/report.py"


rule full_report:
    input:
        unpack(lambda w: full_report_files()[0]),
        paper_data=PAPER_FILES,
    output:
        report("results/report.pdf", caption="../report/report.rst", category="reports"),
    params:
        owners=lambda w: full_report_files()[1],
        studies=STUDIES,
        fe_settings={k: v for k, v in FE.items() if k not in ("convergence", "picture")},
    benchmark:
        "results/benchmarks/report.tsv"
    log:
        "results/logs/report.log",
    script:
        "../scripts/full_report.py"
