"""FE bodies and the ball law against closed forms: Lamé ring, ring in torsion, Hertz contact."""

import math

import numpy as np
import pytest

from hdwf.drive.geometry import drive_geometry
from hdwf.drive.mesh import annulus_mesh
from hdwf.fe import (ball_compliance_coeff, ball_max_pressure, edge_loads,
                     hertz_max_pressure, hertz_point_contact, solve_linear)

E, NU = 210_000.0, 0.3


# ------------------------------------------------------------------ elasticity checks
def _ring(ri, ro, h):
    bm = annulus_mesh(ri, ro, h)
    p = bm.mesh.p
    # three constraints compatible with any axisymmetric / rotational field:
    # u_y = 0 at (+ro, 0) and (-ro, 0), u_x = 0 at (0, ro)
    def node(x, y):
        return int(np.argmin((p[0] - x) ** 2 + (p[1] - y) ** 2))
    return bm, node


def test_lame_thick_ring_internal_pressure():
    """Plane-stress Lame solution u_r(r) = ri^2 p /(E (ro^2-ri^2)) ((1-nu) r + (1+nu) ro^2/r);
    P1 triangles of size t/10 reproduce it within 0.5 % at both surfaces."""
    ri, ro, pr = 10.0, 20.0, 100.0
    bm, node = _ring(ri, ro, 1.0)
    f = edge_loads(bm.mesh, bm.edge_sets["inner"],
                   lambda x, y: (pr * x / np.hypot(x, y), pr * y / np.hypot(x, y)))
    nd = lambda n, c: 2 * n + c      # P1 vector dofs are interleaved (x, y) per node
    fixed = np.array([nd(node(ro, 0), 1), nd(node(-ro, 0), 1), nd(node(0, ro), 0)])
    u = solve_linear(bm, E, NU, fixed, f)
    p = bm.mesh.p
    r = np.hypot(p[0], p[1])
    ur = (u[0] * p[0] + u[1] * p[1]) / r
    exact = lambda rr: ri ** 2 * pr / (E * (ro ** 2 - ri ** 2)) * ((1 - NU) * rr
                                                                  + (1 + NU) * ro ** 2 / rr)
    for nodes, rr in ((bm.node_sets["inner"], ri), (bm.node_sets["outer"], ro)):
        assert np.mean(ur[nodes]) == pytest.approx(exact(rr), rel=5e-3)


def test_ring_under_torsion_shear():
    """Annulus clamped inside, torque T by uniform shear on the outside:
    tau = T/(2 pi r^2 t), u_theta(r) = T r/(4 pi G t) (1/ri^2 - 1/r^2); within 1 %."""
    ri, ro, T = 10.0, 20.0, 1.0e5
    bm = annulus_mesh(ri, ro, 0.8)
    tau = T / (2 * math.pi * ro ** 2)
    f = edge_loads(bm.mesh, bm.edge_sets["outer"],
                   lambda x, y: (-tau * y / np.hypot(x, y), tau * x / np.hypot(x, y)))
    inner = bm.node_sets["inner"]
    fixed = np.concatenate([2 * inner, 2 * inner + 1])
    u = solve_linear(bm, E, NU, fixed, f)
    p = bm.mesh.p
    out = bm.node_sets["outer"]
    ut = (-u[0, out] * p[1, out] + u[1, out] * p[0, out]) / ro
    G = E / (2 * (1 + NU))
    exact = T * ro / (4 * math.pi * G) * (1 / ri ** 2 - 1 / ro ** 2)
    assert np.mean(ut) == pytest.approx(exact, rel=1e-2)


# ------------------------------------------------------------------ Hertz ball law
def test_hertz_sphere_on_flat_matches_closed_form():
    """Sphere (R = 2 mm) on a flat: delta = (9 P^2 / (16 E*^2 R))^(1/3), E* = E/(2(1-nu^2));
    our elliptic-integral Hertz law must reduce to it (rel. 1e-9) for P = 1..100 N."""
    R = 2.0
    c, k = hertz_point_contact(1 / R, 1 / R, E, NU)
    Es = E / (2 * (1 - NU ** 2))
    for P in (1.0, 10.0, 100.0):
        assert c * P ** (2 / 3) == pytest.approx((9 * P ** 2 / (16 * Es ** 2 * R)) ** (1 / 3),
                                                 rel=1e-9)
    assert k == 1.0


