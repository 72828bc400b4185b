"""Reading a mesh out of gmsh's current model as numpy arrays, in a body's own numbering.

gmsh numbers nodes across the whole model (and keeps points that no triangle uses, such as
an arc's centre); a body wants its own nodes only, numbered from 0.  ``SurfaceMesh`` is one
surface's triangles in that numbering, with the coordinates of its nodes and a map from
gmsh's node tags to it for the curves that bound it.
"""

from __future__ import annotations

from dataclasses import dataclass

import gmsh
import numpy as np


def _elements(dim: int, tag: int, gmsh_type: int, nodes_per_element: int) -> np.ndarray:
    types, _, nodes = gmsh.model.mesh.getElements(dim, tag)
    return np.asarray(nodes[list(types).index(gmsh_type)], dtype=np.int64).reshape(-1, nodes_per_element)


@dataclass(frozen=True)
class SurfaceMesh:
    """One meshed surface in its own numbering."""
    points: np.ndarray        # (2, n) coordinates of the nodes its triangles use (mm)
    triangles: np.ndarray     # (3, k) node numbers, as gmsh orients them
    local: np.ndarray         # gmsh node tag -> node number (-1: not on this surface)

    def curve_edges(self, curves) -> np.ndarray:
        """The line elements (m, 2) of gmsh curves ``curves`` (tags; a sign is ignored)."""
        return np.vstack([self.local[_elements(1, abs(cv), 1, 2)] for cv in curves])


def read_surface(surface: int) -> SurfaceMesh:
    """Surface ``surface`` of gmsh's current (meshed) model as a ``SurfaceMesh``."""
    tags, coords, _ = gmsh.model.mesh.getNodes(2, surface, includeBoundary=True)   # its own nodes only
    xy = np.zeros((2, int(tags.max()) + 1))
    xy[:, tags.astype(np.int64)] = coords.reshape(-1, 3)[:, :2].T
    tri = _elements(2, surface, 2, 3)
    used = np.unique(tri)
    local = -np.ones(xy.shape[1], dtype=np.int64)
    local[used] = np.arange(used.size)
    return SurfaceMesh(xy[:, used].copy(), local[tri].T.copy(), local)
