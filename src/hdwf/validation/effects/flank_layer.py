"""Compliance under each tooth: a compliant layer on the flanks (what a plane section lacks)."""

from dataclasses import replace

from . import Effect, Parameter

EFFECT = Effect(
    name="flank_layer",
    title="Compliance under the teeth (a compliant flank layer)",
    description=(
        "Our plane section holds every tooth flank as stiffly as a plane-stress slice of the full "
        "face width. In a real drive, and in a 3D model, a tooth pair also gives way through the "
        "cup wall and diaphragm behind it, the face across its width and the contact itself. "
        "This effect puts that compliance between the flanks as a layer of constant compliance "
        "per unit area, c = thickness_m m / E (as compliant as a steel layer thickness_m modules "
        "thick), in series with every tooth pair over its share of the flank, so the stiffness a "
        "preload gives grows with the flank area in contact and converges with the mesh "
        "(docs/fe-model.md, 'A compliant flank layer'). A modelling value: offered only where a "
        "campaign names it."),
    signature="every engaged state softer, the more so the fewer teeth carry the torque",
    parameters=(Parameter("thickness_m", "module", 0.0, 10000.0, 2000.0,
                          "equivalent steel thickness of the layer, in units of the module m",
                          "linear", 4),),
    apply=lambda ch, thickness_m: replace(ch, flank_layer_m=thickness_m),
    named_only=True,
    references="a locked preloaded design's Φ then converges with the mesh (hd42-lhs-23: 0.1313, "
               "0.1311, 0.1325 arcmin at 1, 1.25, 1.5x with 0.22 m and 1167 m)",
    off={"thickness_m": 0.0},
)
