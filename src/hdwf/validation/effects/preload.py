"""Preloaded tooth engagement: the FS teeth made thicker than the CS spaces leave room for."""

from dataclasses import replace

from . import Effect, Parameter

EFFECT = Effect(
    name="preload",
    title="Preloaded tooth engagement (tooth-thickness interference)",
    description=(
        "A harmonic drive has almost no backlash because the wave generator presses the FS "
        "teeth into the CS spaces at the major axis: the teeth are made thicker than the "
        "spaces leave room for, a preloaded wedge. A tooth offset r_FS or r_CS then first only "
        "relieves that preload, and play opens only once it is used up. The baseline section "
        "has none (the teeth just touch at zero offsets). In the FE model each FS flank is "
        "thickened along its normal by interference_m times the module, the tips relieved as "
        "the preload needs, and the wave generator is mounted on a preload ramp "
        "(docs/fe-model.md, 'Preloaded engagement'). A design value: offered only where a "
        "campaign names it."),
    signature="the dead band shrinks and closes once the preload takes the clearance up; "
              "the elastic slopes stay",
    parameters=(Parameter("interference_m", "module", 0.0, 0.3, 0.15,
                          "normal interference per FS flank, in units of the module m",
                          "linear", 6),),
    apply=lambda ch, interference_m: replace(ch, flank_interference_m=interference_m),
    named_only=True,
    references="the paper's Tables 4/5 take up about 0.14-0.15 m of offset before play opens "
               "(hinge fit, hdwf.study.knee)",
    off={"interference_m": 0.0},
)
