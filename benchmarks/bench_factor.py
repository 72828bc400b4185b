"""Back-substitution with the bodies' factor: SuperLU's LU against CHOLMOD's Cholesky.

Factorises the FS and CS stiffness of HD 42 Table 4 set 8 (default half mesh, the studies'
model) both ways and times solves of 1, 8, 16 and 64 right-hand sides (medians of 5), with
the relative residual of each. The contact solver back-substitutes its compliance columns in
blocks of ``hdwf.fe.structure.SOLVE_BATCH``; this is what chose the factor (``hdwf.fe.bodies``).

Run with one thread:  OMP_NUM_THREADS=1 python benchmarks/bench_factor.py [--unit hd120]
"""

from __future__ import annotations

import argparse
import statistics
import time

import _one_thread  # noqa: F401,E402  (first: one BLAS thread, hdwf importable)

import numpy as np  # noqa: E402
import scipy.sparse as sp  # noqa: E402
from scipy.sparse.linalg import splu  # noqa: E402

from bench_solve import DESIGNS  # noqa: E402
from hdwf.config import load_config  # noqa: E402
from hdwf.drive.geometry import drive_geometry  # noqa: E402
from hdwf.drive.mesh import build_mesh  # noqa: E402
from hdwf.fe.bodies import factorize_spd  # noqa: E402
from hdwf.fe.model import LostMotionModel  # noqa: E402
from hdwf.validation.effects import model_changes  # noqa: E402
from _workspace import ROOT  # noqa: E402


def _median_s(f, repeats: int = 5) -> float:
    times = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        f()
        times.append(time.perf_counter() - t0)
    return statistics.median(times)


def main(unit: str) -> None:
    args, label = DESIGNS[unit]
    changes = model_changes(load_config(ROOT / "config.yaml")["fe"]["effects"])
    g = drive_geometry(*args, **changes.geometry_part())
    model = LostMotionModel(g, build_mesh(g, symmetry="half"), changes=changes)
    print(f"{label}, the studies' model, default half mesh")
    for name in ("fs", "cs"):
        body = model.bodies[name]
        K = body.stiffness if body.tie is None else (body.tie.T @ body.stiffness @ body.tie)
        K = sp.csc_matrix(sp.csr_matrix(K)[body.free_dofs][:, body.free_dofs])
        t_lu = _median_s(lambda: splu(K, permc_spec="MMD_AT_PLUS_A", diag_pivot_thresh=0.0,
                                      options={"SymmetricMode": True}), 3)
        t_ch = _median_s(lambda: factorize_spd(K), 3)
        lu = splu(K, permc_spec="MMD_AT_PLUS_A", diag_pivot_thresh=0.0, options={"SymmetricMode": True})
        ch = factorize_spd(K)
        print(f"{name}: {K.shape[0]} dofs; factorise SuperLU {t_lu:.3f} s, Cholesky {t_ch:.3f} s")
        for k in (1, 8, 16, 64):
            F = np.random.default_rng(k).standard_normal((K.shape[0], k))
            Ff = np.asfortranarray(F)
            s_lu, s_ch = _median_s(lambda: lu.solve(Ff)), _median_s(lambda: ch.solve(F))
            res = [np.linalg.norm(K @ X - F) / np.linalg.norm(F) for X in (lu.solve(Ff), ch.solve(F))]
            print(f"  {k:3d} columns: SuperLU {1e3 * s_lu / k:6.2f} ms a column, Cholesky "
                  f"{1e3 * s_ch / k:6.2f} ({s_lu / s_ch:.1f}x); residual {res[0]:.1e} / {res[1]:.1e}")


if __name__ == "__main__":
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--unit", choices=tuple(DESIGNS), default="hd42")
    main(ap.parse_args().unit)
