"""The PDF reports, built from artefacts only.

``document``: the document model (blocks of typst markup, ``fmt``, ``lit``) and typesetting.
``artefacts``: typed records of the artefact paths each report reads.
``paper_part``, ``fe_part``, ``validation_part``: the sections of Parts I, II and III, each
reading the artefacts it shows. ``build``: ``study_report`` and ``full_report`` composed from
them. ``figures``: the study's figures (matplotlib), drawn by the stages and by ``fe_part``.
"""
