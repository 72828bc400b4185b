"""The statistics of a study: designs of experiments (``doe``), the paper's tables (``paper``),
per-design results into one table (``aggregate``), regression and correlation (``stats``), the
quadratic surrogate (``surrogate``), Sobol' indices (``sobol``) and mesh convergence
(``convergence``)."""
