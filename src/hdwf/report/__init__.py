"""The PDF reports, built from artefacts only.

``document``: the document model (blocks of typst markup, ``fmt``, ``lit``) and typesetting.
``artefacts``: typed records of the artefact paths each report reads.
``paper_part``, ``fe_part`` (with ``agreement_part`` and ``knee_part``), ``validation_part``: the
sections of Parts I, II and III, each reading the artefacts it shows; ``summary_part``: the
opening table of each part's headline figures. ``build``: ``study_report`` and ``full_report``
composed from them. ``figures``: the study's figures (matplotlib), drawn by the stages and by
``fe_part``.
"""
