"""The PDF report, built from artefacts only: the typst document model and its parts
(``document``) and the figures (``figures``)."""
