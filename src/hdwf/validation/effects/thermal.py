"""A temperature difference between the flexspline (with the wave generator) and the CS."""

from dataclasses import replace

from . import Effect, Parameter

ALPHA_STEEL = 11.5e-6   # 1/K, thermal expansion of the steels of FS, bearing and CS

EFFECT = Effect(
    name="thermal",
    title="Temperature difference between flexspline and circular spline",
    description=(
        "In service the wave generator and flexspline run warmer than the circular spline, "
        "which sits in the housing. The warmer inner parts grow by alpha dT relative to it, "
        "so the teeth move into the circular spline's spaces and the flank clearance "
        "shrinks (or grows when they are colder). In the FE model the circular spline is "
        "scaled by 1 / (1 + alpha dT) relative to the rest, a uniform free thermal strain."),
    signature="the dead band shrinks (dT > 0) or grows (dT < 0); the elastic slopes stay",
    parameters=(Parameter("delta_T_K", "K", -40.0, 40.0, 10.0,
                          "temperature of FS and wave generator minus that of the CS",
                          "linear", 8),),   # every 10 K: the response bends where teeth engage
    apply=lambda ch, delta_T_K: replace(ch, cs_scale=ch.cs_scale / (1.0 + ALPHA_STEEL * delta_T_K)),
    references="about 0.085 um of flank clearance per K for HD 42 (background)",
    off={"delta_T_K": 0.0},
)
