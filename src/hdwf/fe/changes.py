"""The physical additions to the baseline FE model, switched on one by one: ``ModelChanges``.

The baseline has frictionless flanks, the CS clamped on its whole outer rim, FS and CS at one
temperature and the output read on the FS rim; ``hdwf.validation.effects`` maps each candidate
effect onto a field here, so every effect is a change of the model, never a correction of its
output.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

from hdwf.drive.relief import PRELOAD_TIP_RELIEF


@dataclass(frozen=True)
class ModelChanges:
    """Physical additions to the baseline model (frictionless flanks, CS clamped on its
    whole outer rim, FS and CS at one temperature, output read on the FS rim).

    ``hdwf.validation.effects`` maps each candidate effect's parameters onto these; every field is a
    change to the FE model itself:

    * ``flank_friction``: Coulomb coefficient on the FS-CS tooth contacts.  A sliding pair's
      force becomes p (n + mu sigma t), sigma = -sign of its slip over the load step; a
      sticking pair carries an unknown tangential force (|f_t| <= mu p) and does not slip.
    * ``cs_rim_stiffness_N_mm2``: the CS outer rim held by radial and tangential springs
      of this stiffness per mm of rim (an elastic housing) instead of clamped (inf).
    * ``cs_scale``: the CS mesh scaled about the axis by this factor, i.e. a uniform
      thermal strain of the CS relative to the FS and wave generator (1 = same
      temperature; plane-stress stiffness is scale-invariant, only the fit changes).
    * ``output_compliance_rad_per_Nmm``: a torsional spring in series between the FS rim
      and the output where the twist is measured (the FS cup and diaphragm).
    * ``output_play_rad``: a dead band in series in the output chain (e.g. the wave
      generator's Oldham coupling, seen at the output).
    * ``output_microslip_loop_rad``: a micro-slip (Iwan) element in series in the output
      chain, given by the width w (rad) of the hysteresis loop it opens at zero torque in the
      lost-motion test 0 -> +T -> 0 -> -T -> 0.  It is the Iwan/Masing element (springs
      bridged by Coulomb sliders, the compliance spread evenly over their slip torques) of
      density a = 2 w / T^2, T the peak torque of the path (the test torque); its twist
      follows the load path with the Masing rule (``hdwf.fe.series.microslip_twist``).
    * ``flank_interference_m``: preloaded engagement, the FS teeth thicker by this many modules
      on each flank (``DriveGeometry.interference_m``), their tips relieved as a preload needs
      (``hdwf.drive.relief.PRELOAD_TIP_RELIEF``). It changes the section's outline, so the
      geometry must carry it (``geometry_part``): a variant with it gets an FS meshed on its own.
    * ``flank_layer_m``: a compliant layer on the tooth flanks, as compliant as a steel layer
      this many modules thick: c = flank_layer_m m / E (mm of approach per MPa of contact
      pressure), in series with every tooth pair over its share of the flank (``contact_rows``).
      It stands for compliance under each tooth that a plane section lacks (the 3D cup and
      face); the mesh is unchanged, the solve carries it (``DriveGeometry.flank_layer_um_per_MPa``).
    * ``flank_layer_fs_pass_only``: how the layer is solved, not a physical addition: its overlap
      integrated along the FS outline alone (the FS nodes against the CS segments, each overlap
      counted once) instead of both passes (the CS tip pass counts the overlap at a CS tip corner
      again).  With the tip corners rounded and 25 segments a flank, 52 of the 54 `fe` designs
      change by less than 2 % on a 1.25x finer mesh, at 3.2-3.5 times the solve (docs/fe-model.md,
      "Mesh convergence"; ``workflow/overlays/converged_contact.yaml``).
    * ``coning_slope``: the FS cup's coning c = b / z_0: the wave generator's push grows as
      w0 (1 + c zeta) across the face width (zeta = 0 at the diaphragm end), solved as
      ``coning_slices`` sections in parallel on one twist (``hdwf.fe.coning``; 0 = the uniform
      section).  Eight slices: doubling them moves Phi by less than 1 % on every design of
      Tables 4/5 (docs/fe-model.md, "Coning").
    """
    flank_friction: float = 0.0
    cs_rim_stiffness_N_mm2: float = math.inf
    cs_scale: float = 1.0
    output_compliance_rad_per_Nmm: float = 0.0
    output_play_rad: float = 0.0
    output_microslip_loop_rad: float = 0.0
    flank_interference_m: float = 0.0
    flank_layer_m: float = 0.0
    flank_layer_fs_pass_only: bool = False
    coning_slope: float = 0.0
    coning_slices: int = 8

    def layer_um_per_MPa(self, module_mm: float, E_MPa: float) -> float:
        """The flank layer's compliance (um per MPa) of a drive of this module and modulus."""
        return 1e3 * self.flank_layer_m * module_mm / E_MPa

    def geometry_part(self) -> dict[str, float]:
        """The ``drive_geometry`` arguments these changes need (``interference_m``, ``tip_relief``)."""
        relieved = PRELOAD_TIP_RELIEF if self.flank_interference_m > 0 else 0.0
        return {"interference_m": self.flank_interference_m, "tip_relief": relieved}

    def fe_part(self) -> "ModelChanges":
        """The changes that need a new contact solve: all but the series elements."""
        return replace(self, output_compliance_rad_per_Nmm=0.0, output_play_rad=0.0,
                       output_microslip_loop_rad=0.0)
