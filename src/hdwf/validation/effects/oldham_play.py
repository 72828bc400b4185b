"""Play of the wave generator's Oldham coupling, seen at the output."""

import math
from dataclasses import replace

from . import Effect, Parameter

ARCSEC = math.pi / (180 * 3600)

EFFECT = Effect(
    name="oldham_play",
    title="Oldham coupling play",
    description=(
        "The wave generator sits on its shaft through an Oldham coupling with a little play. "
        "With the input locked, the wave generator can still turn within that play, and the "
        "output turns with it divided by the ratio, so at every torque reversal the output "
        "moves through a small free angle. In the FE model it is a dead band in series "
        "between the locked input and the output."),
    signature="a pure dead band at the reversal: the two halves of the curve move apart, "
              "slopes unchanged",
    parameters=(Parameter("play_arcsec", "arcsec", 0.0, 30.0, 10.0,
                          "free angle at the output (catalogue: 4–20 arcsec)", "linear"),),
    apply=lambda ch, play_arcsec: replace(ch, output_play_rad=ch.output_play_rad
                                          + play_arcsec * ARCSEC),
    series=True,
    references="makers' catalogues: about 8 arcsec (sizes 17–25), 5 arcsec (size 50)",
    off={"play_arcsec": 0.0},
)
