"""Stages: read the artefacts a rule gets, call the science, write what the rule promises.

One module per rule file (``doe``, ``paper``, ``fe``, ``stats``, ``validation``, ``report``);
each workflow script calls exactly one function here.  File I/O lives here and in
``hdwf.common.io``, not in the science subpackages.
"""
