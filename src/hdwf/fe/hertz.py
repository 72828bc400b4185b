"""Hertz law of a bearing ball: the elastic approach of its two raceway contacts.

The balls are discrete elements between the raceways (``contact_rows``); each adds the
approach delta = c P^(2/3) of exact elliptic-contact Hertz theory, both raceway contacts in
series, to the contact problem as a secant compliance (``solver``).
"""

from __future__ import annotations

import math

from scipy.optimize import brentq
from scipy.special import ellipe, ellipk

from hdwf.drive.geometry import DriveGeometry


def hertz_point_contact(rho_x: float, rho_y: float, E: float, nu: float) -> tuple[float, float]:
    """Exact Hertz elliptical point contact between two bodies of the same steel.

    Harris / Hamrock:  F(rho) = ((k^2+1) E(e) - 2 K(e)) / ((k^2-1) E(e)),
    delta = K(e) [9/(2 E(e) R) (P/(pi k E'))^2]^(1/3), 1/R = rho_x + rho_y, E' = E/(1-nu^2),
    e^2 = 1 - 1/k^2.

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
    Frho = abs(rho_x - rho_y) / (rho_x + rho_y)
    if Frho < 1e-12:
        k, Ke, Ee = 1.0, math.pi / 2, math.pi / 2
    else:
        def res(k):
            m = 1 - 1 / k ** 2
            return ((k ** 2 + 1) * ellipe(m) - 2 * ellipk(m)) / ((k ** 2 - 1) * ellipe(m)) - Frho
        k = brentq(res, 1 + 1e-9, 1e4, xtol=1e-14)
        m = 1 - 1 / k ** 2
        Ke, Ee = float(ellipk(m)), float(ellipe(m))
    c = Ke * (9.0 / (2 * Ee * R) / (math.pi * k * Ep) ** 2) ** (1.0 / 3.0)
    return c, k


def ball_compliance_coeff(g: DriveGeometry, E: float | None = None) -> float:
    """c of delta = c P^(2/3) for one ball: inner + outer raceway contacts in series.

    Ball radius dw/2; raceway radius in the rolling plane d1/2 (inner, convex) and D1/2
    (outer, concave); groove radius f*dw (concave) across.

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
    rb = g.ball_dia / 2
    rg = g.groove_conf * g.ball_dia
    ci, _ = hertz_point_contact(1 / rb + 1 / g.ir_race, 1 / rb - 1 / rg, E, g.nu)
    co, _ = hertz_point_contact(1 / rb - 1 / g.or_race, 1 / rb - 1 / rg, E, g.nu)
    return ci + co
