"""Geometry of the two harmonic drives of the seed paper (HD 42 and HD 120).

Hand-written because the paper gives only a handful of numbers (Tables 1-3: tooth counts,
test torque, bearing d/D/B/d1/D1, parameter bounds, tooth heights 0.337 mm and 1.0 mm);
every other dimension a finite-element model needs is *assumed* here, in ONE table
(``_UNIT_TABLE``) with its source or reason next to it.  Units: mm, N, MPa, rad.

Contents
--------
* ``DriveGeometry``: a frozen dataclass holding everything the mesh and the solver need for
  one design (unit constants + the five design variables d, D, G_r, r_FS, r_CS + the cam).
* ``drive_geometry(unit, d_mm, D_mm, Gr_mm, rFS_mm, rCS_mm)``: builds it.
* the wave-generator cam of the paper's Eq. 3 (``hdwf.drive.cam``),
  R = A + B cos(2 (pi/2)(phi/(pi/2))^n), with A, B solved numerically so that (1) the cam
  perimeter equals pi*d_nominal (the inner-ring bore is inextensible and wraps the cam) and
  (2) the nominal design pushes the flexspline (FS) out by deflection_coeff * w0 (w0 = m, the
  2-tooth difference) at the major axis.
* the tooth flanks: involutes (pressure angle alpha).  Why involute: it is the only profile
  whose normal offset is again the same profile rotated by offset/r_b, so a normal offset
  r_FS / r_CS maps to a *known* rigid-body backlash 2 (r_FS + r_CS) / r_b -- the analytic
  reference the FE model is tested against.  Harmonic Drive's own S-profile is patented and
  not given in the paper.  FS flanks are offset by r_FS normal to the flank into the tooth
  (thinner teeth, smaller dimension over pins), CS flanks by r_CS into the CS material
  (wider spaces, larger dimension between pins), as in the paper's Fig. 5.  Zero offsets
  are the nominal zero-backlash design: with the nominal bearing the major-axis FS tooth
  then sits in its CS space touching both flanks at the pitch point.
* preloaded engagement (``interference_m``, units of m, default 0): the FS flanks are
  thickened by a normal offset interference_m * m, so the wave generator presses the
  teeth into the CS spaces (a preloaded wedge) and r_FS + r_CS first relieve that preload.
* the other preload, a deeper cam (``deflection_coeff`` kappa = push / w0, w0 = m, default 1):
  the nominal bearing pushes the FS out by kappa * w0, so the major-axis teeth sit (kappa - 1) m deeper in
  their CS spaces than the flanks allow (an overlap of (kappa - 1) m sin(alpha) per flank) and
  only the teeth near the major axis are pressed in.  The tips then need more room than the
  0.1 h tip/root clearance of the default addenda: ``addendum_frac`` shortens both.
* ``offset_direction`` "radial" reads r_FS, r_CS as rack shifts (each flank moves normally by
  r sin(alpha)) instead of normal flank offsets (the default).
* ``geometric_backlash_rad/arcmin``: the rigid-body backlash the offsets create.

Levels versus the paper (read before comparing numbers): a normal flank offset r opens a
clearance r on each flank, so the rigid-body backlash alone is 2 (r_FS + r_CS) / r_b,CS,
e.g. 13.4 arcmin for the HD 42 upper bounds (20 + 20 um) and >= 5.9 arcmin for every
HD 120 design (offsets >= 25 um each).  The paper's Phi (0.18-1.49 / 0.64-2.51 arcmin) is
about ten times smaller than this kinematic bound, so its offsets cannot have opened
clearance one-to-one; with the definition used here our Phi ranks the paper's designs
well but its level is about ten times higher.  The cam is sized so that the *nominal*
bearing (d_nom, D_nom, G_r,nom) gives w0 = m (kappa w0 with a deeper cam); bore clearance (d > d_nom), a loose FS fit
(D < D_nom) and a larger G_r give less deflection, i.e. extra radial clearance that opens
dr sin(alpha) on each flank.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass, replace

import numpy as np

from hdwf.drive.cam import cam_for_push, cam_radius
from hdwf.drive.relief import tip_relief

ARCMIN = math.pi / (180.0 * 60.0)  # rad per arcmin

# --------------------------------------------------------------------------------------
# The one table of values.  "paper" = seed paper; "bg" = /work/shared/background.md
# (derived there from the paper); "assumed" = our choice, reason given.
# --------------------------------------------------------------------------------------
@dataclass(frozen=True)
class UnitData:
    """Constants of one drive (paper values and our assumptions, see ``_UNIT_TABLE``)."""
    z_fs: int
    z_cs: int
    torque_Nmm: float
    d_nom: float
    D_nom: float
    Gr_nom: float
    d1: float
    D1: float
    B: float
    module: float
    tooth_height: float
    addendum_frac: float
    alpha_deg: float
    face_fs: float
    face_cs: float
    cs_rim: float
    n_balls: int
    ball_dia: float
    groove_conf: float
    cam_n: float


_UNIT_TABLE: dict[str, "UnitData"] = {
    "hd42": UnitData(
        z_fs=240, z_cs=242,                 # paper Table 1
        torque_Nmm=960.0,                   # paper Table 1: 4 % of T_N = 24 N m -> 0.96 N m
        d_nom=31.000, D_nom=42.000,         # paper Tables 2/3 (113-1145TN)
        Gr_nom=0.015,                       # paper Table 3 nominal radial clearance
        d1=33.10, D1=40.10, B=7.00,         # paper Table 2 (raceway shoulders, width)
        module=0.18,                        # bg: FS bore = D, wall under roots ~2 m -> 0.18
        tooth_height=0.337,                 # paper, Conclusions
        addendum_frac=0.45,                 # assumed: addendum 0.45 h, dedendum 0.55 h leaves
                                            # 0.1 h tip/root clearance at the major axis
        alpha_deg=20.0,                     # assumed: standard involute pressure angle
        face_fs=7.0, face_cs=7.0,           # assumed: tooth face width = bearing width B
        cs_rim=3.0,                         # assumed: CS ring radial thickness below roots
                                            # (~17 m, CSF-17 proportions); clamped outside
        n_balls=24,                         # assumed: ~80 % of the 29 that fit on the pitch
                                            # circle; even -> 180 deg point symmetry
        ball_dia=3.969,                     # assumed: 5/32" ball fills the 3.5 mm shoulder
                                            # gap (D1-d1)/2 plus two groove depths
        groove_conf=0.52,                   # assumed: usual deep-groove conformity f = r/dw
        cam_n=1.0,                          # assumed: Eq. 3 exponent; n = 1 -> cos 2 phi cam
    ),
    "hd120": UnitData(
        z_fs=240, z_cs=242,                 # paper Table 1
        torque_Nmm=21160.0,                 # paper Table 1: 4 % of 529 N m
        d_nom=90.000, D_nom=120.000,        # paper Tables 2/3 (114-876TN)
        Gr_nom=0.030,                       # paper Table 3 nominal
        d1=95.20, D1=114.80, B=18.00,       # paper Table 2
        module=0.514,                       # bg: pitch dia ~123.3 mm
        tooth_height=1.0,                   # paper, Conclusions
        addendum_frac=0.45,                 # assumed, as HD 42
        alpha_deg=20.0,                     # assumed, as HD 42
        face_fs=18.0, face_cs=18.0,         # assumed: = bearing width B
        cs_rim=8.6,                         # assumed: HD 42 value scaled by module ratio
        n_balls=24,                         # assumed, as HD 42
        ball_dia=11.112,                    # assumed: 7/16" ball for the 9.8 mm shoulder gap
        groove_conf=0.52,                   # assumed
        cam_n=1.0,                          # assumed
    ),
}

# Where each value of the table comes from: printed in the report's assumptions table.
_SOURCES: dict[str, tuple[str, str]] = {   # field -> (unit of the value, source or reason)
    "z_fs": ("–", "paper Table 1"),
    "z_cs": ("–", "paper Table 1"),
    "torque_Nmm": ("N·mm", "paper Table 1: 4 % of the rated torque T_N"),
    "d_nom": ("mm", "paper Tables 2/3: nominal bearing bore"),
    "D_nom": ("mm", "paper Tables 2/3: nominal bearing outside diameter; the FS bore is made to it"),
    "Gr_nom": ("mm", "paper Table 3: nominal radial clearance; the cam is sized with it"),
    "d1": ("mm", "paper Table 2: inner-ring raceway shoulder"),
    "D1": ("mm", "paper Table 2: outer-ring raceway shoulder"),
    "B": ("mm", "paper Table 2: bearing width"),
    "module": ("mm", "background: FS bore = D and wall under the roots about 2 modules"),
    "tooth_height": ("mm", "paper, Conclusions"),
    "addendum_frac": ("–", "assumed: addendum 0.45 h, dedendum 0.55 h leave 0.1 h tip/root clearance"),
    "alpha_deg": ("°", "assumed: involute pressure angle 20° (standard)"),
    "face_fs": ("mm", "assumed: FS tooth face width = bearing width B"),
    "face_cs": ("mm", "assumed: CS tooth face width = bearing width B"),
    "cs_rim": ("mm", "assumed: CS rim under the roots (CSF-17 proportions, scaled by module for HD 120)"),
    "n_balls": ("–", "assumed: about 80 % of the balls that fit; even for 180° symmetry"),
    "ball_dia": ("mm", "assumed: inch ball filling the shoulder gap (D1 − d1)/2 plus two groove depths"),
    "groove_conf": ("–", "assumed: usual deep-groove conformity f = r/d_w"),
    "cam_n": ("–", "assumed: Eq. 3 exponent n = 1 (a cos 2φ cam)"),
}


def assumptions_table() -> list[dict]:
    """Every constant of both drives with its unit and source, for the report."""
    rows = []
    for unit, data in _UNIT_TABLE.items():
        for name, (quantity_unit, source) in _SOURCES.items():
            value = getattr(data, name)
            rows.append({"unit": {"hd42": "HD 42", "hd120": "HD 120"}[unit], "name": name,
                         "value": f"{value:g} {quantity_unit}".replace(" –", ""), "source": source})
    rows.append({"unit": "both", "name": "E, ν", "value": f"{E_STEEL:g} MPa, {NU_STEEL:g}", "source": "paper Sect. 4"})
    return rows


E_STEEL = 210_000.0  # MPa, paper Sec. 4
NU_STEEL = 0.3       # paper Sec. 4
# the largest tip round (units of m): its tangent length (about 0.64 rho at a 115 deg corner)
# must stay on the narrowest tip land, HD 42's FS tip, 0.47 m to either side of its middle
MAX_TIP_ROUND_M = 0.25


@dataclass(frozen=True)
class DriveGeometry:
    unit: str
    # design variables (paper Table 3)
    d: float
    D: float
    Gr: float
    r_fs: float
    r_cs: float
    # unit constants
    z_fs: int
    z_cs: int
    module: float
    alpha: float            # pressure angle, rad
    torque: float           # test torque, N mm
    E: float
    nu: float
    face_fs: float
    face_cs: float
    # bearing
    d_nom: float
    D_nom: float
    Gr_nom: float
    d1: float
    D1: float
    B: float
    n_balls: int
    ball_dia: float
    groove_conf: float
    # FS (external teeth); FS bore is made to the nominal bearing OD
    r_fs_bore: float
    r_fs_root: float
    r_fs_pitch: float
    r_fs_tip: float
    # CS (internal teeth)
    r_cs_tip: float
    r_cs_pitch: float
    r_cs_root: float
    r_cs_outer: float
    # cam of Eq. 3
    cam_A: float
    cam_B: float
    cam_n: float
    # preloaded engagement: normal flank interference of the nominal design, in units of m
    interference_m: float = 0.0
    # tip relief, in units of the relief the FS tooth's path needs (``hdwf.drive.relief``)
    tip_relief: float = 0.0
    # radius of the round of the FS and CS tip corners, in units of m (0 = sharp corners)
    tip_round_m: float = 0.0
    # deflection coefficient: the nominal bearing pushes the FS out by this many w0 (> 1: the
    # major-axis teeth are pressed radially into the CS spaces)
    deflection_coeff: float = 1.0
    # how r_FS, r_CS move a flank: "normal" (a normal offset of r) or "radial" (a rack shift
    # of r, i.e. a normal offset of r sin(alpha))
    offset_direction: str = "normal"
    # compliance of a layer on the flanks (um of approach per MPa of contact pressure, 0 = none):
    # the 3D cup's compliance under each tooth, spread over the flank (``contact_rows``)
    flank_layer_um_per_MPa: float = 0.0
    # the layer integrated along the FS outline alone (one contact pass; ``contact_rows``)
    flank_layer_fs_pass_only: bool = False

    # ---- derived quantities -------------------------------------------------------
    @property
    def w0(self) -> float:
        """Radial deflection of the FS at the major axis that the 2-tooth difference asks for (m);
        the cam pushes ``deflection_coeff`` times this."""
        return self.module * (self.z_cs - self.z_fs) / 2.0

    @property
    def preloaded(self) -> bool:
        """Whether the wave generator presses the teeth in (a flank allowance or a deeper cam)."""
        return self.interference_m > 0 or self.deflection_coeff > 1

    @property
    def flank_offsets(self) -> tuple[float, float]:
        """Normal offsets (mm) of the FS and CS flanks that r_FS and r_CS make."""
        scale = math.sin(self.alpha) if self.offset_direction == "radial" else 1.0
        return self.r_fs * scale, self.r_cs * scale

    @property
    def interference(self) -> float:
        """Normal interference per flank (mm) the FS teeth are made thicker by (preload)."""
        return self.interference_m * self.module

    @property
    def tip_round(self) -> float:
        """Radius (mm) of the FS and CS tip corners' round (0: sharp)."""
        return self.tip_round_m * self.module

    @property
    def addendum(self) -> float:
        """Addendum h_a of FS and CS teeth (mm)."""
        return self.r_fs_tip - self.r_fs_pitch

    def relief(self, depth):
        """Tangential tip relief (mm) of a flank ``depth`` (mm) below its tooth's tip:
        ``tip_relief`` times ``hdwf.drive.relief.tip_relief``."""
        if not self.tip_relief:
            return 0.0
        return self.tip_relief * tip_relief(depth, self.module, self.addendum, self.alpha,
                                            self.tilt_factor)

    @property
    def tilt_factor(self) -> float:
        """kappa = 1 - 3 (r_tip - r_n) / r_n: the FS tip's tangential displacement over the
        wall mid-line's (the cross-section turns with the ring; ``hdwf.drive.relief``)."""
        r_n = 0.5 * (self.r_fs_bore + self.r_fs_root)
        return 1.0 - 3.0 * (self.r_fs_tip - r_n) / r_n

    @property
    def r_fs_base(self) -> float:
        return self.r_fs_pitch * math.cos(self.alpha)

    @property
    def r_cs_base(self) -> float:
        return self.r_cs_pitch * math.cos(self.alpha)

    @property
    def ir_bore(self) -> float:
        """Inner ring bore radius (design variable d)."""
        return self.d / 2.0

    @property
    def ir_race(self) -> float:
        return self.d1 / 2.0

    @property
    def or_race(self) -> float:
        return self.D1 / 2.0

    @property
    def or_outer(self) -> float:
        """Outer ring outer radius (design variable D)."""
        return self.D / 2.0

    @property
    def ball_gap(self) -> float:
        """Radial gap per ball: half the radial internal clearance G_r."""
        return self.Gr / 2.0

    @property
    def arcmin_per_um(self) -> float:
        """Rotation of the FS pitch circle per micrometre of arc, arcmin."""
        return 1e-3 / self.r_fs_pitch / ARCMIN

    def cam_radius(self, phi):
        return cam_radius(phi, self.cam_A, self.cam_B, self.cam_n)


