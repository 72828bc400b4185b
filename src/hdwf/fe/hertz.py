"""Hertz law of a bearing ball: the elastic approach of its two raceway contacts, and their
largest contact pressure.

The balls are discrete elements between the raceways (``contact_rows``); each adds the
approach delta = c P^(2/3) of exact elliptic-contact Hertz theory, both raceway contacts in
series, to the contact problem as a secant compliance (``solver``).  The largest pressure of
a ball's contacts is what ISO 76 rates a ball bearing by: 4200 MPa at the most heavily loaded
contact is its basic static load rating, where the raceways begin to dent permanently.
"""

from __future__ import annotations

import math

from scipy.optimize import brentq
from scipy.special import ellipe, ellipk

from hdwf.drive.geometry import DriveGeometry

#: ISO 76: a ball bearing's basic static load rating is the load that gives this contact
#: pressure (MPa) at the centre of its most heavily loaded ball contact (permanent dent of about
#: 1e-4 of the ball diameter); a larger one dents the raceways.
ISO76_BALL_PRESSURE_MPA = 4200.0


def _ellipse(rho_x: float, rho_y: float) -> tuple[float, float, float]:
    """Ellipticity k = a/b of the contact and the complete elliptic integrals K(e), E(e).

    Harris / Hamrock:  F(rho) = ((k^2+1) E(e) - 2 K(e)) / ((k^2-1) E(e)), e^2 = 1 - 1/k^2,
    F(rho) = |rho_x - rho_y| / (rho_x + rho_y).
    """
    Frho = abs(rho_x - rho_y) / (rho_x + rho_y)
    if Frho < 1e-12:
        return 1.0, math.pi / 2, math.pi / 2

    def res(k):
        m = 1 - 1 / k ** 2
        return ((k ** 2 + 1) * ellipe(m) - 2 * ellipk(m)) / ((k ** 2 - 1) * ellipe(m)) - Frho
    k = brentq(res, 1 + 1e-9, 1e4, xtol=1e-14)
    m = 1 - 1 / k ** 2
    return k, float(ellipk(m)), float(ellipe(m))


def hertz_point_contact(rho_x: float, rho_y: float, E: float, nu: float) -> tuple[float, float]:
    """Exact Hertz elliptical point contact between two bodies of the same steel.

    Harris / Hamrock:  delta = K(e) [9/(2 E(e) R) (P/(pi k E'))^2]^(1/3),
    1/R = rho_x + rho_y, E' = E/(1-nu^2) (k, K, E of ``_ellipse``).

    Parameters
    ----------
    rho_x, rho_y : float
        Sums of the principal curvatures (1/mm) of both bodies in the two (aligned)
        principal planes.
    E, nu : float
        Young's modulus (MPa) and Poisson's ratio of both bodies.

    Returns
    -------
    c : float
        Coefficient of the approach delta = c P^(2/3) (mm, N).
    k : float
        Ellipticity a/b of the contact ellipse.
    """
    Ep = E / (1 - nu ** 2)
    R = 1.0 / (rho_x + rho_y)
    k, Ke, Ee = _ellipse(rho_x, rho_y)
    c = Ke * (9.0 / (2 * Ee * R) / (math.pi * k * Ep) ** 2) ** (1.0 / 3.0)
    return c, k


def hertz_max_pressure(rho_x: float, rho_y: float, E: float, nu: float, P: float) -> float:
    """Largest pressure (MPa) of a Hertz elliptical point contact under the load ``P`` (N).

    Hamrock: semi-axes a = (6 k^2 E(e) P R / (pi E'))^(1/3), b = (6 E(e) P R / (pi k E'))^(1/3),
    p_max = 3 P / (2 pi a b); curvatures and E, nu as ``hertz_point_contact``.
    """
    if P <= 0:
        return 0.0
    Ep = E / (1 - nu ** 2)
    R = 1.0 / (rho_x + rho_y)
    k, _, Ee = _ellipse(rho_x, rho_y)
    a = (6 * k ** 2 * Ee * P * R / (math.pi * Ep)) ** (1.0 / 3.0)
    b = (6 * Ee * P * R / (math.pi * k * Ep)) ** (1.0 / 3.0)
    return 3 * P / (2 * math.pi * a * b)


def _raceway_curvatures(g: DriveGeometry) -> tuple[tuple[float, float], tuple[float, float]]:
    """Curvature sums (rolling plane, across) of a ball on the inner and on the outer raceway.

    Ball radius dw/2; raceway radius in the rolling plane d1/2 (inner, convex) and D1/2
    (outer, concave); groove radius f*dw (concave) across.
    """
    rb = g.ball_dia / 2
    rg = g.groove_conf * g.ball_dia
    return (1 / rb + 1 / g.ir_race, 1 / rb - 1 / rg), (1 / rb - 1 / g.or_race, 1 / rb - 1 / rg)


def ball_max_pressure(g: DriveGeometry, P: float, E: float | None = None) -> float:
    """Largest contact pressure (MPa) of a wave-generator ball carrying ``P`` (N): the larger of
    its two raceway contacts (the inner, convex one), to hold against ``ISO76_BALL_PRESSURE_MPA``."""
    E = g.E if E is None else E
    return max(hertz_max_pressure(rx, ry, E, g.nu, P) for rx, ry in _raceway_curvatures(g))


def ball_compliance_coeff(g: DriveGeometry, E: float | None = None) -> float:
    """c of delta = c P^(2/3) for one ball: inner + outer raceway contacts in series.

    Curvatures of ``_raceway_curvatures``.

    Parameters
    ----------
    g : DriveGeometry
        The drive (bearing ball diameter, raceway radii, groove conformity, steel).
    E : float, optional
        Young's modulus (MPa) instead of ``g.E``.

    Returns
    -------
    float
        c (mm / N^(2/3)).
    """
    E = g.E if E is None else E
    return sum(hertz_point_contact(rx, ry, E, g.nu)[0] for rx, ry in _raceway_curvatures(g))
