"""Candidate physical effects that the baseline FE model lacks: the registry.

Each effect is one module in this package that defines ``EFFECT = Effect(...)``: a name,
a physical description, its parameters (units, bounds, a realistic value) and the
signature it leaves in the torque–twist curve, plus ``apply``, which turns parameter values
into a change of the FE model (``hdwf.fe.ModelChanges``), never a correction of its output.
The registry imports every module of the package by itself, so adding an effect is adding
one file (``docs/adding-an-effect.md``).

Calibration needs the model response over each parameter's range. Every parameter has a
``transform`` in which that response is close to linear and zero means "effect off":
``linear`` (the value itself, e.g. a friction coefficient) or ``reciprocal`` (1/value,
e.g. a stiffness, whose compliance adds; with ``power`` p, value^-p: a ring on an elastic
foundation deflects as k^-3/4) — and a ``grid`` of values the per-specimen solves tabulate.
"""

from __future__ import annotations

import importlib
import math
import pkgutil
from dataclasses import dataclass, field
from typing import Callable

from hdwf.fe import ModelChanges


@dataclass(frozen=True)
class Parameter:
    """One parameter of an effect: its range, realistic value and calibration transform."""

    name: str
    unit: str
    lower: float
    upper: float
    realistic: float          # a typical value (synthetic data, documentation)
    description: str
    transform: str = "linear"  # "linear" or "reciprocal": response ~ linear in it, 0 = off
    grid_points: int = 4       # tabulated values besides "off" (for FE-level effects)
    realistic_by_unit: tuple = ()   # ((unit, value), ...) where a drive's size changes it
    power: float = 1.0         # "reciprocal" only: t = value**-power

    def realistic_for(self, unit: str | None) -> float:
        """The realistic value for one drive (``realistic`` unless the size changes it)."""
        return dict(self.realistic_by_unit).get(unit, self.realistic)

    def to_t(self, value: float) -> float:
        """The transformed parameter t of a value (0 = off)."""
        return float(value) ** -self.power if self.transform == "reciprocal" else float(value)

    def from_t(self, t: float) -> float:
        """The value at t (``to_t`` inverted)."""
        if self.transform == "reciprocal":
            return math.inf if t == 0 else float(t) ** (-1.0 / self.power)
        return float(t)

    def sd_from_t(self, t: float, sd_t: float) -> float:
        """Standard uncertainty of the value from that of t (linearised: |dvalue/dt| sd_t)."""
        if self.transform == "reciprocal" and t != 0:
            return sd_t * self.from_t(t) / (self.power * abs(t))
        return sd_t

    @property
    def t_bounds(self) -> tuple[float, float]:
        """The range of t, widened to include 0 (off)."""
        a, b = self.to_t(self.lower), self.to_t(self.upper)
        lo, hi = min(a, b), max(a, b)
        return (min(lo, 0.0), max(hi, 0.0))

    def clip(self, value: float) -> float:
        """``value`` held within [lower, upper] (a value from ``from_t`` may round past a bound)."""
        return min(max(float(value), self.lower), self.upper)

    def grid(self) -> list[float]:
        """Parameter values to tabulate: evenly spaced in t over the bounds, without "off"."""
        lo, hi = self.t_bounds
        n = self.grid_points
        ts = [lo + (hi - lo) * k / n for k in range(n + 1)]
        # clipped: the ends must be the bounds themselves, not their rounded round trip
        return [self.clip(self.from_t(t)) for t in ts if t != 0.0]

    def check(self, value: float, where: str) -> float:
        """``value`` as a float; a ValueError naming ``where`` when it is outside the bounds."""
        v = float(value)
        if not (self.lower <= v <= self.upper):
            raise ValueError(f"{where}: {self.name} = {value!r} {self.unit} is outside "
                             f"[{self.lower:g}, {self.upper:g}]")
        return v


@dataclass(frozen=True)
class Effect:
    """A candidate physical effect: what it is, its signature, its parameters and how it changes
    the FE model."""

    name: str
    title: str
    description: str
    signature: str
    parameters: tuple[Parameter, ...]
    apply: Callable[..., ModelChanges]   # (changes, **params) -> changes
    series: bool = False                 # acts in series at the output: no new contact solve
    # a design value (read off the drawing for a bench drive), not something that happens to a
    # drive: offered only where a campaign names it, never by ``candidates: all``
    named_only: bool = False
    references: str = ""
    off: dict = field(default_factory=dict)   # parameter values that switch it off

    def param(self, name: str) -> Parameter:
        """The parameter called ``name``."""
        for p in self.parameters:
            if p.name == name:
                return p
        raise KeyError(f"effect {self.name!r} has no parameter {name!r} "
                       f"(has: {', '.join(p.name for p in self.parameters)})")


def registry() -> dict[str, Effect]:
    """Every effect module of this package, by name (imported on first use).

    Returns
    -------
    dict
        ``{name: Effect}``, in the order of the modules' names.
    """
    out: dict[str, Effect] = {}
    for info in sorted(pkgutil.iter_modules(__path__), key=lambda i: i.name):
        if info.name.startswith("_"):
            continue
        mod = importlib.import_module(f"{__name__}.{info.name}")
        eff = getattr(mod, "EFFECT", None)
        if not isinstance(eff, Effect):
            raise TypeError(f"hdwf.validation.effects.{info.name} defines no EFFECT = Effect(...)")
        if eff.name in out:
            raise ValueError(f"two effects are named {eff.name!r}")
        out[eff.name] = eff
    return out


def get(name: str) -> Effect:
    """One effect of the registry.

    Parameters
    ----------
    name : str
        The effect's name.

    Returns
    -------
    Effect
        The effect; a KeyError listing the known ones when there is none of that name.
    """
    reg = registry()
    if name not in reg:
        raise KeyError(f"unknown effect {name!r}; known: {', '.join(reg)}")
    return reg[name]


def model_changes(effects: dict[str, dict[str, float]] | None) -> ModelChanges:
    """The FE-model changes of a set of switched-on effects.

    Parameters
    ----------
    effects : dict or None
        ``{name: {param: value}}``; every parameter of each effect must be given, within bounds.

    Returns
    -------
    ModelChanges
        The changes of all the effects, applied in turn.
    """
    ch = ModelChanges()
    for name, params in (effects or {}).items():
        eff = get(name)
        values = {}
        for p in eff.parameters:
            if p.name not in params:
                raise ValueError(f"effect {name!r}: parameter {p.name!r} is missing")
            values[p.name] = p.check(params[p.name], f"effect {name!r}")
        unknown = set(params) - {p.name for p in eff.parameters}
        if unknown:
            raise ValueError(f"effect {name!r}: unknown parameter(s) {sorted(unknown)}")
        ch = eff.apply(ch, **values)
    return ch


def parse_assignment(text: str) -> tuple[str, str, float]:
    """One effect setting as written on the command line (``--effect``), checked.

    Parameters
    ----------
    text : str
        ``NAME:PARAM=VALUE``, e.g. ``tooth_friction:mu=0.08``.

    Returns
    -------
    tuple
        ``(effect, parameter, value)``.
    """
    try:
        name, rest = text.split(":", 1)
        pname, value = rest.split("=", 1)
        v = float(value)
    except ValueError:
        raise ValueError(f"--effect {text!r}: expected NAME:PARAM=VALUE, e.g. "
                         "tooth_friction:mu=0.08") from None
    eff = get(name)
    eff.param(pname).check(v, f"--effect {text!r}")
    return name, pname, v
