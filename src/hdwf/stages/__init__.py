"""Stages: read the artefacts a rule gets, call the science, write what the rule promises.

One module per rule file (``doe``, ``paper``, ``fe``, ``stats``, ``validation``, ``report``), and
one each for the many small solve jobs, which start without pandas (``fe_solve``: one design of an
FE study; ``validation_specimen``: one specimen of a campaign); each workflow script calls exactly
one function here.  File I/O lives here and in
``hdwf.common.io``, not in the science subpackages.
"""
