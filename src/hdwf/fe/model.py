"""Plane-stress FE model of the lost-motion test and our own frictionless contact solver.

Assembly (scikit-fem): each body (FS, CS, bearing inner ring IR, outer ring OR) is a
separate linear-elastic plane-stress steel mesh (E = 210 GPa, nu = 0.3; thickness = the
part's face width), P1 triangles.  Units mm, N, MPa.

Bodies and supports
-------------------
* cam: rigid analytic curve of Eq. 3, locked (not meshed);
* CS: every node of its outer rim is fixed (Dirichlet);
* IR, OR, FS float on their contacts.  Their rigid modes are removed *without bias* the
  FETI way: each floating stiffness is factorised with three DOFs pinned, and the rigid-body
  amplitudes alpha are extra unknowns of the contact problem together with the equations
  R^T (f + G^T p) = 0 (the pinned DOFs then carry no reaction).  The two exceptions are
  exact by construction: the IR rotation is pinned (the ring is clamped on the cam; no
  torque reaches it because ball forces are radial) and the OR rotation is pinned (a free
  bearing ring: balls and the OR/FS interface act radially, so nothing can turn it and
  its pinned DOF carries zero reaction).  In the wave-generator stage the FS rotation is
  pinned as well (nothing but the teeth can hold it); in the torque stage it is free and
  its amplitude is the twist.

Contacts (unilateral, frictionless), rows of a gap operator g = g0 + G u >= 0:
* cam - IR bore: node-to-rigid-curve, gap and normal re-evaluated at the deformed
  configuration and re-linearised until the geometry update is below 1e-6 mm;
* balls: discrete elements between raceway arcs (radial; each row is the exact P1 mean of
  u_r over an arc of +-ball_dia/8, fixed in mm so the patch does not depend on the mesh),
  initial gap G_r / 2, and a Hertz law delta = c P^(2/3) (exact elliptic-contact Hertz, both raceways in series)
  added as a secant compliance to the diagonal; secant updated to convergence;
* OR outer - FS bore: mortar-type bins (piecewise-constant pressure over 1 deg arcs;
  exact P1 mean of u_r of each side over the arc), initial gap (D_nom - D)/2 from the fit.
  Both arc rows integrate the field along the boundary edges instead of averaging the
  nodes that fall inside: node-count averages made the WG stiffness, and so Phi of HD 42,
  jump by up to 4 % from one mesh to the next;
* FS - CS flanks: node-to-segment in two passes (FS flank/tip nodes against CS boundary
  segments; CS tip-land and tip-corner nodes against FS boundary segments), a node beyond
  the end of its closest segment measuring its distance to that corner (its offset along
  the segment's normal is the gap to the segment's straight extension: FS flank nodes
  beside a CS tip "touched" the extension of the tip land, a false contact that came and
  went with the node spacing and moved Phi of hd42-lhs-22 by 2.5 % between meshes),
  built at the wave-generator-deflected configuration (gaps evaluated at the deformed FS)
  and linearised about it (small deformation on top of the deflected state).  At +-T
  every pair is re-detected at the deformed state (nonlinear gap); if that finds more
  than 0.05 um penetration (large twists slide the flanks), the pairs near contact are
  re-paired and re-linearised about that state and the level is solved again
  (``max_penetration_redetected_um`` reports the final check).

Contact solver (hand-written, as asked): a dual Schur-complement / active-set method.
Each body is factorised ONCE (scipy SuperLU).  For a contact pair i the compliance column
x_i = K^-1 G_i^T is obtained by back-substitution only when the pair first enters the
working set, and reused over all later iterations and load steps.  On the working set
the small dense mixed LCP

    g = g0 + G K^-1 f + C p + H alpha >= 0,  p >= 0,  p.g = 0,  H^T p = -R^T f,
    C = G K^-1 G^T + diag(s_ball),  H = G R

is solved exactly by a primal-dual active-set (PDAS) iteration: solve the KKT system of
the current active set, drop pairs with tensile p, add every candidate with penetration,
repeat until no pair has p < 0 and the largest penetration of all candidate pairs is
< ``tol_gap`` (1e-5 mm = 0.01 um).  Candidates outside the working set are checked every
iteration with the displacement on the contact DOFs, so no violated pair can be missed.
A free rigid mode that is loaded but not yet held (the FS rotation under torque while the
teeth are apart) is closed by adding the first pair that closes along that mode.
Cost: one factorisation per body plus back-solves, a handful of dense KKT solves per
load step.  A run that does not converge returns status "failed" with a reason.

Half model (``mesh.symmetry == "half"``, hand-written): the drive and its load are
invariant under the rotation by pi about the axis (even tooth and ball counts, pi-periodic
cam, torque), so the solution satisfies u(-x) = -u(x) and only the upper half of every
body is meshed (``hdwf.drive.mesh``).  On the cut every node at (-x, 0) is tied to its partner
at (x, 0), u = -u_partner: body dofs u = P u_red, and K_red = P^T K P is what is
factorised (``_solve_body`` maps forces by P^T and displacements by P, so the watch
vector, the rows and the full fields keep the half-body node numbering).  The symmetric
field has no translations, so a floating half body keeps only its rotation: one pinned
tangential dof, and stage 1 has no free rigid mode at all.  Contacts cover angles
[0, pi) only, each standing for itself and its image: balls 0 .. n/2-1 (ball 0 on the
cut), fit bins over [0, pi), cam rows and tooth slave nodes on the half; the tied nodes
at angle pi are left out of every row (their rows would repeat their partners'), and a
ball patch or fit bin reaching below angle 0 uses the images near pi (same radial
motion).  The half rim carries T/2 (``f_scale``) while the twist measure stays the mean
rotation of the rim, so the twist equals the full model's; the tooth count is doubled.
Both models give the same Phi to mesh noise (two different gmsh meshes of one density).

The frictionless FS is indifferent inside the backlash at zero torque; zero-torque steps
use 1e-3 of the test torque in the direction of the last load (the state an
infinitesimally small friction would leave), documented in the result.

Load and twist: the torque is a body-force pattern f = T w_i (-y, x) / sum(w r^2) on the FS
rim below the tooth roots (w_i = nodal areas), the 2D stand-in for the shear flow the cup
brings in; the twist is the work-conjugate mean rotation q^T u of the same region (exact
rigid rotation for a rigid motion).  Curve twists are relative to the first (+0) state.

Approximations (known, small): P1 triangles (Phi of the designs we checked moves by
< 2 % between 1x and 1.25x the paper's density, see docs/fe-model.md); the fit bins compare the
two surfaces at equal reference angles (their relative slide of ~10 um on a surface slope
<= 0.017 shifts those gaps by < 0.2 um, the same for every design); ball 0 sits on the
major axis (one sample of the WG angle).  Friction, cup torsion, housing compliance,
a temperature difference and Oldham play are off in the baseline (``ModelChanges``).
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field, fields, replace

import numpy as np
import scipy.sparse as sp
from scipy.optimize import brentq
from scipy.sparse.linalg import splu
from scipy.spatial import cKDTree
from scipy.special import ellipe, ellipk
from skfem import Basis, ElementTriP1, ElementVector, asm
from skfem.models.elasticity import lame_parameters, linear_elasticity

from hdwf.drive.geometry import ARCMIN, DriveGeometry, cam_points
from hdwf.drive.mesh import BodyMesh, DriveMesh

TOL_GAP = 1e-5          # mm: 0.01 um allowed penetration
ZERO_TORQUE_BIAS = 1e-3  # fraction of the test torque used at the zero-torque steps
RELIN_TOL = 5e-5         # mm: re-linearise tooth pairs at +-T above 0.05 um re-detected
BALL_PATCH_FRAC = 0.125  # ball load spread over +-ball_dia/8 of raceway arc
FRICTION_MAX_IT = 30     # slip-direction iterations per load level (flank friction)
SLIP_TOL = 1e-7          # mm: a slip below 0.1 nm over a step counts as none
RELIN_NEAR = 5e-3        # mm: ... but only those pairs closer than this (the loaded flanks)
CS_TIP_BAND = 0.05       # CS slave nodes of the second contact pass: tip land and corners


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
    """
    flank_friction: float = 0.0
    cs_rim_stiffness_N_mm2: float = math.inf
    cs_scale: float = 1.0
    output_compliance_rad_per_Nmm: float = 0.0
    output_play_rad: float = 0.0

    def fe_part(self) -> "ModelChanges":
        """The changes that need a new contact solve: all but the series elements."""
        return replace(self, output_compliance_rad_per_Nmm=0.0, output_play_rad=0.0)


# --------------------------------------------------------------------------------------
# Elasticity
# --------------------------------------------------------------------------------------
def plane_stress_lame(E: float, nu: float) -> tuple[float, float]:
    lam, mu = lame_parameters(E, nu)
    return 2 * lam * mu / (lam + 2 * mu), mu


def assemble_stiffness(body: BodyMesh, E: float, nu: float):
    """Plane-stress stiffness (N/mm) of a body of thickness ``body.thickness``."""
    basis = Basis(body.mesh, ElementVector(ElementTriP1()))
    lam, mu = plane_stress_lame(E, nu)
    K = asm(linear_elasticity(lam, mu), basis) * body.thickness
    return K.tocsr(), basis


def nodal_areas(mesh) -> np.ndarray:
    p, t = mesh.p, mesh.t
    a = 0.5 * np.abs((p[0, t[1]] - p[0, t[0]]) * (p[1, t[2]] - p[1, t[0]])
                     - (p[0, t[2]] - p[0, t[0]]) * (p[1, t[1]] - p[1, t[0]]))
    w = np.zeros(p.shape[1])
    for k in range(3):
        np.add.at(w, t[k], a / 3)
    return w


