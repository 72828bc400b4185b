"""Coulomb friction on the FS–CS tooth flanks."""

from dataclasses import replace

from . import Effect, Parameter

EFFECT = Effect(
    name="tooth_friction",
    title="Coulomb friction on the tooth flanks",
    description=(
        "The flanks of the flexspline and circular-spline teeth slide on each other while "
        "the torque rises and falls. Friction leans each contact force by the friction "
        "angle against the slip: while loading it helps carry the torque, while unloading "
        "it holds the teeth back, so the twist lags the torque. In the FE model every "
        "tooth contact gets a tangential force mu p against its slip (or, while it sticks, "
        "whatever tangential force keeps the slip at zero, up to mu p)."),
    signature=("loading and unloading branches separate (a hysteresis loop: the unloading "
               "branch lags); the lost motion itself changes little"),
    parameters=(Parameter("mu", "–", 0.0, 0.3, 0.08,
                          "friction coefficient of steel on steel, lubricated", "linear", 3),),
    apply=lambda ch, mu: replace(ch, flank_friction=mu),
    references="Taghirad & Bélanger 1996; Tjahjowidodo et al.; Dhaouadi & Ghorbel",
    off={"mu": 0.0},
)
