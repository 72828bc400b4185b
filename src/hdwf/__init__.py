"""hdwf: a reproducible study of harmonic-drive lost motion.

One module per stage: ``doe`` (designs of experiments), ``paper`` (the seed paper's tables),
``aggregate`` (per-design results into one Parquet table), ``stats`` (regression and
correlation), ``surrogate`` (the quadratic of the paper's Eq. 11), ``sobol`` (sensitivity
indices, estimated and exact), ``plots`` and ``report``; ``config``, ``provenance`` and
``io`` are shared plumbing.  The library knows nothing of Snakemake.
"""

__version__ = "0.1.0"

#: The five study parameters, in the paper's order, and their column names.
PARAMETERS = ("d", "D", "Gr", "rFS", "rCS")
PARAMETER_COLUMNS = tuple(f"{p}_mm" for p in PARAMETERS)
#: Display names as the paper writes them.
PARAMETER_LABELS = {"d": "d", "D": "D", "Gr": "G_r", "rFS": "r_FS", "rCS": "r_CS"}
UNITS = ("hd42", "hd120")