def unit_data(unit: str) -> UnitData:
    """The frozen constants of "hd42" or "hd120"."""
    try:
        return _UNIT_TABLE[unit.lower()]
    except KeyError:
        raise ValueError(f"unknown unit {unit!r}; expected one of {sorted(_UNIT_TABLE)}")


# --------------------------------------------------------------------------------------
# Involute flanks
# --------------------------------------------------------------------------------------
def inv(a):
    return np.tan(a) - a


def fs_half_angle(g: DriveGeometry, r):
    """Half tooth-thickness angle of an FS tooth at radius r (tooth centred on angle 0).

    Nominal arc thickness at the pitch circle is pi m / 2; the normal offset r_FS on each
    flank rotates that involute by r_FS / r_b towards the tooth centre, the preload
    interference (``interference``, a thickness allowance) by as much away from it.
    """
    r = np.asarray(r, dtype=float)
    rb = g.r_fs_base
    ar = np.arccos(np.clip(rb / r, -1, 1))
    out = ((math.pi * g.module / 2) / (2 * g.r_fs_pitch) + inv(g.alpha) - inv(ar)
           - (g.flank_offsets[0] - g.interference) / rb)
    return out - g.relief(g.r_fs_tip - r) / r if g.tip_relief else out


def cs_half_space_angle(g: DriveGeometry, r):
    """Half space-width angle of a CS tooth space at radius r (space centred on angle 0).

    The space of an internal gear is the mirror of an external tooth cut by the same rack,
    so it has the same involute form; r_CS widens it by r_CS / r_b per flank.
    """
    r = np.asarray(r, dtype=float)
    rb = g.r_cs_base
    ar = np.arccos(np.clip(rb / r, -1, 1))
    out = (math.pi * g.module / 2) / (2 * g.r_cs_pitch) + inv(g.alpha) - inv(ar) + g.flank_offsets[1] / rb
    return out + g.relief(r - g.r_cs_tip) / r if g.tip_relief else out


