"""Plumbing every stage shares: atomic file writes and Parquet metadata (``io``), the provenance
stamped on each artefact (``provenance``) and the errors that name a file, field and value
(``errors``), values as strict JSON takes them (``jsonsafe``), and one BLAS thread per process unless the
environment sets another (``blas``)."""
