"""Coning of the flexspline cup: the wave generator's push grows along the face width."""

from dataclasses import replace

from . import Effect, Parameter

EFFECT = Effect(
    name="coning",
    title="Flexspline coning (quasi-3D cup)",
    description=(
        "The flexspline is a cup held circular by its diaphragm, so the radial push of the wave "
        "generator grows from the diaphragm end of the teeth to the open end: the tooth ring is "
        "a cone. The teeth at the open end are pressed deeper into the CS spaces than those at "
        "the diaphragm end, so engagement is lost gradually along the face width as an offset "
        "grows. In the FE model the section is solved as eight slices across the face width, "
        "each pushed w0 (1 + slope zeta), sharing the FS rotation (docs/fe-model.md, "
        "'Coning'). A coned specimen costs eight slice mounts (about 12 times the section's "
        "solve): offered only where a campaign names it."),
    signature="the dead band closes gradually (a soft knee of Phi against the offsets); "
              "the elastic slopes stay",
    parameters=(Parameter("slope", "1", 0.0, 0.4, 0.2,
                          "coning slope c = b / z0 (face width over the diaphragm-to-teeth distance)",
                          "linear", 2),),
    apply=lambda ch, slope: replace(ch, coning_slope=slope),
    named_only=True,
    references="a cup about 0.8 D long with teeth b ~ 0.15-0.2 D wide: c ~ 0.2-0.3",
    off={"slope": 0.0},
)