# --------------------------------------------------------------------------------------
# Rigid-body backlash (analytic reference)
# --------------------------------------------------------------------------------------
def geometric_backlash_rad(g: DriveGeometry, radial_shortfall_mm: float = 0.0) -> float:
    """Rigid-body lost motion of the major-axis tooth pair, rad.

    At the major axis the FS pitch point coincides with the CS pitch point P (radius
    r_pCS).  Both flanks are involutes through P with pressure angle alpha there, so the
    normal clearance on each flank is the flank offsets of r_FS + r_CS (``flank_offsets``:
    r_FS + r_CS, or (r_FS + r_CS) sin(alpha) for rack shifts), + radial_shortfall * sin(alpha)
    if the FS does not reach the full deflection w0, and a rigid FS rotation psi about the
    drive centre closes it at the rate |x_P x n| = r_pCS cos(alpha) = r_b,CS.  The FS can turn
    both ways, so Phi = 2 (clearance) / r_b,CS.  A preload interference delta enters as
    -delta, a deeper cam as -(kappa - 1) w0 sin(alpha) (a negative result is a preloaded,
    rigidly locked pair).  With kappa > 1 a tooth off the axis touches first (its tangential
    offset closes one flank faster than its withdrawal opens it), so the lost motion is then
    below this major-axis value (tests/fe/test_preload.py, the rack path).
    """
    gap = (sum(g.flank_offsets) - g.interference
           - (g.deflection_coeff - 1.0) * g.w0 * math.sin(g.alpha)
           + radial_shortfall_mm * math.sin(g.alpha))
    return 2.0 * gap / g.r_cs_base