def edge_loads(mesh, edges: np.ndarray, traction) -> np.ndarray:
    """Consistent P1 nodal forces (per unit thickness) of a traction function
    ``traction(x, y) -> (tx, ty)`` on boundary edges, 2-point Gauss per edge."""
    p = mesh.p
    f = np.zeros((2, p.shape[1]))
    xa, xb = p[:, edges[:, 0]], p[:, edges[:, 1]]
    L = np.linalg.norm(xb - xa, axis=0)
    for s in (0.5 - 0.5 / math.sqrt(3), 0.5 + 0.5 / math.sqrt(3)):
        x = xa + s * (xb - xa)
        tx, ty = traction(x[0], x[1])
        for node, N in ((edges[:, 0], 1 - s), (edges[:, 1], s)):
            np.add.at(f[0], node, 0.5 * L * N * tx)
            np.add.at(f[1], node, 0.5 * L * N * ty)
    return f


def solve_linear(body: BodyMesh, E: float, nu: float, fixed_dofs: np.ndarray,
                 f_nodal: np.ndarray) -> np.ndarray:
    """Plain linear solve (verification helper); f_nodal is (2, nnodes); returns (2, n)."""
    K, basis = assemble_stiffness(body, E, nu)
    nd = basis.nodal_dofs
    f = np.zeros(K.shape[0])
    f[nd[0]], f[nd[1]] = f_nodal[0], f_nodal[1]
    free = np.setdiff1d(np.arange(K.shape[0]), fixed_dofs)
    u = np.zeros(K.shape[0])
    u[free] = splu(K[free][:, free].tocsc()).solve(f[free])
    return np.vstack([u[nd[0]], u[nd[1]]])


# --------------------------------------------------------------------------------------
# Hertz contact of a ball
# --------------------------------------------------------------------------------------
def hertz_point_contact(rho_x: float, rho_y: float, E: float, nu: float):
    """Exact Hertz elliptical point contact between two bodies of the same steel.

    rho_x, rho_y: sums of the principal curvatures (1/mm) of both bodies in the two
    (aligned) principal planes.  Returns ``(c, k)`` with the approach delta = c P^(2/3)
    (mm, N) and the ellipticity k = a/b.  Harris / Hamrock:  F(rho) =
    ((k^2+1) E(e) - 2 K(e)) / ((k^2-1) E(e)), delta = K(e) [9/(2 E(e) R) (P/(pi k E'))^2]^(1/3),
    1/R = rho_x + rho_y, E' = E/(1-nu^2), e^2 = 1 - 1/k^2.
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
    """
    E = g.E if E is None else E
    rb = g.ball_dia / 2
    rg = g.groove_conf * g.ball_dia
    ci, _ = hertz_point_contact(1 / rb + 1 / g.ir_race, 1 / rb - 1 / rg, E, g.nu)
    co, _ = hertz_point_contact(1 / rb - 1 / g.or_race, 1 / rb - 1 / rg, E, g.nu)
    return ci + co


# --------------------------------------------------------------------------------------
# Bodies
# --------------------------------------------------------------------------------------
@dataclass
class _Body:
    name: str
    bm: BodyMesh
    K: sp.csr_matrix
    nd: np.ndarray                  # (2, nnodes) global-in-body dof numbers
    free: np.ndarray
    lu: object
    modes: dict[str, np.ndarray]    # name -> full-body rigid mode vector
    watch_nodes: np.ndarray         # body node ids whose dofs are watched
    wofs: int = 0                   # offset of this body in the watch vector
    wpos: np.ndarray | None = None  # node id -> position in watch vector (2 per node) or -1
    P: sp.csr_matrix | None = None  # half model: body dofs = P @ reduced dofs (cut ties)
    dep: np.ndarray = field(default_factory=lambda: np.zeros(0, dtype=np.int64))  # tied nodes

    @property
    def x(self):
        return self.bm.mesh.p


def _scaled(bm: BodyMesh, s: float) -> BodyMesh:
    """The body mesh scaled about the axis by ``s`` (same nodes, elements and groups)."""
    from skfem import MeshTri

    return BodyMesh(name=bm.name, mesh=MeshTri(bm.mesh.p * s, bm.mesh.t), thickness=bm.thickness,
                    node_sets=bm.node_sets, edge_sets=bm.edge_sets)


def _node_u(b: "_Body", nodes: np.ndarray, u_watch: np.ndarray) -> np.ndarray:
    """Displacements (2 x n) of watched ``nodes`` of body ``b`` from the watch vector."""
    return np.vstack([u_watch[b.wpos[0, nodes]], u_watch[b.wpos[1, nodes]]])


def _pin_nodes(p: np.ndarray, boundary: np.ndarray, r_mid: float):
    """Two interior nodes near (-r_mid, 0) and (r_mid, 0)."""
    mask = np.ones(p.shape[1], bool)
    mask[boundary] = False
    idx = np.flatnonzero(mask)
    a = idx[np.argmin((p[0, idx] + r_mid) ** 2 + p[1, idx] ** 2)]
    b = idx[np.argmin((p[0, idx] - r_mid) ** 2 + p[1, idx] ** 2)]
    return a, b


def _symmetry_map(p: np.ndarray, nd: np.ndarray):
    """Half model: tie every cut node at (-x, 0) to its partner at (x, 0), u = -u_partner.

    Returns P (ndof x nred, body dofs = P @ reduced dofs) and the tied (eliminated) nodes.
    """
    scale = float(np.abs(p).max())
    cut = np.abs(p[1]) <= 1e-9 * scale
    right = np.flatnonzero(cut & (p[0] > 0))
    left = np.flatnonzero(cut & (p[0] < 0))
    right = right[np.argsort(p[0, right])]
    left = left[np.argsort(-p[0, left])]
    if right.size != left.size or right.size == 0 or np.abs(
            p[0, right] + p[0, left]).max() > 1e-7 * scale:
        raise ValueError("half model: the cut nodes at angle 0 and pi do not pair up")
    ndof = 2 * p.shape[1]
    keep = np.ones(p.shape[1], bool)
    keep[left] = False
    red = -np.ones(ndof, dtype=np.int64)
    kd = np.sort(np.concatenate([nd[0, keep], nd[1, keep]]))
    red[kd] = np.arange(kd.size)
    sgn = np.ones(ndof)
    for c in (0, 1):
        red[nd[c, left]] = red[nd[c, right]]
        sgn[nd[c, left]] = -1.0
    P = sp.csr_matrix((sgn, (np.arange(ndof), red)), shape=(ndof, kd.size))
    return P, left


def _make_body(name: str, bm: BodyMesh, E: float, nu: float, fixed_nodes=None,
               watch_nodes=None, half: bool = False,
               ground_springs: np.ndarray | None = None) -> tuple[_Body, float]:
    """``ground_springs`` (N/mm per node, both directions) hold the body elastically:
    then nothing is pinned and the body has no rigid modes."""
    K, basis = assemble_stiffness(bm, E, nu)
    nd = basis.nodal_dofs
    if ground_springs is not None:
        kd = np.zeros(K.shape[0])
        kd[nd[0]] = ground_springs
        kd[nd[1]] = ground_springs
        K = (K + sp.diags(kd)).tocsr()
    p = bm.mesh.p
    ndof = K.shape[0]
    modes = {}
    P, dep = None, np.zeros(0, dtype=np.int64)
    Kr = K
    if half:
        P, dep = _symmetry_map(p, nd)
        Kr = (P.T @ K @ P).tocsr()
        red = P.indices                      # reduced dof of every body dof (one entry a row)
    if ground_springs is not None:
        fixed = np.zeros(0, dtype=np.int64)
    elif fixed_nodes is not None:
        fixed = np.concatenate([nd[0, fixed_nodes], nd[1, fixed_nodes]])
        if half:
            fixed = np.unique(red[fixed])
    elif half:
        # the symmetric field has no translations; only the rotation is pinned, by the
        # tangential dof of an interior node on the y axis
        on_cut = np.flatnonzero(np.abs(p[1]) <= 1e-9 * np.abs(p).max())
        bnd = np.concatenate(list(bm.node_sets.values()) + [on_cut])
        r = np.hypot(p[0], p[1])
        r_mid = 0.5 * (r.min() + r.max())
        mask = np.ones(p.shape[1], bool)
        mask[bnd] = False
        idx = np.flatnonzero(mask)
        a = idx[np.argmin(p[0, idx] ** 2 + (p[1, idx] - r_mid) ** 2)]
        fixed = np.array([red[nd[0, a]]])
        v = np.zeros(ndof)
        v[nd[0]], v[nd[1]] = -p[1], p[0]
        modes["rot"] = v
    else:
        bnd = np.concatenate(list(bm.node_sets.values()))
        r = np.hypot(p[0], p[1])
        a, b = _pin_nodes(p, bnd, 0.5 * (r.min() + r.max()))
        fixed = np.array([nd[0, a], nd[1, a], nd[1, b]])
        for mname, vx, vy in (("tx", np.ones_like(p[0]), np.zeros_like(p[0])),
                              ("ty", np.zeros_like(p[0]), np.ones_like(p[0])),
                              ("rot", -p[1], p[0])):
            v = np.zeros(ndof)
            v[nd[0]], v[nd[1]] = vx, vy
            modes[mname] = v
    free = np.setdiff1d(np.arange(Kr.shape[0]), fixed)   # reduced dofs in the half model
    t0 = time.perf_counter()
    lu = splu(Kr[free][:, free].tocsc(), permc_spec="COLAMD")
    tf = time.perf_counter() - t0
    wn = np.unique(np.asarray(watch_nodes, dtype=np.int64))
    return _Body(name, bm, K, nd, free, lu, modes, wn, P=P, dep=dep), tf