def test_hertz_ball_in_groove_vs_hamrock_brewe():
    """Ball (dw 3.969) in the inner groove (f = 0.52) of the HD 42 bearing: exact Hertz vs
    the Hamrock-Brewe curve fits (k ~ 1.0339 (Ry/Rx)^0.636, E ~ 1.0003 + 0.5968 Rx/Ry,
    K ~ 1.5277 + 0.6023 ln(Ry/Rx)), which are accurate to a few per cent: within 3 %."""
    rb, rg, rr = 3.969 / 2, 0.52 * 3.969, 33.10 / 2
    rho_x, rho_y = 1 / rb + 1 / rr, 1 / rb - 1 / rg
    c, k = hertz_point_contact(rho_x, rho_y, E, NU)
    Rx, Ry = 1 / rho_x, 1 / rho_y
    kk = 1.0339 * (Ry / Rx) ** 0.636
    Ee = 1.0003 + 0.5968 * Rx / Ry
    Kk = 1.5277 + 0.6023 * math.log(Ry / Rx)
    R = 1 / (rho_x + rho_y)
    Ep = E / (1 - NU ** 2)
    P = 20.0
    d_hb = Kk * (9 / (2 * Ee * R) * (P / (math.pi * kk * Ep)) ** 2) ** (1 / 3)
    assert k == pytest.approx(kk, rel=0.03)
    assert c * P ** (2 / 3) == pytest.approx(d_hb, rel=0.03)
    # the HD 42 ball (inner + outer contact in series) at 14 N approaches ~1.6 um
    g = drive_geometry("hd42", 31.0, 42.0, 0.015, 0.0, 0.0)
    assert ball_compliance_coeff(g) * 14.0 ** (2 / 3) == pytest.approx(1.64e-3, rel=0.05)


def test_hertz_pressure_sphere_on_flat_matches_closed_form():
    """Sphere (R = 2 mm) on a flat: p0 = (6 P E*^2 / (pi^3 R^2))^(1/3) (Johnson, Contact
    Mechanics, eq. 4.24), within 1e-9 for P = 1..100 N; no load, no pressure."""
    R = 2.0
    Es = E / (2 * (1 - NU ** 2))
    for P in (1.0, 10.0, 100.0):
        assert hertz_max_pressure(1 / R, 1 / R, E, NU, P) == pytest.approx(
            (6 * P * Es ** 2 / (math.pi ** 3 * R ** 2)) ** (1 / 3), rel=1e-9)
    assert hertz_max_pressure(1 / R, 1 / R, E, NU, 0.0) == 0.0


def test_hertz_pressure_of_a_ball_in_its_groove_agrees_with_its_approach():
    """Elliptical contact (HD 42 ball in its inner groove, k = 8.7): Johnson's delta = K(e) p0 b / E*
    ties the pressure to the approach the solver uses (``hertz_point_contact``, tested above):
    within 1e-9. A ball's pressure grows as P^(1/3)."""
    from scipy.special import ellipk
    rb, rg, rr = 3.969 / 2, 0.52 * 3.969, 33.10 / 2
    rho_x, rho_y = 1 / rb + 1 / rr, 1 / rb - 1 / rg
    P = 20.0
    c, k = hertz_point_contact(rho_x, rho_y, E, NU)
    p0 = hertz_max_pressure(rho_x, rho_y, E, NU, P)
    Ep = E / (1 - NU ** 2)
    b = math.sqrt(3 * P / (2 * math.pi * k * p0))      # p0 = 3 P / (2 pi a b), a = k b
    assert c * P ** (2 / 3) == pytest.approx(float(ellipk(1 - 1 / k ** 2)) * p0 * b / (Ep / 2), rel=1e-9)
    g = drive_geometry("hd42", 31.0, 42.0, 0.015, 0.0, 0.0)
    assert ball_max_pressure(g, 8 * P) == pytest.approx(2 * ball_max_pressure(g, P), rel=1e-12)