def geometric_backlash_arcmin(g: DriveGeometry, radial_shortfall_mm: float = 0.0) -> float:
    return geometric_backlash_rad(g, radial_shortfall_mm) / ARCMIN


# --------------------------------------------------------------------------------------
# Builder
# --------------------------------------------------------------------------------------
def drive_geometry(unit: str, d_mm: float, D_mm: float, Gr_mm: float, rFS_mm: float,
                   rCS_mm: float, *, interference_m: float = 0.0,
                   tip_relief: float = 0.0, deflection_coeff: float = 1.0,
                   addendum_frac: float | None = None, tip_round_m: float = 0.0,
                   offset_direction: str = "normal") -> DriveGeometry:
    """Geometry of one design of unit "hd42" or "hd120" (all lengths in mm).

    ``interference_m`` (>= 0, units of the module m): preloaded engagement.  The FS teeth
    are made thicker by a normal offset of interference_m * m on each flank (a tooth
    thickness allowance), so with the nominal bearing the major-axis tooth would overlap
    its CS space by that much on both flanks: the wave generator presses it in as a
    preloaded wedge, and r_FS + r_CS first relieve that preload before clearance opens.
    0 (the default) is the zero-interference design of the 2-tooth difference.

    ``tip_relief`` (>= 0): FS and CS tips relieved by this multiple of the relief the FS
    tooth's path needs to leave the mesh without crossing the CS tips
    (``hdwf.drive.relief``); 0 (the default) keeps the plain involutes, whose tips cross
    51-69 deg from the major axis.

    ``tip_round_m`` (in [0, 0.25], units of m): the tip corners of FS and CS teeth rounded with
    this radius, tangent to the flank and the tip circle (``hdwf.drive.sector_mesh``); 0 (the
    default) keeps them sharp.  Where the tips cross in the exit zone a sharp corner pressed
    into a flank is a contact a node or two long that moves with the mesh; a round is
    resolved by several (docs/fe-model.md, "Mesh convergence").

    ``deflection_coeff`` (kappa in [1, 2)): the cam is sized so that the nominal bearing pushes
    the FS out by kappa * w0 at the major axis; 1 (the default) is the 2-tooth difference with
    the teeth just touching, > 1 presses the teeth near the major axis into their spaces.

    ``offset_direction`` ("normal", the default, or "radial"): r_FS and r_CS as normal offsets
    of the flanks, or as radial shifts of the cutting rack (a normal offset of r sin(alpha)).

    ``addendum_frac`` (in [0.2, 0.5], default the unit's 0.45): addendum of FS and CS teeth as
    a fraction of the tooth height h; the tip/root clearance at the major axis is (1 - 2 *
    addendum_frac) h, which a deeper cam eats by (kappa - 1) m.
    """
    if not (interference_m >= 0.0 and math.isfinite(interference_m)):
        raise ValueError(f"interference_m must be finite and >= 0, got {interference_m!r}")
    if not (tip_relief >= 0.0 and math.isfinite(tip_relief)):
        raise ValueError(f"tip_relief must be finite and >= 0, got {tip_relief!r}")
    if not (0.0 <= tip_round_m <= MAX_TIP_ROUND_M):
        raise ValueError(f"tip_round_m must be in [0, {MAX_TIP_ROUND_M}] (units of m), got {tip_round_m!r}")
    if offset_direction not in ("normal", "radial"):
        raise ValueError(f"offset_direction must be 'normal' or 'radial', got {offset_direction!r}")
    if not (1.0 <= deflection_coeff < 2.0):
        raise ValueError(f"deflection_coeff must be in [1, 2), got {deflection_coeff!r}")
    if tip_relief and deflection_coeff != 1.0:
        raise ValueError("tip_relief is derived on the path of the 2-tooth push (deflection_coeff 1); "
                         f"got deflection_coeff={deflection_coeff!r} with tip_relief={tip_relief!r}")
    t = asdict(unit_data(unit))
    if addendum_frac is not None:
        if not (0.2 <= addendum_frac <= 0.5):
            raise ValueError(f"addendum_frac must be in [0.2, 0.5], got {addendum_frac!r}")
        t["addendum_frac"] = float(addendum_frac)
    m = t["module"]
    h = t["tooth_height"]
    ha = t["addendum_frac"] * h
    hf = h - ha
    r_fs_pitch = t["z_fs"] * m / 2
    r_cs_pitch = t["z_cs"] * m / 2
    w0 = m * (t["z_cs"] - t["z_fs"]) / 2
    A, B = cam_for_push(t["d_nom"], t["Gr_nom"], deflection_coeff * w0, t["cam_n"])
    return DriveGeometry(
        unit=unit.lower(), d=float(d_mm), D=float(D_mm), Gr=float(Gr_mm),
        r_fs=float(rFS_mm), r_cs=float(rCS_mm),
        z_fs=int(t["z_fs"]), z_cs=int(t["z_cs"]), module=m,
        alpha=math.radians(t["alpha_deg"]), torque=t["torque_Nmm"], E=E_STEEL, nu=NU_STEEL,
        face_fs=t["face_fs"], face_cs=t["face_cs"],
        d_nom=t["d_nom"], D_nom=t["D_nom"], Gr_nom=t["Gr_nom"], d1=t["d1"], D1=t["D1"],
        B=t["B"], n_balls=int(t["n_balls"]), ball_dia=t["ball_dia"],
        groove_conf=t["groove_conf"],
        r_fs_bore=t["D_nom"] / 2, r_fs_root=r_fs_pitch - hf, r_fs_pitch=r_fs_pitch,
        r_fs_tip=r_fs_pitch + ha,
        r_cs_tip=r_cs_pitch - ha, r_cs_pitch=r_cs_pitch, r_cs_root=r_cs_pitch + hf,
        r_cs_outer=r_cs_pitch + hf + t["cs_rim"],
        cam_A=A, cam_B=B, cam_n=t["cam_n"], interference_m=float(interference_m),
        tip_relief=float(tip_relief), deflection_coeff=float(deflection_coeff),
        offset_direction=offset_direction, tip_round_m=float(tip_round_m),
    )


def nominal_geometry(unit: str) -> DriveGeometry:
    """Table 3 nominal design (zero offsets for HD 42, 0.025 mm for HD 120)."""
    if unit.lower() == "hd42":
        return drive_geometry("hd42", 31.0, 42.0, 0.015, 0.0, 0.0)
    return drive_geometry("hd120", 90.0, 120.0, 0.030, 0.025, 0.025)


def with_changes(g: DriveGeometry, **kw) -> DriveGeometry:
    """Copy with some fields replaced (e.g. a stiffer E for the rigid-body limit)."""
    return replace(g, **kw)
