"""Stress of a body from its displacement field: what the deformed-shape picture colours.

P1 triangles have constant strain, so each element gets one plane-stress tensor; scikit-fem
interpolates the field's gradient, the rest is Hooke's law.
"""

from __future__ import annotations

import numpy as np
from skfem import Basis, ElementTriP1, ElementVector

from hdwf.fe.bodies import plane_stress_lame


def von_mises_stress(mesh, u: np.ndarray, E: float, nu: float) -> np.ndarray:
    """The plane-stress von Mises stress (MPa) of each triangle under the displacement ``u``.

    Parameters
    ----------
    mesh : skfem.MeshTri
        The body's P1 mesh (mm).
    u : numpy.ndarray
        (2, nnodes) displacements (mm).
    E, nu : float
        Young's modulus (MPa) and Poisson's ratio.

    Returns
    -------
    numpy.ndarray
        One value per element (MPa); a rigid motion gives zero.
    """
    basis = Basis(mesh, ElementVector(ElementTriP1()), intorder=1)
    grad = basis.interpolate(np.asarray(u, float).T.ravel()).grad[..., 0]   # (2, 2, nelems), constant on P1
    strain = 0.5 * (grad + grad.transpose(1, 0, 2))
    lam, mu = plane_stress_lame(E, nu)
    trace = strain[0, 0] + strain[1, 1]
    sxx, syy, sxy = lam * trace + 2 * mu * strain[0, 0], lam * trace + 2 * mu * strain[1, 1], 2 * mu * strain[0, 1]
    return np.sqrt(sxx ** 2 - sxx * syy + syy ** 2 + 3 * sxy ** 2)
