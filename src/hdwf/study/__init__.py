"""The statistics of a study: designs of experiments (``doe``), the paper's tables (``paper``),
per-design results into one table (``aggregate``), regression and correlation (``stats``), the
quadratic surrogate (``surrogate``), Sobol' indices (``sobol``), mesh convergence
(``convergence``), the knee of Φ against clearance (``knee``), the agreement of our Φ with the
paper's, also under the measured mesh scatter (``agreement``), and lost motion against makers'
catalogues (``catalogue``)."""