# --------------------------------------------------------------------------------------
# Contact rows
# --------------------------------------------------------------------------------------
@dataclass
class _Rows:
    """A block of contact pairs: sparse rows over the watch vector + gap constants."""
    kind: str
    G: sp.csr_matrix                # (n, nwatch)
    g0: np.ndarray                  # g = g0 + G u_watch
    info: dict = field(default_factory=dict)


def _radial_rows(body: _Body, nodes_per_row: list[np.ndarray], sign: float, nwatch: int):
    """Rows averaging sign * (e_r . u) over node groups of one body."""
    r, c, v = [], [], []
    p = body.x
    for i, nodes in enumerate(nodes_per_row):
        w = sign / len(nodes)
        th = np.arctan2(p[1, nodes], p[0, nodes])
        for comp, cs in ((0, np.cos(th)), (1, np.sin(th))):
            r.append(np.full(len(nodes), i))
            c.append(body.wpos[comp, nodes])
            v.append(w * cs)
    return sp.csr_matrix((np.concatenate(v), (np.concatenate(r), np.concatenate(c))),
                         shape=(len(nodes_per_row), nwatch))


def _arc_average_rows(body: _Body, edges: np.ndarray, centres: np.ndarray, half_width: float,
                      sign: float, per: float, nwatch: int) -> sp.csr_matrix:
    """Rows giving sign * the mean radial displacement over the arcs
    [centre - half_width, centre + half_width] of a circular boundary (mortar-type).

    The P1 field is integrated exactly along the boundary edges (in angle), so a row
    does not depend on which nodes happen to fall inside its arc: the mesh only changes
    the quadrature, not the definition.  ``per`` is the period in angle (pi in the half
    model: an arc reaching below 0 uses the edges near pi, whose radial motion is that of
    their images)."""
    p = body.x
    th = np.arctan2(p[1], p[0])
    n1, n2 = edges[:, 0], edges[:, 1]
    dt = np.angle(np.exp(1j * (th[n2] - th[n1])))          # signed edge span
    r, c, v = [], [], []
    for i, cen in enumerate(centres):
        # edge end angles relative to the centre, wrapped into (-per/2, per/2]
        a1 = (th[n1] - cen + per / 2) % per - per / 2
        a2 = a1 + dt
        lo, hi = np.minimum(a1, a2), np.maximum(a1, a2)
        s_lo, s_hi = np.maximum(lo, -half_width), np.minimum(hi, half_width)
        on = s_hi > s_lo
        if not on.any():
            raise ValueError(f"{body.name}: no boundary edge within the arc at "
                             f"{math.degrees(cen):.2f} deg")
        L = (hi - lo)[on]
        # integral of the hat functions of the edge's two nodes over the overlap
        t_lo, t_hi = s_lo[on], s_hi[on]
        first_is_lo = (a1 <= a2)[on]
        w_at_hi = (0.5 * (t_hi ** 2 - t_lo ** 2) - lo[on] * (t_hi - t_lo)) / L
        w_at_lo = (t_hi - t_lo) - w_at_hi
        w1 = np.where(first_is_lo, w_at_lo, w_at_hi)
        w2 = np.where(first_is_lo, w_at_hi, w_at_lo)
        nodes = np.concatenate([n1[on], n2[on]])
        w = sign * np.concatenate([w1, w2]) / (2 * half_width)
        for comp, trig in ((0, np.cos(th[nodes])), (1, np.sin(th[nodes]))):
            r.append(np.full(nodes.size, i))
            c.append(body.wpos[comp, nodes])
            v.append(w * trig)
    return sp.csr_matrix((np.concatenate(v), (np.concatenate(r), np.concatenate(c))),
                         shape=(len(centres), nwatch))


def _boundary_lengths(mesh, edges: np.ndarray) -> np.ndarray:
    """Tributary boundary length (mm) of every node of ``mesh`` (zero off ``edges``)."""
    p = mesh.p
    L = np.hypot(*(p[:, edges[:, 1]] - p[:, edges[:, 0]]))
    w = np.zeros(p.shape[1])
    np.add.at(w, edges[:, 0], L / 2)
    np.add.at(w, edges[:, 1], L / 2)
    return w


def _boundary_edge_normals(mesh, edges: np.ndarray) -> np.ndarray:
    """Unit normals of boundary edges pointing OUT of the body's material."""
    p = mesh.p
    N = p.shape[1]
    key_f = np.sort(mesh.facets, axis=0).astype(np.int64)   # int64: N^2 overflows int32
    keys = key_f[0] * N + key_f[1]
    order = np.argsort(keys)
    e = np.sort(edges, axis=1).astype(np.int64)
    want = e[:, 0] * N + e[:, 1]
    loc = np.minimum(np.searchsorted(keys[order], want), keys.size - 1)
    pos = order[loc]
    if np.any(keys[pos] != want) or np.any(edges < 0):
        raise ValueError("boundary edges of a contact group are not edges of the "
                         "triangle mesh (gmsh mesh defect)")
    tri = mesh.f2t[0, pos]
    third = mesh.t[:, tri]
    third = np.where((third != e[:, 0]) & (third != e[:, 1]), third, -1).max(axis=0)
    d = p[:, edges[:, 1]] - p[:, edges[:, 0]]
    n = np.vstack([d[1], -d[0]]) / np.linalg.norm(d, axis=0)
    inward = np.einsum("ij,ij->j", n, p[:, third] - p[:, edges[:, 0]]) > 0
    n[:, inward] *= -1
    return n


def _closest_segments(xs: np.ndarray, xa: np.ndarray, xb: np.ndarray, nrm: np.ndarray):
    """For each point of ``xs`` (2 x n) the closest of the segments a->b (2 x m, outward unit
    normals ``nrm``): (signed gap, segment index, parameter t in [0, 1] of the closest point).
    The gap is the offset along the segment's normal, except for a point beyond the end of its
    closest segment: that point faces a corner, and its gap is its distance to the corner
    (the normal offset there is the gap to the segment's straight extension)."""
    tree = cKDTree((0.5 * (xa + xb)).T)
    kq = min(8, xa.shape[1])
    _, cand = tree.query(xs.T, k=kq)
    cand = cand.reshape(xs.shape[1], kq)
    best = np.full(xs.shape[1], np.inf)
    bg = np.zeros(xs.shape[1])
    be = np.zeros(xs.shape[1], dtype=np.int64)
    bt = np.zeros(xs.shape[1])
    for jj in range(kq):
        e = cand[:, jj]
        a, b = xa[:, e], xb[:, e]
        d = b - a
        t_free = ((xs - a) * d).sum(0) / (d ** 2).sum(0)
        t = np.clip(t_free, 0, 1)
        pr = a + t * d
        dist = np.hypot(*(xs - pr))
        gap = ((xs - pr) * nrm[:, e]).sum(0)
        # beyond the segment's end: in the fan outside a corner, so outside the body (inside
        # a convex corner a point projects into an edge; the concave root corners never
        # bear, the tip/root clearance is 0.1 h)
        beyond = (t_free < -1e-9) | (t_free > 1 + 1e-9)
        gap = np.where(beyond, dist, gap)
        better = dist < best - 1e-12
        best = np.where(better, dist, best)
        bg, be, bt = (np.where(better, gap, bg), np.where(better, e, be),
                      np.where(better, t, bt))
    return bg, be, bt


# --------------------------------------------------------------------------------------
# Result
# --------------------------------------------------------------------------------------
@dataclass
class LostMotionResult:
    phi_plus_arcmin: float
    phi_minus_arcmin: float
    lost_motion_arcmin: float
    step: np.ndarray
    torque_Nm: np.ndarray
    twist_arcmin: np.ndarray
    teeth_in_contact: int
    max_penetration_um: float
    iterations: int
    status: str
    reason: str
    solve_s: float
    factorize_s: float
    n_dofs: int = 0
    wg_deflection_um: float = float("nan")   # FS bore radial displacement at major axis
    max_penetration_redetected_um: float = float("nan")  # tooth pairs re-found at +-T
    notes: str = ""
    fields: dict | None = None   # with keep_fields: {"wg": {...}, "plus": {...}} body -> (2, n) mm

    @property
    def curve(self) -> dict[str, np.ndarray]:
        return {"step": self.step, "torque_Nm": self.torque_Nm,
                "twist_arcmin": self.twist_arcmin}


class ContactFailure(RuntimeError):
    pass


