"""The model against measurements: which physical effect does the FE model miss?

One module per idea, in the order a campaign uses them:

* ``measurements``: the bench's file format, read and checked (``measurement_header``: its
  columns, before any value);
* ``effects``: the candidate physical effects (one module each) and their registry;
* ``variants``: the model with effects switched on (variant keys, a campaign's variants) and
  their solves per specimen, in a process pool;
* ``synthesis``: synthetic specimens, curves and noise (``hdwf synth``), design ranges;
* ``observations``: measured values as one vector, and the model's value of each;
* ``comparison``: comparison error, validation uncertainty, residual tests, BIC and the verdict;
* ``signature``: the baseline's residual split into named terms (level, compliance, play, loop,
  trends), read against ``noise``: the stated uncertainty against the data's own scatter;
* ``calibration``: effect responses, joint least-squares calibration, re-solves near an
  estimate, leave-one-specimen-out error;
* ``detectability``: which candidates data at a given noise could show (``hdwf plan``);
* ``diagnosis``: the greedy search and its typed result (``diagnosis.json``);
* ``ladder``: the model's error rung by rung, from actual solves.

Reading and writing the workflow's files is ``hdwf.stages.validation``'s job.
"""
