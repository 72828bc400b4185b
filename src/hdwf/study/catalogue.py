"""Lost motion against makers' catalogues: the elastic Φ a real drive of the same size shows.

Harmonic Drive's catalogues give a unit's torsional stiffness K1, the slope of its torque–twist
curve below the torque T1. The lost-motion test's ±T (4 % of T_N) lies below T1 for both drives,
so a catalogue unit's elastic lost motion is Φ = 2 T / K1, hysteresis and backlash aside. That is
a check against the world that no FE model of ours or the paper's made: a whole unit (cup,
diaphragm, bearing, teeth) measured by its maker. HD 42 compares with the CSF size 17, HD 120 lies
between sizes 45 and 50 (``COMPARABLE_SIZES``; docs/fe-model.md, "Against makers' catalogues").

Two limits, in opposite directions (``LIMITS``): the values are for ratio 50, our drives are ratio
120, and K1 rises with the ratio (HFUC-32-100's 6.7·10⁴ against CSF-32-50's 5.4·10⁴ N·m/rad, 24 %),
so a ratio-120 unit's 2T/K1 is likely lower; and K1 is the mean slope from 0 to T1, while ±T is a
quarter of T1, where a real curve is softer, so its 2T/K there is likely higher.

Torque and stiffness both scale with the size cubed, so drives of one series show lost motion of
the same order in arcmin: the catalogue's two Φ stand in that ratio, which ``size_ratio`` compares
with the ratio of a model's two levels.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from hdwf.drive.geometry import ARCMIN   # rad per arcmin


@dataclass(frozen=True)
class CatalogueUnit:
    """One catalogue unit: series, size, ratio, K1 (N·m/rad) below T1 (N·m)."""

    series: str
    size: int
    ratio: int
    k1_Nm_per_rad: float
    t1_Nm: float


#: Harmonic Drive CSF series, ratio 50, as gathered for this project from the maker's catalogue
#: (sizes 17, 32, 50 with their T1 in one table, size 45 beside the paper's fits)
CATALOGUE = (
    CatalogueUnit("CSF", 17, 50, 0.81e4, 3.9),
    CatalogueUnit("CSF", 32, 50, 5.4e4, 29.0),
    CatalogueUnit("CSF", 45, 50, 15e4, 76.0),
    CatalogueUnit("CSF", 50, 50, 20e4, 108.0),
)

#: what the comparison cannot hold fixed, for the report to say beside it
LIMITS = ("the catalogue's K1 is for ratio 50 and our drives are ratio 120: a higher ratio is stiffer "
          "(24 % for size 32 at ratio 100), so a ratio-120 unit's 2T/K1 is likely lower; K1 is the mean slope "
          "from 0 to T1 and ±T is about a quarter of T1, where a real curve is softer, so its 2T/K there is "
          "likely higher")

#: the catalogue sizes each drive compares with (HD 120 lies between two)
COMPARABLE_SIZES = {"hd42": (17,), "hd120": (45, 50)}


def catalogue_units(unit: str) -> tuple[CatalogueUnit, ...]:
    """The catalogue units ``unit`` (``hd42`` or ``hd120``) compares with."""
    try:
        sizes = COMPARABLE_SIZES[unit]
    except KeyError:
        raise ValueError(f"no catalogue size compares with drive {unit!r}; known: {', '.join(COMPARABLE_SIZES)}") from None
    return tuple(u for u in CATALOGUE if u.size in sizes)


@dataclass(frozen=True)
class CatalogueCheck:
    """One drive's lost motion against the catalogue units it compares with.

    ``catalogue_phi_arcmin`` is (low, high) over those units (2 T / K1, the stiffer unit first);
    ``ratio`` each level (median Φ of a set of designs) over that range, (low, high).
    """

    unit: str
    torque_Nm: float
    sizes: tuple[int, ...]
    catalogue_phi_arcmin: tuple[float, float]
    levels_arcmin: dict[str, float]

    def ratio(self, name: str) -> tuple[float, float]:
        """The level ``name`` over the catalogue's Φ: (over the largest, over the smallest)."""
        lo, hi = self.catalogue_phi_arcmin
        return self.levels_arcmin[name] / hi, self.levels_arcmin[name] / lo

    def stiffness_Nm_per_rad(self, name: str) -> float:
        """The secant stiffness of the test, 2 T / Φ, that level ``name`` means."""
        return 2.0 * self.torque_Nm / (self.levels_arcmin[name] * ARCMIN)


def catalogue_check(unit: str, torque_Nm: float, levels_arcmin: dict[str, np.ndarray]) -> CatalogueCheck:
    """``levels_arcmin``'s median Φ (e.g. ``{"paper": ..., "ours": ...}``) against the catalogue.

    Raises ValueError when the test torque is not below every compared unit's T1 (K1 would not
    be the slope there) or a level has no finite value.
    """
    units = catalogue_units(unit)
    beyond = [u for u in units if not torque_Nm < u.t1_Nm]
    if beyond:
        raise ValueError(f"{unit}: the test torque {torque_Nm:g} N·m is not below T1 of size "
                         f"{', '.join(str(u.size) for u in beyond)}: K1 is not the slope there")
    phi = sorted(2.0 * torque_Nm / u.k1_Nm_per_rad / ARCMIN for u in units)
    levels = {}
    for name, values in levels_arcmin.items():
        finite = np.asarray(values, float)
        finite = finite[np.isfinite(finite)]
        if finite.size == 0:
            raise ValueError(f"{unit}: no finite lost motion in {name!r}")
        levels[name] = float(np.median(finite))
    return CatalogueCheck(unit, torque_Nm, tuple(u.size for u in units), (phi[0], phi[-1]), levels)


def size_ratio(small: CatalogueCheck, large: CatalogueCheck, name: str | None = None) -> tuple[float, float]:
    """The larger drive's Φ over the smaller's: the catalogue's (low, high), or level ``name``'s (twice)."""
    if name is None:
        (s_lo, s_hi), (l_lo, l_hi) = small.catalogue_phi_arcmin, large.catalogue_phi_arcmin
        return l_lo / s_hi, l_hi / s_lo
    r = large.levels_arcmin[name] / small.levels_arcmin[name]
    return r, r