# --------------------------------------------------------------------------------------
# The solver
# --------------------------------------------------------------------------------------
class LostMotionModel:
    """Holds the factorised bodies, contact rows and the working set."""

    def __init__(self, geom: DriveGeometry, mesh: DriveMesh, E: float | None = None,
                 max_iter: int = 200, tol_gap: float = TOL_GAP, zone_deg: float = 35.0,
                 n_bins: int = 360, changes: ModelChanges | None = None):
        self.g = geom
        self.changes = changes = ModelChanges() if changes is None else changes
        self.mu = float(changes.flank_friction)
        self.E = geom.E if E is None else E
        self.max_iter, self.tol_gap = max_iter, tol_gap
        self.iterations = 0
        self.debug = False
        self.add_min, self.add_frac = 5, 0.2
        self.n_bins = n_bins
        self.half = (getattr(mesh, "symmetry", "full") == "half"
                     or float(mesh.sizes.get("symmetry_half", 0.0)) == 1.0)
        # half model: the half rim carries half the torque; the twist measure (mean rotation
        # of the rim) is the same for the half and the whole
        self.f_scale = 0.5 if self.half else 1.0
        bms = dict(mesh.bodies)
        # watch sets: every contact node (teeth only in the engagement zones)
        def zone(bm, nodes):
            th = np.arctan2(bm.mesh.p[1, nodes], bm.mesh.p[0, nodes])
            dth = np.abs(np.angle(np.exp(2j * th))) / 2   # distance to nearest major axis
            return nodes[dth < math.radians(zone_deg)]
        fs_w = np.concatenate([bms["fs"].node_sets["fs_bore"],
                               zone(bms["fs"], bms["fs"].node_sets["fs_teeth"])])
        cs_w = zone(bms["cs"], bms["cs"].node_sets["cs_teeth"])
        ir_w = np.concatenate([bms["ir"].node_sets["ir_bore"], bms["ir"].node_sets["ir_race"]])
        or_w = np.concatenate([bms["or"].node_sets["or_race"], bms["or"].node_sets["or_outer"]])
        self.factorize_s = 0.0
        self.bodies: dict[str, _Body] = {}
        self._cs_mesh0, self._cs_watch = bms["cs"], cs_w
        for name, w, fixed in (("fs", fs_w, None),
                               ("cs", cs_w, bms["cs"].node_sets["cs_outer"]),
                               ("ir", ir_w, None), ("or", or_w, None)):
            if name == "cs":
                b, tf = self._build_cs(changes)
            else:
                b, tf = _make_body(name, bms[name], self.E, geom.nu, fixed, w, self.half)
            self.factorize_s += tf
            self.bodies[name] = b
        ofs = 0
        for b in self.bodies.values():
            b.wofs = ofs
            b.wpos = -np.ones((2, b.x.shape[1]), dtype=np.int64)
            n = b.watch_nodes.size
            b.wpos[0, b.watch_nodes] = ofs + 2 * np.arange(n)
            b.wpos[1, b.watch_nodes] = ofs + 2 * np.arange(n) + 1
            ofs += 2 * n
        self.nwatch = ofs
        self.n_dofs = sum(b.K.shape[0] for b in self.bodies.values())
        # torque load pattern on the FS rim (below the tooth roots) and its twist measure
        fs = self.bodies["fs"]
        p = fs.x
        rim_tri = np.hypot(*p[:, fs.bm.mesh.t].mean(axis=1)) < geom.r_fs_root
        sub = fs.bm.mesh.t[:, rim_tri]
        a = 0.5 * np.abs((p[0, sub[1]] - p[0, sub[0]]) * (p[1, sub[2]] - p[1, sub[0]])
                         - (p[0, sub[2]] - p[0, sub[0]]) * (p[1, sub[1]] - p[1, sub[0]]))
        w = np.zeros(p.shape[1])
        for k in range(3):
            np.add.at(w, sub[k], a / 3)
        J = float(np.sum(w * (p[0] ** 2 + p[1] ** 2)))
        q = np.zeros(fs.K.shape[0])
        q[fs.nd[0]], q[fs.nd[1]] = -w * p[1] / J, w * p[0] / J
        self.q = q       # twist measure; load per unit torque is f_scale * q (N/(N mm))
        self.uq = self.f_scale * self._solve_body(fs, q[:, None])[:, 0]
        self.uq_watch = self._watch_vec("fs", self.uq)
        self.qq = float(q @ self.uq)
        # rigid modes: (body, mode) -> column of R (watch restriction), twist, load
        self.mode_list: list[tuple[str, str]] = []
        self.ball_c = ball_compliance_coeff(geom, self.E)
        # working set storage
        self.rows: dict[str, _Rows] = {}
        self._Xbuf = np.zeros((self.nwatch, 0))  # compliance columns on the watch dofs
        self.Xq = np.zeros(0)                  # q^T K^-1 G^T
        self._GW = None                        # rows of the working set
        self.CW = np.zeros((0, 0))             # their compliance matrix
        self.W: list[tuple[str, int]] = []     # working-set pairs (kind, row index)
        self.Wpos: dict[tuple[str, int], int] = {}
        # flank friction: K^-1 Gt^T columns (slip rows) and G_W K^-1 Gt_W^T
        self._Ybuf = np.zeros((self.nwatch, 0))
        self.Yq = np.zeros(0)
        self.CWY = np.zeros((0, 0))
        self.CWYY = np.zeros((0, 0))                     # Gt_W K^-1 Gt_W^T
        self._TW = None
        self._sigma: dict[tuple[str, int], float] = {}   # friction direction per pair

    def _build_cs(self, changes: ModelChanges) -> tuple[_Body, float]:
        """The CS body: scaled (thermal strain) and on rim springs (housing) as ``changes`` say."""
        bm = self._cs_mesh0 if changes.cs_scale == 1.0 else _scaled(self._cs_mesh0, changes.cs_scale)
        springs = None
        if math.isfinite(changes.cs_rim_stiffness_N_mm2):
            springs = changes.cs_rim_stiffness_N_mm2 * _boundary_lengths(bm.mesh,
                                                                         bm.edge_sets["cs_outer"])
        return _make_body("cs", bm, self.E, self.g.nu, bm.node_sets["cs_outer"], self._cs_watch,
                          self.half, ground_springs=springs)

    def fork(self) -> "LostMotionModel":
        """A copy that shares the factorised bodies and copies the mutable contact state."""
        import copy

        new = copy.copy(self)
        new.bodies, new.rows = dict(self.bodies), dict(self.rows)
        new.W, new.Wpos = list(self.W), dict(self.Wpos)
        new.mode_list, new._sigma = list(self.mode_list), dict(self._sigma)
        for name in ("_Xbuf", "_Ybuf", "Xq", "Yq", "CW", "CWY", "CWYY"):
            setattr(new, name, getattr(self, name).copy())
        return new

    def apply_tooth_stage_changes(self, changes: ModelChanges):
        """Switch the tooth-stage changes (friction, CS scale and support) on a model whose
        wave generator is mounted: none of them touches the bodies or contacts of that stage
        (the CS has no contact before the teeth), so it is reused as it is."""
        if any(k == "tooth" for k, _ in self.W):
            raise RuntimeError("apply_tooth_stage_changes: the teeth are already engaged")
        old = self.changes
        handled = {"flank_friction", "cs_rim_stiffness_N_mm2", "cs_scale"}
        other = [f.name for f in fields(ModelChanges) if f.name not in handled
                 and getattr(changes, f.name) != getattr(ModelChanges(), f.name)]
        if other:    # a new tooth-stage change must be applied here too (adding-an-effect.md)
            raise NotImplementedError(f"apply_tooth_stage_changes does not apply {other}")
        if (changes.cs_scale, changes.cs_rim_stiffness_N_mm2) != (old.cs_scale,
                                                                   old.cs_rim_stiffness_N_mm2):
            prev = self.bodies["cs"]
            if (changes.cs_rim_stiffness_N_mm2 == old.cs_rim_stiffness_N_mm2
                    and not math.isfinite(old.cs_rim_stiffness_N_mm2) and not prev.modes):
                # a clamped CS only scaled (thermal strain): a uniformly scaled plane-stress
                # body has the same stiffness matrix (B ~ 1/s, area ~ s^2), so the
                # factorisation is kept and only the coordinates move
                self.bodies["cs"] = replace(prev, bm=_scaled(prev.bm, changes.cs_scale / old.cs_scale))
            else:
                b, tf = self._build_cs(changes)
                b.wofs, b.wpos = prev.wofs, prev.wpos
                self.bodies["cs"] = b
                self.factorize_s += tf
        self.mu = float(changes.flank_friction)
        if self.mu > 0 and self.CWY.shape[0] != len(self.W):
            n = len(self.W)      # the mounted contacts have no slip rows: zero columns
            self._Ybuf = np.zeros((self.nwatch, max(n, 1)))
            self.Yq = np.zeros(n)
            self.CWY = np.zeros((n, n))
            self.CWYY = np.zeros((n, n))
            self._TW = sp.csr_matrix((n, self.nwatch))
        self.changes = changes

    # ---------------------------------------------------------------- linear algebra
    def _solve_body(self, b: _Body, F: np.ndarray) -> np.ndarray:
        if b.P is not None:                  # half model: solve on the tied (reduced) dofs
            Fr = np.asarray(b.P.T @ F)
            Ur = np.zeros((b.P.shape[1], F.shape[1]))
            Ur[b.free] = b.lu.solve(np.ascontiguousarray(Fr[b.free]))
            return np.asarray(b.P @ Ur)
        U = np.zeros((b.K.shape[0], F.shape[1]))
        U[b.free] = b.lu.solve(np.ascontiguousarray(F[b.free]))
        return U

    def _watch_vec(self, name: str, u_full: np.ndarray) -> np.ndarray:
        b = self.bodies[name]
        v = np.zeros(self.nwatch)
        wn = b.watch_nodes
        v[b.wpos[0, wn]] = u_full[b.nd[0, wn]]
        v[b.wpos[1, wn]] = u_full[b.nd[1, wn]]
        return v

    def _watch_to_body(self, name: str, Gt: sp.csc_matrix) -> np.ndarray:
        """Map watch-vector force columns (nwatch x k) to full-body force vectors."""
        b = self.bodies[name]
        wn = b.watch_nodes
        F = np.zeros((b.K.shape[0], Gt.shape[1]))
        Gd = Gt.toarray()
        F[b.nd[0, wn]] = Gd[b.wpos[0, wn]]
        F[b.nd[1, wn]] = Gd[b.wpos[1, wn]]
        return F

    def _columns(self, Grows: sp.csr_matrix) -> tuple[np.ndarray, np.ndarray]:
        """K^-1 G^T for rows G (k x nwatch): watch restriction and q-projection."""
        k = Grows.shape[0]
        X = np.zeros((self.nwatch, k))
        Xq = np.zeros(k)
        Gt = Grows.T.tocsr()
        for name, b in self.bodies.items():
            sl = slice(b.wofs, b.wofs + 2 * b.watch_nodes.size)
            cols = np.flatnonzero(np.diff(Gt[sl].tocsc().indptr))
            if cols.size == 0:
                continue
            for c0 in range(0, cols.size, 256):   # bounded memory per batch
                cc = cols[c0:c0 + 256]
                Fw = Gt[:, cc].tocsc()
                F = self._watch_to_body(name, Fw)
                U = self._solve_body(b, F)
                wn = b.watch_nodes
                X[b.wpos[0, wn][:, None], cc[None, :]] += U[b.nd[0, wn]]
                X[b.wpos[1, wn][:, None], cc[None, :]] += U[b.nd[1, wn]]
                if name == "fs":
                    Xq[cc] += self.q @ U
        return X, Xq

    # ---------------------------------------------------------------- rigid modes
    def _R(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Watch restriction, twist and torque-load component of the active modes."""
        R = np.zeros((self.nwatch, len(self.mode_list)))
        Rq = np.zeros(len(self.mode_list))
        Rf = np.zeros(len(self.mode_list))
        for j, (bn, mn) in enumerate(self.mode_list):
            v = self.bodies[bn].modes[mn]
            R[:, j] = self._watch_vec(bn, v)
            if bn == "fs":
                Rq[j] = self.q @ v
                Rf[j] = self.f_scale * (self.q @ v)     # R^T f per unit torque
        return R, Rq, Rf

    # ---------------------------------------------------------------- rows
    def cam_rows(self, u_watch: np.ndarray) -> _Rows:
        ir = self.bodies["ir"]
        nodes = self._indep(ir, ir.bm.node_sets["ir_bore"])
        X = ir.x[:, nodes]
        x = X + _node_u(ir, nodes, u_watch)
        cp = cam_points(self.g.cam_A, self.g.cam_B, self.g.cam_n, 32768)
        tree = cKDTree(cp)
        _, j = tree.query(x.T)
        best_g = np.full(x.shape[1], np.inf)
        best_n = np.zeros((2, x.shape[1]))
        nc = cp.shape[0]
        for j0, j1 in ((j - 1, j), (j, j + 1)):
            a, b = cp[j0 % nc].T, cp[j1 % nc].T
            d = b - a
            L2 = (d ** 2).sum(0)
            t = np.clip(((x - a) * d).sum(0) / L2, 0, 1)
            proj = a + t * d
            n = np.vstack([d[1], -d[0]]) / np.sqrt(L2)       # outward for a CCW curve
            gap = ((x - proj) * n).sum(0)
            dist = np.hypot(*(x - proj))
            better = dist < np.abs(best_g)
            best_g = np.where(better, gap, best_g)
            best_n = np.where(better, n, best_n)
        k = nodes.size
        r = np.repeat(np.arange(k), 2)
        c = np.column_stack([ir.wpos[0, nodes], ir.wpos[1, nodes]]).ravel()
        v = best_n.T.ravel()
        G = sp.csr_matrix((v, (r, c)), shape=(k, self.nwatch))
        g0 = best_g - G @ u_watch
        return _Rows("cam", G, g0)

    def ball_rows(self) -> _Rows:
        g = self.g
        ir, orr = self.bodies["ir"], self.bodies["or"]
        # half model: the balls in [0, pi) (ball 0 on the cut, its image at pi implied)
        nb = g.n_balls // 2 if self.half else g.n_balls
        per = math.pi if self.half else 2 * math.pi
        thb = 2 * math.pi * np.arange(nb) / g.n_balls
        # each ball acts on a raceway arc of a quarter ball diameter, fixed in mm so the
        # patch stiffness does not depend on the mesh (the Hertz law adds the local part)
        hw_i = BALL_PATCH_FRAC * g.ball_dia / g.ir_race
        hw_o = BALL_PATCH_FRAC * g.ball_dia / g.or_race
        Gi = _arc_average_rows(ir, ir.bm.edge_sets["ir_race"], thb, hw_i, -1.0, per, self.nwatch)
        Go = _arc_average_rows(orr, orr.bm.edge_sets["or_race"], thb, hw_o, +1.0, per, self.nwatch)
        return _Rows("ball", (Gi + Go).tocsr(), np.full(nb, g.ball_gap))

    def fit_rows(self) -> _Rows:
        g = self.g
        fs, orr = self.bodies["fs"], self.bodies["or"]
        # half model: the bins over [0, pi) only (same bin width)
        nbin = self.n_bins // 2 if self.half else self.n_bins
        per = math.pi if self.half else 2 * math.pi
        centres = per * np.arange(nbin) / nbin
        hw = math.pi / self.n_bins
        G = (_arc_average_rows(fs, fs.bm.edge_sets["fs_bore"], centres, hw, +1.0, per, self.nwatch)
             + _arc_average_rows(orr, orr.bm.edge_sets["or_outer"], centres, hw, -1.0, per,
                                 self.nwatch)).tocsr()
        return _Rows("fit", G, np.full(nbin, g.r_fs_bore - g.or_outer))

    def tooth_rows(self, u_watch: np.ndarray, cand_gap: float,
                   nodes: tuple[np.ndarray, np.ndarray] | None = None) -> _Rows:
        """FS/CS tooth contact pairs at the deformed configuration, kept if the gap there is
        below ``cand_gap``; with ``nodes`` (the ``info["nodes"]`` of earlier rows) the same
        slave nodes are re-paired and re-linearised (same rows, new geometry).

        Two passes: every FS tooth-boundary node against the CS tooth segments, and the CS
        tip-land nodes (tip corners included) against the FS tooth segments: one pass alone
        would let a CS tip corner sink into an FS flank between two FS nodes.  A node beyond
        the end of its closest segment gets its distance to the corner as its gap
        (``_closest_segments``).
        """
        fs, cs = self.bodies["fs"], self.bodies["cs"]
        if nodes is None:
            sn_fs = self._indep(fs, np.intersect1d(fs.bm.node_sets["fs_teeth"], fs.watch_nodes))
            cn = np.intersect1d(cs.bm.node_sets["cs_teeth"], cs.watch_nodes)
            r_cn = np.hypot(cs.x[0, cn], cs.x[1, cn])
            tip_band = self.g.r_cs_tip + CS_TIP_BAND * (self.g.r_cs_root - self.g.r_cs_tip)
            sn_cs = self._indep(cs, cn[r_cn <= tip_band])
        else:
            sn_fs, sn_cs = nodes
        G1, Gt1, g1, k1 = self._node_to_segment(fs, sn_fs, cs, "cs_teeth", u_watch, cand_gap)
        G2, Gt2, g2, k2 = self._node_to_segment(cs, sn_cs, fs, "fs_teeth", u_watch, cand_gap)
        sn_fs, sn_cs = sn_fs[k1], sn_cs[k2]
        # which FS tooth a pair belongs to (teeth in contact); the half model's tooth z/2
        # is the image of tooth 0 (ids modulo z/2; counted twice)
        zid = self.g.z_fs // 2 if self.half else self.g.z_fs
        th = np.concatenate([np.arctan2(fs.x[1, sn_fs], fs.x[0, sn_fs]),
                             np.arctan2(cs.x[1, sn_cs], cs.x[0, sn_cs])])
        tooth = np.round(th / (2 * math.pi / self.g.z_fs)).astype(int) % zid
        return _Rows("tooth", sp.vstack([G1, G2]).tocsr(), np.concatenate([g1, g2]),
                     {"tooth": tooth, "nodes": (sn_fs, sn_cs),
                      "Gt": sp.vstack([Gt1, Gt2]).tocsr()})

    def _node_to_segment(self, sb: _Body, sn: np.ndarray, mb: _Body, edge_set: str,
                         u_watch: np.ndarray, cand_gap: float):
        """Slave nodes ``sn`` of body ``sb`` against the closest boundary segment of body
        ``mb`` (group ``edge_set``), gap along the segment's outward normal at the deformed
        configuration.  Returns (G, Gt, g0, kept): normal and tangential (slip) rows
        d . (u_slave - u_master point) and the gap g0 + G u of the kept pairs."""
        xs = sb.x[:, sn] + _node_u(sb, sn, u_watch)
        E = mb.bm.edge_sets[edge_set]
        E = E[(mb.wpos[0, E[:, 0]] >= 0) & (mb.wpos[0, E[:, 1]] >= 0)]
        nrm = _boundary_edge_normals(mb.bm.mesh, E)
        xa = mb.x[:, E[:, 0]] + _node_u(mb, E[:, 0], u_watch)
        xb = mb.x[:, E[:, 1]] + _node_u(mb, E[:, 1], u_watch)
        bg, be, bt = _closest_segments(xs, xa, xb, nrm)
        kept = bg < cand_gap
        sn, bg, be, bt = sn[kept], bg[kept], be[kept], bt[kept]
        n = nrm[:, be]
        k = sn.size

        def pair_rows(d):
            rows, cols, vals = [], [], []
            for comp in (0, 1):
                rows += [np.arange(k)] * 3
                cols += [sb.wpos[comp, sn], mb.wpos[comp, E[be, 0]], mb.wpos[comp, E[be, 1]]]
                vals += [d[comp], -(1 - bt) * d[comp], -bt * d[comp]]
            return sp.csr_matrix((np.concatenate(vals),
                                  (np.concatenate(rows), np.concatenate(cols))),
                                 shape=(k, self.nwatch))

        G = pair_rows(n)
        Gt = pair_rows(np.vstack([-n[1], n[0]]))   # slip along the master segment (friction)
        return G, Gt, bg - G @ u_watch, kept

    @staticmethod
    def _indep(b: _Body, nodes: np.ndarray) -> np.ndarray:
        """Nodes without the tied cut nodes at angle pi (half model): their rows would
        repeat those of their partners at angle 0."""
        nodes = np.asarray(nodes)
        return nodes if b.dep.size == 0 else nodes[~np.isin(nodes, b.dep)]

    # ---------------------------------------------------------------- working set
    def _all_rows(self):
        kinds = list(self.rows)
        G = sp.vstack([self.rows[k].G for k in kinds]).tocsr()
        g0 = np.concatenate([self.rows[k].g0 for k in kinds])
        ids = [(k, i) for k in kinds for i in range(self.rows[k].G.shape[0])]
        return G, g0, ids

    def _slip_rows(self, ids) -> sp.csr_matrix:
        """Slip rows (tangent to the CS flank) of the pairs ``ids``; zero for non-teeth."""
        out = []
        for k, i in ids:
            gt = self.rows[k].info.get("Gt")
            out.append(gt[i] if gt is not None else sp.csr_matrix((1, self.nwatch)))
        return sp.vstack(out).tocsr() if out else sp.csr_matrix((0, self.nwatch))

    def _all_slip_rows(self) -> sp.csr_matrix:
        return sp.vstack([self.rows[k].info["Gt"] if "Gt" in self.rows[k].info
                          else sp.csr_matrix((self.rows[k].G.shape[0], self.nwatch))
                          for k in self.rows]).tocsr()

    @staticmethod
    def _grow(buf: np.ndarray, n0: int, k: int) -> np.ndarray:
        if n0 + k <= buf.shape[1]:
            return buf
        cap = max(2 * buf.shape[1], n0 + k, 256)     # grow the column store geometrically
        new = np.zeros((buf.shape[0], cap))
        new[:, :n0] = buf[:, :n0]
        return new

    def _add_to_W(self, ids: list[tuple[str, int]]):
        ids = [i for i in ids if i not in self.Wpos]
        if not ids:
            return
        Gn = sp.vstack([self.rows[k].G[i] for k, i in ids]).tocsr()
        X, Xq = self._columns(Gn)
        n0, k = len(self.W), len(ids)
        self._Xbuf = self._grow(self._Xbuf, n0, k)
        self._Xbuf[:, n0:n0 + k] = X
        for i in ids:
            self.Wpos[i] = len(self.W)
            self.W.append(i)
        self.Xq = np.concatenate([self.Xq, Xq])
        # compliance among the working set, C_ij = G_i K^-1 G_j^T, grown by new columns
        self._GW = Gn if self._GW is None else sp.vstack([self._GW, Gn]).tocsr()
        newcols = np.asarray(self._GW @ X)
        CW = np.zeros((n0 + k, n0 + k))
        CW[:n0, :n0] = self.CW
        CW[:, n0:] = newcols
        CW[n0:, :n0] = newcols[:n0].T
        self.CW = CW
        if self.mu > 0:                    # columns of the slip rows (not symmetric)
            Tn = self._slip_rows(ids)
            Y, Yq = self._columns(Tn)
            self._Ybuf = self._grow(self._Ybuf, n0, k)
            self._Ybuf[:, n0:n0 + k] = Y
            self.Yq = np.concatenate([self.Yq, Yq])
            self._TW = Tn if self._TW is None else sp.vstack([self._TW, Tn]).tocsr()
            CWY = np.zeros((n0 + k, n0 + k))
            CWY[:n0, :n0] = self.CWY
            CWY[:, n0:] = np.asarray(self._GW @ Y)
            CWY[n0:, :n0] = np.asarray(Gn @ self._Ybuf[:, :n0])
            self.CWY = CWY
            CWYY = np.zeros((n0 + k, n0 + k))
            CWYY[:n0, :n0] = self.CWYY
            CWYY[:, n0:] = np.asarray(self._TW @ Y)
            CWYY[n0:, :n0] = np.asarray(Tn @ self._Ybuf[:, :n0])
            self.CWYY = CWYY

    @property
    def Yw(self) -> np.ndarray:
        return self._Ybuf[:, :len(self.W)]

    @property
    def Xw(self) -> np.ndarray:
        return self._Xbuf[:, :len(self.W)]

    def _replace_rows(self, kind: str, rows: _Rows):
        """New linearisation of one kind of rows (same count): refresh its columns."""
        self.rows[kind] = rows
        idx = [(self.Wpos[(k, i)], i) for (k, i) in self.W if k == kind]
        if idx:
            pos = np.array([a for a, _ in idx])
            X, Xq = self._columns(rows.G[[b for _, b in idx]])
            self._Xbuf[:, pos] = X
            self.Xq[pos] = Xq
            self._GW = sp.vstack([self.rows[k].G[i] for k, i in self.W]).tocsr()
            self.CW = np.asarray(self._GW @ self.Xw)
            if self.mu > 0:
                Y, Yq = self._columns(self._slip_rows([(kind, b) for _, b in idx]))
                self._Ybuf[:, pos] = Y
                self.Yq[pos] = Yq
                self.CWY = np.asarray(self._GW @ self.Yw)
                self._TW = self._slip_rows(self.W)
                self.CWYY = np.asarray(self._TW @ self.Yw)

    # ---------------------------------------------------------------- full fields
    def full_displacements(self, st: dict, T: float) -> dict[str, np.ndarray]:
        """Displacement (2, nnodes) of every body at a solved level, u = K^-1 (f + G^T p) + R alpha
        (the same superposition the twist is read from); one back-substitution per body."""
        G, _, _ = self._all_rows()
        forces = G.T @ st["p"]
        if self.mu > 0:                  # friction: the forces lean along the flank
            forces = forces + self._all_slip_rows().T @ st["ft"]
        force_watch = sp.csc_matrix(forces[:, None])
        out = {}
        for name, b in self.bodies.items():
            F = self._watch_to_body(name, force_watch)
            if name == "fs":
                F[:, 0] += T * self.f_scale * self.q
            u = self._solve_body(b, F)[:, 0]
            for j, (bn, mn) in enumerate(self.mode_list):
                if bn == name:
                    u = u + st["alpha"][j] * b.modes[mn]
            out[name] = np.vstack([u[b.nd[0]], u[b.nd[1]]])
        return out

    # ---------------------------------------------------------------- one load level
    def solve_level(self, T: float, active: dict | None):
        """Solve the contact problem at torque T (N mm), warm-started from ``active``
        (and the last displacement); Hertz secants of the balls iterated to 0.1 %.

        With flank friction the stick/slip state of every loaded tooth pair is iterated
        too: a pair coming into contact slides against its slip; a sticking pair whose
        tangential force leaves the cone |f_t| <= mu p slides in the force's direction; a
        sliding pair whose slip runs with its friction force sticks."""
        G, g0, ids = self._all_rows()
        R, Rq, Rf = self._R()
        GR = G @ R
        ball_idx = np.array([j for j, (k, _) in enumerate(ids) if k == "ball"])
        idpos = {i: j for j, i in enumerate(ids)}
        act = set() if active is None else set(k for k, v in active.items() if v)
        # initial: every violated pair at zero contact force
        base = getattr(self, "_u_last", None)
        u0 = T * self.uq_watch if base is None else base
        gfree = g0 + G @ u0
        act |= {ids[j] for j in np.flatnonzero(gfree < -self.tol_gap)}
        fr = None
        if self.mu > 0:
            # friction state of every tooth pair: +-1 sliding (tangential force mu p sigma),
            # 0 sticking (tangential force unknown, slip over the step = 0), nan not yet
            # in contact (no tangential force until its slip is known)
            Gt = self._all_slip_rows()
            tooth = np.array([k == "tooth" for k, _ in ids])
            state = np.array([self._sigma.get(i, np.nan) for i in ids])
            fr = dict(Gt=Gt, TR=Gt @ R, s_target=Gt @ u0, state=state)
        for fric_it in range(FRICTION_MAX_IT):
            p_full, ft, alpha, u, gap, act = self._hertz_loop(T, G, g0, ids, idpos, R, Rq, Rf,
                                                              GR, act, ball_idx, fr)
            if fr is None:
                break
            state = fr["state"]
            slip = fr["Gt"] @ u - fr["s_target"]
            loaded = tooth & (p_full > 0)
            new = state.copy()
            new[~loaded] = np.nan
            # a pair coming into contact slides against its slip
            fresh = loaded & np.isnan(state)
            new[fresh] = np.where(np.abs(slip[fresh]) < SLIP_TOL, 0.0, -np.sign(slip[fresh]))
            # sticking pair beyond the cone: slides in the direction of its force
            over = loaded & (state == 0) & (np.abs(ft) > self.mu * p_full * (1 + 1e-9))
            new[over] = np.sign(ft[over])
            # sliding pair whose slip runs with its friction force: it sticks
            back = loaded & (state != 0) & (state * slip > SLIP_TOL)
            new[back] = 0.0
            if np.array_equal(new, state, equal_nan=True):
                break
            fr["state"] = new
        else:
            raise ContactFailure("flank friction: stick/slip states did not settle in "
                                 f"{FRICTION_MAX_IT} iterations at T={T / 1000:.4g} N m")
        if fr is not None:
            self._sigma = {ids[j]: float(fr["state"][j]) for j in np.flatnonzero(tooth)}
        self._u_last = u
        wp = np.array([self.Wpos[i] for i in ids if i in self.Wpos], dtype=np.int64)
        pw = np.array([p_full[idpos[i]] for i in ids if i in self.Wpos])
        twist = T * self.qq + (self.Xq[wp] @ pw if wp.size else 0.0) + Rq @ alpha
        if fr is not None and wp.size:
            fw = np.array([ft[idpos[i]] for i in ids if i in self.Wpos])
            twist += self.Yq[wp] @ fw
        return dict(p=p_full, alpha=alpha, u=u, gap=gap, ids=ids, twist=float(twist),
                    active={i: True for i in act}, ft=ft)

    def _hertz_loop(self, T, G, g0, ids, idpos, R, Rq, Rf, GR, act, ball_idx, fr):
        pb = getattr(self, "_ball_p", None)
        if pb is None:
            pb = np.full(self.rows["ball"].G.shape[0], 1.0)
        for hertz_it in range(40):
            s_ball = self.ball_c * np.maximum(pb, 1e-3) ** (-1.0 / 3.0)
            p_full, ft, alpha, u, gap, conv = self._pdas(T, G, g0, ids, idpos, R, Rq, Rf, GR,
                                                         act, s_ball, ball_idx, fr)
            act = {ids[j] for j in np.flatnonzero(p_full > 0)}
            pb_new = p_full[ball_idx]
            on = pb_new > 0        # the secant of an open ball does not matter
            change = (np.max(np.abs(pb_new - pb)[on]) if on.any() else 0.0) / max(
                1e-9, np.max(np.abs(pb_new)))
            pb = np.where(pb_new > 0, pb_new, pb)
            if not conv:
                raise ContactFailure(f"active-set iteration did not converge in "
                                     f"{self.max_iter} iterations at T={T / 1000:.4g} N m")
            if change < 1e-3:
                break
        else:
            raise ContactFailure("Hertz secant iteration on ball loads did not converge")
        self._ball_p = pb
        return p_full, ft, alpha, u, gap, act

    def _pdas(self, T, G, g0, ids, idpos, R, Rq, Rf, GR, act, s_ball, ball_idx, fr=None):
        """Primal-dual active set on the dense dual problem; see the module docstring."""
        nm = R.shape[1]
        npairs = len(ids)
        sdiag = np.zeros(npairs)
        sdiag[ball_idx] = s_ball
        Guq = G @ self.uq_watch
        friction = fr is not None
        ft_full = np.zeros(npairs)
        A = set(act)
        for it in range(self.max_iter):
            self.iterations += 1
            self._add_to_W(sorted(A - set(self.Wpos)))
            # a loaded rigid mode with nothing holding it: add the first pair it closes
            Al = sorted(A, key=lambda i: self.Wpos[i])
            rows = [idpos[i] for i in Al]
            for j in range(nm):
                load = T * Rf[j]
                if abs(load) < 1e-12:
                    continue
                held = np.abs(GR[rows, j]).max() if rows else 0.0
                if held > 1e-12:
                    continue
                base = getattr(self, "_u_last", None)
                gfree = g0 + G @ (base if base is not None else T * self.uq_watch)
                rate = GR[:, j] * np.sign(load)
                closing = np.flatnonzero(rate < -1e-12)
                if closing.size == 0:
                    raise ContactFailure(f"rigid mode {self.mode_list[j]} is loaded but no "
                                         "contact pair can hold it")
                need = gfree[closing] / (-rate[closing])
                jbest = closing[np.argmin(need)]
                A.add(ids[jbest])
                self._add_to_W([ids[jbest]])
            Al = sorted(A, key=lambda i: self.Wpos[i])
            wp = np.array([self.Wpos[i] for i in Al], dtype=np.int64)
            rows = np.array([idpos[i] for i in Al], dtype=np.int64)
            nA = len(Al)
            C = self.CW[np.ix_(wp, wp)]
            C = 0.5 * (C + C.T) + np.diag(sdiag[rows])
            H = GR[rows]
            scale = np.abs(np.diag(C)).max() if nA else 1.0
            if not friction:
                nS = 0
                M = np.zeros((nA + nm, nA + nm))
                M[:nA, :nA] = C + 1e-13 * scale * np.eye(nA)
                M[:nA, nA:] = H
                M[nA:, :nA] = H.T
                rhs = np.concatenate([-(g0[rows] + T * Guq[rows]), -T * Rf])
            else:
                # unknowns (p_A, lambda_S, alpha): sliding pairs add mu sigma p along the
                # flank, sticking pairs S an unknown tangential force with zero slip
                st = fr["state"][rows]
                ms = self.mu * np.nan_to_num(st)
                sk = np.flatnonzero(st == 0)
                Swp, Srows, nS = wp[sk], rows[sk], sk.size
                TR = fr["TR"]
                n = nA + nS
                M = np.zeros((n + nm, n + nm))
                M[:nA, :nA] = C + self.CWY[np.ix_(wp, wp)] * ms[None, :] + 1e-13 * scale * np.eye(nA)
                M[:nA, nA:n] = self.CWY[np.ix_(wp, Swp)]
                M[:nA, n:] = H
                M[nA:n, :nA] = self.CWY[np.ix_(wp, Swp)].T + self.CWYY[np.ix_(Swp, wp)] * ms[None, :]
                M[nA:n, nA:n] = self.CWYY[np.ix_(Swp, Swp)] + 1e-13 * scale * np.eye(nS)
                M[nA:n, n:] = TR[Srows]
                M[n:, :nA] = (H + ms[:, None] * TR[rows]).T
                M[n:, nA:n] = TR[Srows].T
                Gt = fr["Gt"]
                rhs = np.concatenate([-(g0[rows] + T * Guq[rows]),
                                      fr["s_target"][Srows] - T * (Gt[Srows] @ self.uq_watch),
                                      -T * Rf])
            M[nA + nS:, nA + nS:] = -1e-14 * np.eye(nm)   # keeps unheld, unloaded modes at zero
            try:
                sol = np.linalg.solve(M, rhs)
            except np.linalg.LinAlgError:
                sol = np.linalg.lstsq(M, rhs, rcond=None)[0]
            pA, alpha = sol[:nA], sol[nA + nS:]
            pW = np.zeros(len(self.W))
            pW[wp] = pA
            u = T * self.uq_watch + self.Xw @ pW + R @ alpha
            if friction:
                ftA = ms * pA
                ftA[sk] = sol[nA:nA + nS]
                fW = np.zeros(len(self.W))
                fW[wp] = ftA
                u = u + self.Yw @ fW
                ft_full = np.zeros(npairs)
                ft_full[rows] = ftA
            p_full = np.zeros(npairs)
            p_full[rows] = pA
            gap = g0 + G @ u + sdiag * p_full
            neg = [Al[k] for k in np.flatnonzero(pA < 0)]
            viol = np.flatnonzero(gap < -self.tol_gap)
            viol = viol[np.argsort(gap[viol])]
            viol = [ids[j] for j in viol if ids[j] not in A]
            # limited addition: the most violated few first (full switching cycles when
            # a near-mechanism makes one iterate overshoot)
            viol = viol[:max(self.add_min, int(self.add_frac * len(viol)))]
            if self.debug:
                kinds = [k for k, _ in Al]
                print(f"it {it} nA {nA} teeth {kinds.count('tooth')} neg {len(neg)} viol {len(viol)} "
                      f"ming {gap.min():.3g} alpha {np.round(alpha, 6)}")
            if not neg and not viol:
                p_full = np.maximum(p_full, 0.0)
                return p_full, ft_full, alpha, u, gap, True
            if it > 25 and neg:          # anti-cycling: one change at a time
                neg = [Al[int(np.argmin(pA))]]
            A.difference_update(neg)
            A.update(viol)
        return p_full, ft_full, alpha, u, gap, False


# --------------------------------------------------------------------------------------
# Public driver
# --------------------------------------------------------------------------------------
def series_output_twist(rim_twist_rad: np.ndarray, torque_Nmm: np.ndarray,
                        changes: ModelChanges) -> np.ndarray:
    """Twist at the output (rad) from the twist of the FS rim along the test sequence:
    the series spring adds T c, the dead band +-play/2 in the direction of the last
    non-zero load (the zero-torque steps keep the side they were loaded from)."""
    out = np.asarray(rim_twist_rad, dtype=float) + changes.output_compliance_rad_per_Nmm * \
        np.asarray(torque_Nmm, dtype=float)
    if changes.output_play_rad:
        side, last = np.zeros(len(out)), 1.0
        for k, T in enumerate(torque_Nmm):
            if abs(T) > 0:
                last = math.copysign(1.0, T)
            side[k] = last
        out = out + 0.5 * changes.output_play_rad * side
    return out


def _load_path(steps_per_ramp: int) -> np.ndarray:
    n = steps_per_ramp
    up = np.linspace(0, 1, n + 1)
    return np.concatenate([up, up[::-1][1:], -up[1:], -up[::-1][1:]])


def _mount_wave_generator(model: LostMotionModel, geom: DriveGeometry):
    """Stage 1: the wave generator pushed into the FS (no teeth), FS rotation pinned.
    Returns (u_wg, state, wg deflection in um)."""
    # (the half model's symmetric field has no translations: no modes in stage 1)
    model.mode_list = [] if model.half else [("fs", "tx"), ("fs", "ty"), ("ir", "tx"),
                                             ("ir", "ty"), ("or", "tx"), ("or", "ty")]
    model.rows["ball"] = model.ball_rows()
    model.rows["fit"] = model.fit_rows()
    u = np.zeros(model.nwatch)
    model.rows["cam"] = model.cam_rows(u)
    state = None
    for geo_it in range(6):
        state = model.solve_level(0.0, state["active"] if state else None)
        u = state["u"]
        new = model.cam_rows(u)
        change = np.max(np.abs((new.g0 + new.G @ u) - (model.rows["cam"].g0
                                                        + model.rows["cam"].G @ u)))
        if change < 1e-6 and geo_it > 0:
            break
        model._replace_rows("cam", new)
    fs = model.bodies["fs"]
    bore = fs.bm.node_sets["fs_bore"]
    j0 = bore[np.argmin((fs.x[0, bore] - geom.r_fs_bore) ** 2 + fs.x[1, bore] ** 2)]
    return u, state, float(u[fs.wpos[0, j0]]) * 1000.0


def _torque_test(model: LostMotionModel, geom: DriveGeometry, frac: np.ndarray, u_wg, state,
                 fields: dict | None):
    """Stage 2: teeth at the deflected configuration, FS rotation free, the torque sequence.
    Returns (rim twists in rad, max penetration, re-detected penetration, teeth in contact)."""
    Tn = geom.torque
    cand = 0.25 * geom.module + 3 * (geom.r_fs + geom.r_cs)
    model.rows["tooth"] = model.tooth_rows(u_wg, cand)
    model.mode_list = model.mode_list + [("fs", "rot")]
    active = state["active"]
    twists, maxpen, maxpen_nl, tooth_count = [], 0.0, 0.0, 0
    last_sign = 1.0
    for k, fr in enumerate(frac):
        if abs(fr) > 1e-12:
            last_sign = math.copysign(1.0, fr)
            T = fr * Tn
        else:
            T = ZERO_TORQUE_BIAS * Tn * last_sign
        st = model.solve_level(T, active)
        if abs(abs(fr) - 1.0) < 1e-12:
            # independent check at +-T: re-detect every FS/CS pair in the zones at the
            # deformed configuration (nonlinear gap, no candidate threshold).  Large
            # twists slide the flanks along each other; if the linearised pairing
            # then misses more than RELIN_TOL, re-pair and re-linearise the tooth
            # rows about this state and solve the level again.
            for relin in range(4):
                chk = model.tooth_rows(st["u"], np.inf)
                pen_nl = float(-(chk.g0 + chk.G @ st["u"]).min())
                if pen_nl <= RELIN_TOL or relin == 3:
                    break
                tr = model.rows["tooth"]
                new = model.tooth_rows(st["u"], np.inf, nodes=tr.info["nodes"])
                # only pairs at or near contact are re-linearised; the open flanks
                # keep the WG-state pairing, which is the right one for the way back
                near = (tr.g0 + tr.G @ st["u"]) < RELIN_NEAR
                Dn = sp.diags(near.astype(float))
                Df = sp.diags((~near).astype(float))
                info = dict(tr.info, Gt=(Dn @ new.info["Gt"] + Df @ tr.info["Gt"]).tocsr())
                mixed = _Rows("tooth", (Dn @ new.G + Df @ tr.G).tocsr(),
                              np.where(near, new.g0, tr.g0), info)
                model._replace_rows("tooth", mixed)
                st = model.solve_level(T, st["active"])
            maxpen_nl = max(maxpen_nl, pen_nl)
        active = st["active"]
        twists.append(st["twist"])
        kinds = np.array([i[0] for i in st["ids"]])
        geo_mask = kinds != "ball"
        maxpen = max(maxpen, float(-(st["gap"][geo_mask]).min()))
        if abs(fr - 1.0) < 1e-12:
            if fields is not None and "plus" not in fields:
                fields["plus"] = model.full_displacements(st, T)
            tr = model.rows["tooth"]
            ti = [i for (kk, i) in st["ids"] if kk == "tooth"]
            pt = st["p"][kinds == "tooth"]
            tooth_count = int(np.unique(tr.info["tooth"][np.array(ti)[pt > 0]]).size)
            if model.half:
                tooth_count *= 2             # every tooth has its image at +pi
    return np.array(twists), maxpen, maxpen_nl, tooth_count


def _result(geom, frac, changes, twists, maxpen, maxpen_nl, tooth_count, model, t0, wg_defl,
            fields) -> LostMotionResult:
    Tn = geom.torque
    tw = series_output_twist(twists, frac * Tn, changes) / ARCMIN
    tw = tw - tw[0]
    kp = int(np.argmin(np.abs(frac - 1.0)))
    km = int(np.argmin(np.abs(frac + 1.0)))
    phi_p, phi_m = float(tw[kp]), float(-tw[km])
    return LostMotionResult(
        phi_plus_arcmin=phi_p, phi_minus_arcmin=phi_m,
        lost_motion_arcmin=phi_p + phi_m, step=np.arange(frac.size),
        torque_Nm=frac * Tn / 1000.0, twist_arcmin=tw, teeth_in_contact=tooth_count,
        max_penetration_um=max(0.0, maxpen) * 1000.0, iterations=model.iterations,
        status="ok", reason="", solve_s=time.perf_counter() - t0,
        factorize_s=model.factorize_s, n_dofs=model.n_dofs, wg_deflection_um=wg_defl,
        max_penetration_redetected_um=max(0.0, maxpen_nl) * 1000.0,
        notes=(f"zero-torque steps at {ZERO_TORQUE_BIAS:g} T_test towards the last load; "
               f"tooth penetration re-detected at the deformed state at +-T: "
               f"{max(0.0, maxpen_nl) * 1000:.4f} um"),
        fields=fields)


def _failed(exc, model, t0) -> LostMotionResult:
    nan, empty = float("nan"), np.array([])
    return LostMotionResult(
        phi_plus_arcmin=nan, phi_minus_arcmin=nan, lost_motion_arcmin=nan,
        step=empty, torque_Nm=empty, twist_arcmin=empty, teeth_in_contact=0,
        max_penetration_um=nan, iterations=model.iterations if model else 0,
        status="failed", reason=f"{type(exc).__name__}: {exc}",
        solve_s=time.perf_counter() - t0,
        factorize_s=model.factorize_s if model else nan,
        n_dofs=model.n_dofs if model else 0)


def solve_lost_motion(geom: DriveGeometry, mesh: DriveMesh, steps_per_ramp: int = 5,
                      E: float | None = None, max_iter: int = 200,
                      tol_gap: float = TOL_GAP, keep_fields: bool = False,
                      changes: ModelChanges | None = None) -> LostMotionResult:
    """Simulate the lost-motion test 0 -> +T -> 0 -> -T -> 0 (WG locked, CS fixed).

    ``E`` overrides Young's modulus (e.g. the rigid-body limit); ``max_iter`` limits the
    active-set iterations per load level (a run that hits it returns status "failed");
    ``keep_fields`` also returns the displacement of every node after the wave generator
    is mounted (``wg``) and at +T (``plus``); ``changes`` switches on physical additions
    to the baseline model (``ModelChanges``, set by ``hdwf.validation.effects``).
    """
    changes = ModelChanges() if changes is None else changes
    t0 = time.perf_counter()
    frac = _load_path(steps_per_ramp)
    model = None
    try:
        model = LostMotionModel(geom, mesh, E=E, max_iter=max_iter, tol_gap=tol_gap,
                                changes=changes)
        u_wg, state, wg_defl = _mount_wave_generator(model, geom)
        fields = {"wg": model.full_displacements(state, 0.0)} if keep_fields else None
        out = _torque_test(model, geom, frac, u_wg, state, fields)
        return _result(geom, frac, changes, *out, model, t0, wg_defl, fields)
    except Exception as exc:   # any failure is reported, never a silent number
        return _failed(exc, model, t0)


def solve_lost_motion_variants(geom: DriveGeometry, mesh: DriveMesh, steps_per_ramp: int,
                               variants: list[ModelChanges]) -> list[LostMotionResult]:
    """The test for several model variants of one design, sharing what they can: the bodies
    are assembled and factorised and the wave generator mounted once; each variant then
    switches its tooth-stage changes on a copy (a new CS factorisation only when it changes
    the CS support) and runs the torque sequence. Same numbers as ``solve_lost_motion``
    for each variant up to round-off."""
    t0 = time.perf_counter()
    frac = _load_path(steps_per_ramp)
    base = None
    try:
        base = LostMotionModel(geom, mesh)
        u_wg, state, wg_defl = _mount_wave_generator(base, geom)
    except Exception as exc:
        failed = _failed(exc, base, t0)
        return [failed for _ in variants]
    out = []
    for ch in variants:
        t1 = time.perf_counter()
        model = None
        try:
            model = base.fork()
            model.apply_tooth_stage_changes(ch.fe_part())
            res = _torque_test(model, geom, frac, u_wg, state, None)
            out.append(_result(geom, frac, ch, *res, model, t1, wg_defl, None))
        except Exception as exc:
            out.append(_failed(exc, model, t1))
    return out
