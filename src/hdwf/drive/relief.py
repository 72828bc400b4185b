"""Tip relief that lets the teeth leave the mesh: derived from the FS tooth's path.

The wave generator moves each FS tooth relative to the CS along the path of the mounted
flexspline (an inextensible ring pushed out by w = w0 cos 2 phi, so its tangential
displacement is v = -(w0/2) sin 2 phi).  With the 2-tooth difference (w0 = m) and the
pitch circles unrolled to racks (the rack approximation of harmonic-drive tooth design;
r_p = 120 m is large against a tooth), the FS tooth at phi from the major axis sits

* radially withdrawn from full depth by  Delta(phi) = m (1 - cos 2 phi),
* tangentially ahead of its CS space by   s(phi) = (m/2) (2 phi - kappa sin 2 phi)

(a cycloid for kappa = 1).  kappa carries the tooth's tilt: the wall's cross-section turns
with the ring by chi = (v - w') / r_n = 1.5 w0 sin 2 phi / r_n (Kirchhoff), which moves a
point c outside the wall's mid-line r_n back by chi c, so a tooth point at radius r
advances with kappa = 1 - 3 (r - r_n) / r_n (0.92 at the FS tip of both drives; the FE mount
gives 0.92 at the pitch circle).  It is taken at the FS tip, where the tips cross.
Straight-sided (rack) flanks of pressure angle alpha then overlap by e(phi) = s - Delta
tan(alpha) along the pitch line wherever the tips still reach past each other, i.e. over the
band of depth D(phi) = 2 h_a - Delta(phi) between the two tips.  e is negative on the way
out of the working zone (the withdrawal opens more than the advance closes) and turns
positive again at 2 phi - kappa sin 2 phi = 2 tan(alpha) (1 - cos 2 phi) (phi = 51 deg for
20 deg and kappa = 0.923; 55 deg for kappa = 1): from there until the tips clear radially
(Delta = 2 h_a, phi = 66.5 deg for h_a = 0.84 m) the tip corners of FS and CS cross each
other -- the exit-zone overlap of the unrelieved profile.  (Below 6 deg the tilt makes
e > 0 by less than 1 um; there the teeth are in their involute working contact, not
crossing, and the rule leaves them alone: only the exit branch is relieved.)

The relief removes exactly that crossing, half from each tooth: at depth d below its tip,
each flank (FS and CS alike) is relieved tangentially by

    c(d) = 1/2 e(phi_d),   cos 2 phi_d = 1 - (2 h_a - d) / m,

(0 where e <= 0, and below d_0).  Why it suffices: the band of the tooth at phi covers depths d_FS + d_CS =
D(phi), and c decreases with d, so c(d_FS) + c(d_CS) >= 2 c(D(phi)) = e(phi).  Why it is
the least such relief split evenly: at d = D(phi) the two tips just meet (d_FS = D, d_CS =
0 and the reverse), so 2 c(d) = e is needed there.  It starts at the depth
d_0 = 2 h_a - Delta(phi_0) from the tip (e(phi_0) = 0) and is largest at the tip.  It does
not depend on the design variables (d, D, G_r, r_FS, r_CS: those only move the flanks) and
leaves the flanks below d_0, where the working contacts lie, unchanged.
"""

from __future__ import annotations

import math

import numpy as np
from scipy.optimize import brentq

# The relief a preloaded engagement is solved with (``DriveGeometry.tip_relief``), 10 % over the
# derived one: the mounted FS withdraws a little less than the rack path, and at 1.0 the tips of
# loose-bearing designs still touched at the exit (docs/fe-model.md, "Tip relief").
PRELOAD_TIP_RELIEF = 1.1


def _advance(two_phi, kappa):
    """The FS tooth's tangential advance s / m at 2 phi."""
    return 0.5 * (two_phi - kappa * np.sin(two_phi))


def tip_relief(depth, module: float, addendum: float, alpha: float, kappa: float = 1.0):
    """Tangential tip relief (mm) of a flank at ``depth`` (mm, >= 0) below its tooth tip.

    Parameters
    ----------
    depth : array_like
        Depth below the tip of the tooth (FS: r_tip - r; CS: r - r_tip), mm.
    module : float
        The module m (= w0, the 2-tooth difference), mm.
    addendum : float
        The addendum h_a of FS and CS teeth, mm.
    alpha : float
        Pressure angle, rad.
    kappa : float
        Tilt factor of the tangential displacement, 1 - 3 (r_tip - r_n) / r_n.

    Returns
    -------
    numpy.ndarray
        c(d) = 1/2 (s - Delta tan(alpha)) at the tooth position whose tip band just reaches
        depth d; 0 where the path does not make the tips cross.
    """
    d = np.asarray(depth, dtype=float)
    withdrawal = np.clip(2.0 * addendum - d, 0.0, 2.0 * module)      # Delta(phi_d)
    two_phi = np.arccos(np.clip(1.0 - withdrawal / module, -1.0, 1.0))
    e = module * _advance(two_phi, kappa) - withdrawal * math.tan(alpha)
    # the exit branch only: near the major axis the tilt makes e > 0 by < 1 um (kappa < 1,
    # phi < 6 deg), where the teeth are in their working (involute) contact, not crossing
    exit_branch = (d >= 0.0) & (d <= relief_start_depth(module, addendum, alpha, kappa))
    return np.where(exit_branch, 0.5 * np.maximum(e, 0.0), 0.0)


def relief_start_depth(module: float, addendum: float, alpha: float,
                       kappa: float = 1.0) -> float:
    """Depth below the tip (mm) where the relief starts (e = 0 on the path); 0 if none."""
    # the exit root of e in 2 phi: e < 0 at 60 deg, > 0 at 180 deg
    two_phi = brentq(lambda t: _advance(t, kappa) - math.tan(alpha) * (1.0 - math.cos(t)),
                     math.pi / 3, math.pi, xtol=1e-15)
    return max(0.0, 2.0 * addendum - module * (1.0 - math.cos(two_phi)))
