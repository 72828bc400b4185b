"""Adapter for rule fe_mesh: one design -> gmsh .msh (review) and .npz (solver input)."""
import logging, sys
sys.path.insert(0, __import__("os").path.dirname(__file__))
from _adapter import setup  # noqa: E402

from hdwf.fe_study import mesh_stage  # noqa: E402

setup(snakemake)  # noqa: F821
w = snakemake.wildcards  # noqa: F821
facts = mesh_stage(snakemake.input[0], w.design, w.unit, dict(snakemake.params.settings),  # noqa: F821
                   snakemake.output.msh, snakemake.output.npz)  # noqa: F821
logging.info("%s", facts)
