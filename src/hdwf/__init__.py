"""hdwf: a reproducible study of harmonic-drive lost motion, and its model against measurements.

Subpackages by concept (``docs/architecture.md``): ``common`` (atomic I/O, provenance,
errors), ``drive`` (geometry and gmsh mesh of a design), ``fe`` (the FE model and its contact
solver), ``study`` (designs of experiments, the paper's tables, statistics, surrogate, Sobol'
indices, mesh convergence), ``validation`` (measurements, candidate effects, calibration,
diagnosis, ladder), ``report`` (the typst PDF and its figures) and ``stages`` (read -> compute
-> write, one module per rule file); ``config`` and ``cli`` on top.  The library knows
nothing of Snakemake.
"""

__version__ = "0.1.0"

#: The five study parameters, in the paper's order, and their column names.
PARAMETERS = ("d", "D", "Gr", "rFS", "rCS")
PARAMETER_COLUMNS = tuple(f"{p}_mm" for p in PARAMETERS)
#: Display names as the paper writes them.
PARAMETER_LABELS = {"d": "d", "D": "D", "Gr": "G_r", "rFS": "r_FS", "rCS": "r_CS"}
UNITS = ("hd42", "hd120")
