"""Compliance of the circular spline's mounting in its housing."""

from dataclasses import replace

from . import Effect, Parameter

EFFECT = Effect(
    name="cs_housing",
    title="Circular spline and housing compliance",
    description=(
        "The baseline clamps every node of the circular spline's outer rim. A real circular "
        "spline is bolted into a housing that gives a little: its rim can move and ovalise. "
        "In the FE model the rim is held by radial and tangential springs of stiffness k "
        "per millimetre of rim (an elastic foundation) instead of being clamped."),
    signature=("extra, nearly linear compliance (a steeper curve), slightly more teeth "
               "share the load; no loop, little change of the dead band"),
    parameters=(Parameter("k_N_per_mm2", "N/mm²", 1.0e3, 1.0e7, 5.0e3,
                          "foundation stiffness of the housing per mm of rim", "reciprocal", 3,
                          power=0.75),),
    apply=lambda ch, k_N_per_mm2: replace(ch, cs_rim_stiffness_N_mm2=k_N_per_mm2),
    # a ring on an elastic foundation deflects as k^-3/4 (Hetényi), which the FE response
    # follows (lost-motion change ∝ k^-0.72…-0.83 over 1e3…1e6 N/mm²): t = k^-0.75 keeps
    # the calibration's spline nearly straight where the realistic values lie
    references="background: clamping the whole rim overstates stiffness; Hetényi, Beams on "
               "Elastic Foundation (1946)",
    off={"k_N_per_mm2": float("inf")},
)
