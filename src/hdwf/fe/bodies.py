"""The elastic bodies of the section: stiffness, factorisation, rigid modes, half-model ties.

Assembly (scikit-fem): each body (FS, CS, bearing inner ring IR, outer ring OR) is a
separate linear-elastic plane-stress steel mesh (E = 210 GPa, nu = 0.3; thickness = the
part's face width), P1 triangles.  Units mm, N, MPa.

Bodies and supports
-------------------
* cam: rigid analytic curve of Eq. 3, locked (not meshed; its rows are in ``contact_rows``);
* CS: every node of its outer rim is fixed (Dirichlet), or, with an elastic housing
  (``ModelChanges.cs_rim_stiffness_N_mm2``), held by springs on its rim and pinned nowhere;
* IR, OR, FS float on their contacts.  Their rigid modes are removed *without bias* the
  FETI way: each floating stiffness is factorised with three DOFs pinned, and the rigid-body
  amplitudes alpha are extra unknowns of the contact problem together with the equations
  R^T (f + G^T p) = 0 (the pinned DOFs then carry no reaction).  The two exceptions are
  exact by construction: the IR rotation is pinned (the ring is clamped on the cam; no
  torque reaches it because ball forces are radial) and the OR rotation is pinned (a free
  bearing ring: balls and the OR/FS interface act radially, so nothing can turn it and
  its pinned DOF carries zero reaction).  In the wave-generator stage the FS rotation is
  pinned as well (nothing but the teeth can hold it); in the torque stage it is free and
  its amplitude is the twist.  Which modes are unknowns at each stage is set in ``cycle``.

Half model (``mesh.symmetry == "half"``, hand-written): on the cut every node at (-x, 0)
is tied to its partner at (x, 0), u = -u_partner: body dofs u = P u_red, and
K_red = P^T K P is what is factorised (``Body.solve`` maps forces by P^T and displacements
by P, so the watch vector, the rows and the full fields keep the half-body node
numbering).  The symmetric field has no translations, so a floating half body keeps only
its rotation: one pinned tangential dof, and stage 1 has no free rigid mode at all.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field, replace

import numpy as np
import scipy.sparse as sp
from cholespy import CholeskySolverD, MatrixType
from skfem import Basis, ElementTriP1, ElementVector, MeshTri, asm
from skfem.models.elasticity import lame_parameters, linear_elasticity

from hdwf.drive.mesh import BodyMesh
from hdwf.fe.changes import ModelChanges


# --------------------------------------------------------------------------------------
# Elasticity
# --------------------------------------------------------------------------------------

class SparseCholesky:
    """K^-1 of a symmetric positive definite stiffness by CHOLMOD's sparse Cholesky factor.

    Through ``cholespy`` (its CPU solver is CHOLMOD with a fill-reducing ordering): a body's
    compliance columns are back-substituted some hundred times per design, and a Cholesky
    factor solves a block of them 2-3 times faster than SuperLU's LU of the same matrix
    (``benchmarks/bench_factor.py``). A K that is not positive definite (a floating body left
    unpinned, a negative stiffness) raises ``ValueError`` here, at the factorisation.
    """

    def __init__(self, K: sp.spmatrix):
        K = sp.csr_matrix(K, dtype=np.float64)
        self._solver = CholeskySolverD(K.shape[0], K.indptr.astype(np.int32), K.indices.astype(np.int32),
                                       K.data, MatrixType.CSR)

    def solve(self, F: np.ndarray) -> np.ndarray:
        """K^-1 F for a vector or a block of columns (n x k)."""
        B = np.ascontiguousarray(F, dtype=np.float64)
        if B.size == 0:      # no columns: cholespy would crash on an empty block
            return np.zeros(B.shape)
        X = np.empty_like(B)
        self._solver.solve(B, X)
        return X


def factorize_spd(K: sp.spmatrix) -> SparseCholesky:
    """Factorise a symmetric positive definite stiffness (pinned dofs removed): ``SparseCholesky``."""
    return SparseCholesky(K)


def plane_stress_lame(E: float, nu: float) -> tuple[float, float]:
    """Lamé parameters of plane stress.

    Parameters
    ----------
    E, nu : float
        Young's modulus (MPa) and Poisson's ratio.

    Returns
    -------
    lam, mu : float
        The plane-stress lambda = 2 lam mu / (lam + 2 mu) of the 3D ``lam`` and the shear
        modulus mu (MPa).
    """
    lam, mu = lame_parameters(E, nu)
    return 2 * lam * mu / (lam + 2 * mu), mu


def assemble_stiffness(body: BodyMesh, E: float, nu: float):
    """Plane-stress stiffness (N/mm) of a body of thickness ``body.thickness``.

    Parameters
    ----------
    body : BodyMesh
        The body's P1 triangle mesh and thickness (mm).
    E, nu : float
        Young's modulus (MPa) and Poisson's ratio.

    Returns
    -------
    K : scipy.sparse.csr_matrix
        The stiffness matrix over the body's vector dofs.
    basis : skfem.Basis
        The vector P1 basis (``basis.nodal_dofs`` numbers the dofs of every node).
    """
    basis = Basis(body.mesh, ElementVector(ElementTriP1()))
    lam, mu = plane_stress_lame(E, nu)
    K = asm(linear_elasticity(lam, mu), basis) * body.thickness
    return K.tocsr(), basis


def edge_loads(mesh, edges: np.ndarray, traction) -> np.ndarray:
    """Consistent P1 nodal forces (per unit thickness) of a traction on boundary edges.

    Parameters
    ----------
    mesh : skfem.MeshTri
        The body mesh.
    edges : numpy.ndarray
        (k, 2) node ids of the loaded boundary edges.
    traction : callable
        ``traction(x, y) -> (tx, ty)`` (N/mm^2), evaluated at two Gauss points per edge.

    Returns
    -------
    numpy.ndarray
        (2, nnodes) nodal forces (N/mm).
    """
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
    """Plain linear solve of one body (a verification helper).

    Parameters
    ----------
    body : BodyMesh
        The body.
    E, nu : float
        Young's modulus (MPa) and Poisson's ratio.
    fixed_dofs : numpy.ndarray
        Dof numbers held at zero (P1 vector dofs are interleaved, 2 n + component).
    f_nodal : numpy.ndarray
        (2, nnodes) nodal forces (N).

    Returns
    -------
    numpy.ndarray
        (2, nnodes) displacements (mm).
    """
    K, basis = assemble_stiffness(body, E, nu)
    nd = basis.nodal_dofs
    f = np.zeros(K.shape[0])
    f[nd[0]], f[nd[1]] = f_nodal[0], f_nodal[1]
    free = np.setdiff1d(np.arange(K.shape[0]), fixed_dofs)
    u = np.zeros(K.shape[0])
    u[free] = factorize_spd(K[free][:, free]).solve(f[free])
    return np.vstack([u[nd[0]], u[nd[1]]])


# --------------------------------------------------------------------------------------
# Factorised bodies
# --------------------------------------------------------------------------------------
@dataclass(frozen=True)
class Material:
    """Linear-elastic steel of every body: Young's modulus (MPa) and Poisson's ratio."""
    E: float
    nu: float


@dataclass
class Body:
    """One body, its stiffness factorised once, and where its dofs sit in the watch vector.

    ``watch_offset`` and ``watch_index`` are filled in by ``Structure`` when it numbers the
    watch vector (the dofs of every contact node of every body).
    """
    name: str
    body_mesh: BodyMesh
    stiffness: sp.csr_matrix
    dofs: np.ndarray                   # (2, nnodes) dof numbers of every node
    free_dofs: np.ndarray              # unpinned dofs (reduced dofs in the half model)
    factor: SparseCholesky             # Cholesky factor of the stiffness on the free dofs
    modes: dict[str, np.ndarray]       # name -> full-body rigid mode vector
    watch_nodes: np.ndarray            # node ids whose dofs are watched
    watch_offset: int = 0              # offset of this body in the watch vector
    watch_index: np.ndarray | None = None   # (2, nnodes) position in the watch vector or -1
    tie: sp.csr_matrix | None = None   # half model: body dofs = tie @ reduced dofs
    tied_nodes: np.ndarray = field(default_factory=lambda: np.zeros(0, dtype=np.int64))

    @property
    def x(self) -> np.ndarray:
        """Reference coordinates (2, nnodes) of the nodes (mm)."""
        return self.body_mesh.mesh.p

    def solve(self, F: np.ndarray) -> np.ndarray:
        """K^-1 F for force columns F (ndof x k) with the pinned dofs at zero."""
        if self.tie is not None:             # half model: solve on the tied (reduced) dofs
            Fr = np.asarray(self.tie.T @ F)
            Ur = np.zeros((self.tie.shape[1], F.shape[1]))
            Ur[self.free_dofs] = self.factor.solve(Fr[self.free_dofs])
            return np.asarray(self.tie @ Ur)
        U = np.zeros((self.stiffness.shape[0], F.shape[1]))
        U[self.free_dofs] = self.factor.solve(F[self.free_dofs])
        return U

    def node_displacements(self, nodes: np.ndarray, u_watch: np.ndarray) -> np.ndarray:
        """Displacements (2 x n) of watched ``nodes`` from the watch vector."""
        return np.vstack([u_watch[self.watch_index[0, nodes]],
                          u_watch[self.watch_index[1, nodes]]])

    def independent(self, nodes: np.ndarray) -> np.ndarray:
        """``nodes`` without the tied cut nodes at angle pi (half model): their contact rows
        would repeat those of their partners at angle 0."""
        nodes = np.asarray(nodes)
        return nodes if self.tied_nodes.size == 0 else nodes[~np.isin(nodes, self.tied_nodes)]

    def scaled(self, s: float) -> "Body":
        """The same body with its coordinates scaled about the axis by ``s``.

        A uniformly scaled plane-stress body has the same stiffness matrix (B ~ 1/s,
        area ~ s^2), so the factorisation is kept and only the coordinates move.
        """
        return replace(self, body_mesh=scaled_body_mesh(self.body_mesh, s))


def scaled_body_mesh(bm: BodyMesh, s: float) -> BodyMesh:
    """The body mesh scaled about the axis by ``s`` (same nodes, elements and groups).

    Parameters
    ----------
    bm : BodyMesh
        The mesh.
    s : float
        Scale factor.

    Returns
    -------
    BodyMesh
        A new mesh with coordinates ``s`` times those of ``bm``.
    """
    return BodyMesh(name=bm.name, mesh=MeshTri(bm.mesh.p * s, bm.mesh.t), thickness=bm.thickness,
                    node_sets=bm.node_sets, edge_sets=bm.edge_sets)


def _boundary_lengths(mesh, edges: np.ndarray) -> np.ndarray:
    """Tributary boundary length (mm) of every node of ``mesh`` (zero off ``edges``)."""
    p = mesh.p
    L = np.hypot(*(p[:, edges[:, 1]] - p[:, edges[:, 0]]))
    w = np.zeros(p.shape[1])
    np.add.at(w, edges[:, 0], L / 2)
    np.add.at(w, edges[:, 1], L / 2)
    return w


def _interior(p: np.ndarray, boundary: np.ndarray) -> np.ndarray:
    """Node ids that are not in ``boundary``."""
    mask = np.ones(p.shape[1], bool)
    mask[boundary] = False
    return np.flatnonzero(mask)


def _pin_nodes(p: np.ndarray, boundary: np.ndarray, r_mid: float):
    """Two interior nodes near (-r_mid, 0) and (r_mid, 0)."""
    idx = _interior(p, boundary)
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


def _floating_supports(bm: BodyMesh, nd: np.ndarray, ndof: int, tie: sp.csr_matrix | None):
    """Pinned dofs and rigid modes of a floating body (nothing holds it but its contacts).

    Full model: three dofs of two interior nodes at mid radius, modes tx, ty, rot.  Half
    model: the symmetric field has no translations; only the rotation is pinned, by the
    tangential dof of an interior node on the y axis (a reduced dof).
    """
    p = bm.mesh.p
    modes = {}
    if tie is not None:
        red = tie.indices                    # reduced dof of every body dof (one entry a row)
        on_cut = np.flatnonzero(np.abs(p[1]) <= 1e-9 * np.abs(p).max())
        bnd = np.concatenate(list(bm.node_sets.values()) + [on_cut])
        r = np.hypot(p[0], p[1])
        r_mid = 0.5 * (r.min() + r.max())
        idx = _interior(p, bnd)
        a = idx[np.argmin(p[0, idx] ** 2 + (p[1, idx] - r_mid) ** 2)]
        fixed = np.array([red[nd[0, a]]])
        v = np.zeros(ndof)
        v[nd[0]], v[nd[1]] = -p[1], p[0]
        modes["rot"] = v
        return fixed, modes
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
    return fixed, modes


def make_body(name: str, bm: BodyMesh, material: Material, watch_nodes, *, fixed_nodes=None,
              half: bool = False, ground_springs: np.ndarray | None = None) -> tuple[Body, float]:
    """Assemble and factorise one body.

    Parameters
    ----------
    name : str
        Body name (``fs``, ``cs``, ``ir``, ``or``).
    bm : BodyMesh
        Its mesh.
    material : Material
        Its steel.
    watch_nodes : array_like
        Node ids whose dofs enter the watch vector (every contact node).
    fixed_nodes : array_like, optional
        Nodes held at zero (both directions); without them and without springs the body
        floats and gets rigid modes.
    half : bool
        Half model: the cut nodes are tied (``_symmetry_map``).
    ground_springs : numpy.ndarray, optional
        N/mm per node, both directions: they hold the body elastically; then nothing is
        pinned and the body has no rigid modes.

    Returns
    -------
    body : Body
        The factorised body (its watch positions not yet numbered).
    seconds : float
        Time spent in the factorisation.
    """
    K, basis = assemble_stiffness(bm, material.E, material.nu)
    nd = basis.nodal_dofs
    if ground_springs is not None:
        kd = np.zeros(K.shape[0])
        kd[nd[0]] = ground_springs
        kd[nd[1]] = ground_springs
        K = (K + sp.diags(kd)).tocsr()
    ndof = K.shape[0]
    modes = {}
    P, dep = None, np.zeros(0, dtype=np.int64)
    Kr = K
    if half:
        P, dep = _symmetry_map(bm.mesh.p, nd)
        Kr = (P.T @ K @ P).tocsr()
    if ground_springs is not None:
        fixed = np.zeros(0, dtype=np.int64)
    elif fixed_nodes is not None:
        fixed = np.concatenate([nd[0, fixed_nodes], nd[1, fixed_nodes]])
        if half:
            fixed = np.unique(P.indices[fixed])
    else:
        fixed, modes = _floating_supports(bm, nd, ndof, P)
    free = np.setdiff1d(np.arange(Kr.shape[0]), fixed)   # reduced dofs in the half model
    t0 = time.perf_counter()
    factor = factorize_spd(Kr[free][:, free])
    tf = time.perf_counter() - t0
    wn = np.unique(np.asarray(watch_nodes, dtype=np.int64))
    return Body(name, bm, K, nd, free, factor, modes, wn, tie=P, tied_nodes=dep), tf


def make_cs_body(mesh0: BodyMesh, watch_nodes: np.ndarray, material: Material, half: bool,
                 changes: ModelChanges) -> tuple[Body, float]:
    """The CS body: scaled (thermal strain) and on rim springs (housing) as ``changes`` say.

    Parameters
    ----------
    mesh0 : BodyMesh
        The CS mesh at the FS temperature.
    watch_nodes : numpy.ndarray
        Its watched nodes (the teeth in the engagement zones).
    material : Material
        Its steel.
    half : bool
        Half model.
    changes : ModelChanges
        ``cs_scale`` and ``cs_rim_stiffness_N_mm2`` are used.

    Returns
    -------
    body : Body
        The factorised CS.
    seconds : float
        Time spent in the factorisation.
    """
    bm = mesh0 if changes.cs_scale == 1.0 else scaled_body_mesh(mesh0, changes.cs_scale)
    springs = None
    if math.isfinite(changes.cs_rim_stiffness_N_mm2):
        springs = changes.cs_rim_stiffness_N_mm2 * _boundary_lengths(bm.mesh,
                                                                     bm.edge_sets["cs_outer"])
    return make_body("cs", bm, material, watch_nodes, fixed_nodes=bm.node_sets["cs_outer"],
                     half=half, ground_springs=springs)
