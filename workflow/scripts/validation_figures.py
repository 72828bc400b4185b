"""Adapter for rule validation_figures: measured vs predicted, residuals, the ladder."""
import json, sys
sys.path.insert(0, __import__("os").path.dirname(__file__))
from _adapter import setup  # noqa: E402

import pandas as pd  # noqa: E402

from hdwf.report.figures import ladder_figure, measured_vs_predicted_figure, residual_figure  # noqa: E402

setup(snakemake)  # noqa: F821
inp, out = snakemake.input, snakemake.output  # noqa: F821
diag = json.loads(open(inp.diagnosis).read())
points = pd.read_parquet(inp.points)
name = f"{diag['campaign']} ({diag['unit'].upper()})"
measured_vs_predicted_figure(points, f"{name}: measured against predicted", out.measured)
residual_figure(points, f"{name}: residuals", out.residuals)
ladder_figure(pd.read_parquet(inp.ladder), diag.get("noise_arcmin"), f"{name}: the error ladder", out.ladder)
