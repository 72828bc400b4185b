"""The paper's quadratic response surface (Eq. 11): 1 + 5 linear + 10 interaction + 5 square
terms = 21 coefficients, fitted by least squares on inputs scaled to [-1, 1] over the study
bounds (scaling keeps the normal equations well conditioned and makes the coefficients
directly usable for the exact Sobol indices of ``hdwf.study.sobol``)."""

from __future__ import annotations

from dataclasses import asdict, dataclass, field
from itertools import combinations

import numpy as np

from hdwf import PARAMETERS


def term_names(parameters=PARAMETERS) -> list[str]:
    names = ["1"] + list(parameters)
    names += [f"{a}*{b}" for a, b in combinations(parameters, 2)]
    names += [f"{p}^2" for p in parameters]
    return names


def to_centered(X: np.ndarray, lower, upper) -> np.ndarray:
    """Map inputs from [lower, upper] to u in [-1, 1]."""
    lower, upper = np.asarray(lower, float), np.asarray(upper, float)
    return 2.0 * (np.asarray(X, float) - lower) / (upper - lower) - 1.0


def design_matrix(u: np.ndarray) -> np.ndarray:
    k = u.shape[1]
    cols = [np.ones(len(u))] + [u[:, i] for i in range(k)]
    cols += [u[:, i] * u[:, j] for i, j in combinations(range(k), 2)]
    cols += [u[:, i] ** 2 for i in range(k)]
    return np.column_stack(cols)


@dataclass
class QuadraticSurrogate:
    parameters: list[str]
    lower: list[float]
    upper: list[float]
    terms: list[str]
    coefficients: list[float]
    n: int
    r2: float
    r2_adj: float
    q2_loo: float
    rmse: float
    bounds_source: str = "table3"
    extra: dict = field(default_factory=dict)

    def predict(self, X: np.ndarray) -> np.ndarray:
        return self._evaluate(to_centered(X, self.lower, self.upper))

    def predict_unit(self, U01: np.ndarray) -> np.ndarray:
        """Predict on points of the unit cube [0, 1)^k (as samplers produce them)."""
        return self._evaluate(2.0 * np.asarray(U01, float) - 1.0)

    def polynomial(self) -> tuple[float, np.ndarray, np.ndarray, np.ndarray]:
        """Eq. 11's coefficients by kind: the constant, the linear a (k), the squares q (k) and the
        interactions r (k x k, r_ij above the diagonal, zeros elsewhere)."""
        params = self.parameters
        r = np.zeros((len(params), len(params)))
        for i, j in combinations(range(len(params)), 2):
            r[i, j] = self.coefficient(f"{params[i]}*{params[j]}")
        return (self.coefficient("1"), np.array([self.coefficient(p) for p in params]),
                np.array([self.coefficient(f"{p}^2") for p in params]), r)

    def _evaluate(self, u: np.ndarray) -> np.ndarray:
        """c0 + u·a + u·(Q u), Q = diag(q) + r: the design matrix's product without the matrix
        (21 columns of 1.8 M rows for a Sobol' estimate at N = 262 144)."""
        c0, a, q, r = self.polynomial()
        return c0 + u @ a + np.einsum("ni,ni->n", u @ (np.diag(q) + r), u)

    def coefficient(self, term: str) -> float:
        return self.coefficients[self.terms.index(term)]

    def to_dict(self) -> dict:
        d = asdict(self)
        d["coefficients_by_term"] = dict(zip(self.terms, self.coefficients))
        return d

    @classmethod
    def from_dict(cls, d: dict) -> "QuadraticSurrogate":
        keys = {f for f in cls.__dataclass_fields__}
        return cls(**{k: v for k, v in d.items() if k in keys})


def fit_quadratic(X: np.ndarray, y: np.ndarray, lower, upper, bounds_source: str = "table3") -> QuadraticSurrogate:
    """Least-squares fit of Eq. 11 with R², adjusted R², leave-one-out Q² (PRESS) and RMSE.

    Q² uses the hat-matrix identity e_loo = e / (1 - h_ii), exact for least squares.
    """
    X, y = np.asarray(X, float), np.asarray(y, float)
    A = design_matrix(to_centered(X, lower, upper))
    n, p = A.shape
    if n <= p:
        raise ValueError(f"the quadratic has {p} terms and needs more than {p} designs, got {n}")
    coef, *_ = np.linalg.lstsq(A, y, rcond=None)
    resid = y - A @ coef
    ss_tot = float(np.sum((y - y.mean()) ** 2))
    r2 = 1.0 - float(resid @ resid) / ss_tot
    r2_adj = 1.0 - (1.0 - r2) * (n - 1) / (n - p)
    Q, _ = np.linalg.qr(A)
    h = np.sum(Q * Q, axis=1)
    press = float(np.sum((resid / (1.0 - h)) ** 2))
    return QuadraticSurrogate(
        parameters=list(PARAMETERS), lower=[float(v) for v in lower], upper=[float(v) for v in upper],
        terms=term_names(), coefficients=[float(c) for c in coef], n=n, r2=r2, r2_adj=r2_adj,
        q2_loo=1.0 - press / ss_tot, rmse=float(np.sqrt(np.mean(resid ** 2))), bounds_source=bounds_source,
        extra={"max_leverage": float(h.max())},
    )


def rebound(model: QuadraticSurrogate, lower, upper, bounds_source: str) -> QuadraticSurrogate:
    """The same polynomial re-expressed on other bounds (exact: a quadratic stays a quadratic
    under an affine change of variables, so a least-squares fit on 3^k grid points recovers it)."""
    k = len(model.parameters)
    grid = np.array(np.meshgrid(*[[-1.0, 0.0, 1.0]] * k, indexing="ij")).reshape(k, -1).T
    lower, upper = np.asarray(lower, float), np.asarray(upper, float)
    X = lower + (grid + 1.0) / 2.0 * (upper - lower)
    coef, *_ = np.linalg.lstsq(design_matrix(grid), model.predict(X), rcond=None)
    return QuadraticSurrogate(parameters=model.parameters, lower=list(map(float, lower)),
                              upper=list(map(float, upper)), terms=model.terms, coefficients=[float(c) for c in coef],
                              n=model.n, r2=model.r2, r2_adj=model.r2_adj, q2_loo=model.q2_loo, rmse=model.rmse,
                              bounds_source=bounds_source, extra=dict(model.extra))
