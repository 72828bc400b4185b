"""Torsion of the flexspline cup and diaphragm between the toothed rim and the output."""

from dataclasses import replace

from . import Effect, Parameter

EFFECT = Effect(
    name="fs_cup_torsion",
    title="Flexspline cup torsion",
    description=(
        "The 2D section loads the toothed rim, but the bench reads the twist at the output "
        "flange, at the far end of the flexspline's thin cup and diaphragm. The cup twists "
        "under the torque like a thin tube, K = 2 pi G R^3 t / L, a spring in series with "
        "everything the section models. In the FE model it is a torsional spring between "
        "the rim and the output."),
    signature="extra twist proportional to the torque: a steeper curve, no dead band, no loop",
    parameters=(Parameter("K_Nm_per_rad", "N·m/rad", 1.0e3, 1.0e7, 6.0e4,
                          "torsional stiffness of cup and diaphragm (thin tube: 2 pi G R^3 t / L)",
                          "reciprocal",
                          # R, t and L all grow with the drive: K ~ size^3, (120/42)^3 = 23.3
                          realistic_by_unit=(("hd120", 1.4e6),)),),
    apply=lambda ch, K_Nm_per_rad: replace(
        ch, output_compliance_rad_per_Nmm=ch.output_compliance_rad_per_Nmm
        + 1.0 / (K_Nm_per_rad * 1000.0)),
    series=True,
    references="thin-walled tube in torsion; about 15 % of a 42 mm unit's compliance",
    off={"K_Nm_per_rad": float("inf")},
)
