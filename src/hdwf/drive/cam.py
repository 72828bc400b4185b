"""The wave-generator cam of the paper's Eq. 3: R = A + B cos(2 (pi/2) (phi/(pi/2))^n).

Its radius, perimeter and polyline; ``size_cam``, which solves A and B so that the inner
ring's bore (inextensible, pi d_nom long) wraps the cam and the cam reaches a given radius at
the major axis; and ``cam_for_push``, the cam with which the nominal bearing pushes the
flexspline out by a given amount.  Units: mm, rad.
"""

from __future__ import annotations

import math

import numpy as np
from scipy.optimize import brentq


def _fold(phi):
    """Map any angle to [0, pi/2] with the cam's two mirror symmetries."""
    p = np.mod(np.asarray(phi, dtype=float), np.pi)
    return np.where(p > np.pi / 2, np.pi - p, p)


def cam_radius(phi, A: float, B: float, n: float):
    """R(phi) = A + B cos(2 (pi/2) (phi/(pi/2))^n), mirrored to the full circle."""
    p = _fold(phi)
    return A + B * np.cos(np.pi * (p / (np.pi / 2)) ** n)


def cam_perimeter(A: float, B: float, n: float, npts: int = 20000) -> float:
    """Perimeter of the closed cam curve (dense polyline, chord error ~1e-9 mm)."""
    phi = np.linspace(0.0, np.pi / 2, npts + 1)
    r = cam_radius(phi, A, B, n)
    x, y = r * np.cos(phi), r * np.sin(phi)
    return 4.0 * float(np.sum(np.hypot(np.diff(x), np.diff(y))))


def cam_points(A: float, B: float, n: float, npts: int = 4096) -> np.ndarray:
    """Closed polyline (npts x 2) of the cam, counter-clockwise from the major axis."""
    phi = np.linspace(0.0, 2 * np.pi, npts, endpoint=False)
    r = cam_radius(phi, A, B, n)
    return np.column_stack([r * np.cos(phi), r * np.sin(phi)])


def size_cam(d_nom: float, major_radius: float, n: float) -> tuple[float, float]:
    """Solve A, B: perimeter = pi d_nom and A + B = major_radius (cam radius at phi = 0)."""
    def res(B):
        return cam_perimeter(major_radius - B, B, n) - math.pi * d_nom
    B = brentq(res, 0.0, 0.2 * major_radius, xtol=1e-12)
    return major_radius - B, B


def cam_for_push(d_nom: float, Gr_nom: float, push: float, n: float) -> tuple[float, float]:
    """A, B of the cam with which the nominal bearing (bore d_nom wrapped on the cam, radial
    clearance Gr_nom, OD = FS bore) pushes the FS out by ``push`` at the major axis, rigid-body:
    A + B is the bore radius + push + Gr_nom/2 (the ball gap on the loaded side)."""
    return size_cam(d_nom, d_nom / 2 + push + Gr_nom / 2, n)
