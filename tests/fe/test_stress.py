"""The von Mises stress of a displacement field (``hdwf.fe.stress``) against closed forms of plane stress."""

import numpy as np
import pytest
from skfem import MeshTri

from hdwf.fe.stress import von_mises_stress

E, NU = 210_000.0, 0.3
MESH = MeshTri().refined(3)
X, Y = MESH.p


def test_uniaxial_stress_reads_its_own_value():
    """σ_xx = 100 MPa: ε_xx = σ/E and ε_yy = −ν σ/E; von Mises of uniaxial stress is σ."""
    u = np.vstack([100.0 / E * X, -NU * 100.0 / E * Y])
    assert von_mises_stress(MESH, u, E, NU) == pytest.approx(np.full(MESH.t.shape[1], 100.0), rel=1e-12)


def test_pure_shear_reads_root_three_tau():
    """τ_xy = 50 MPa from γ = τ / G: von Mises √3 τ."""
    G = E / (2 * (1 + NU))
    u = np.vstack([50.0 / G * Y, 0.0 * X])
    assert von_mises_stress(MESH, u, E, NU) == pytest.approx(np.full(MESH.t.shape[1], np.sqrt(3) * 50.0), rel=1e-12)


def test_a_rigid_motion_carries_no_stress():
    """A small rotation about the axis and a translation: what turns the FS in the test, not what loads it."""
    u = np.vstack([-1e-3 * Y + 0.02, 1e-3 * X - 0.01])
    assert np.abs(von_mises_stress(MESH, u, E, NU)).max() < 1e-9
