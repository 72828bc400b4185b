"""Plumbing every stage shares: atomic file writes and Parquet metadata (``io``), the provenance
stamped on each artefact (``provenance``), the errors that name a file, field and value
(``errors``) and the allocator settings of a long numeric run (``allocator``)."""
