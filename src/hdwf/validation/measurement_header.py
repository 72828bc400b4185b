"""The header of a measurement file: which of the documented forms its columns give, and what is
wrong with them before any value is read (a quantity in the wrong unit, a missing column, another
form's uncertainty, a column name mistyped). Column names only; values are ``measurements``' job."""

from __future__ import annotations

import difflib

from hdwf import PARAMETER_COLUMNS

ID_COLUMNS = ["specimen_id", "unit", *PARAMETER_COLUMNS]
FORMS = {
    "curve": ["step", "torque_Nm", "twist_arcmin"],
    "phi": ["phi_plus_arcmin", "phi_minus_arcmin"],
    "lost_motion": ["lost_motion_arcmin"],
}
UNCERTAINTY_COLUMN = {"curve": "u_twist_arcmin", "phi": "u_arcmin", "lost_motion": "u_arcmin"}
# Columns that carry the right quantity in the wrong unit: named so the user knows what to convert.
_WRONG_UNITS = {
    "torque": ("torque_Nm", ["torque_kNm", "torque_Nmm", "torque_mNm", "torque_lbfin", "torque_ozin", "torque"]),
    "twist": ("twist_arcmin", ["twist_deg", "twist_rad", "twist_arcsec", "twist_mrad", "twist_urad", "twist"]),
    "lost_motion": ("lost_motion_arcmin", ["lost_motion_deg", "lost_motion_arcsec", "lost_motion_rad"]),
}
# The units a parameter column may come in by mistake ('rFS_um', 'd_in'): only these are read as one.
_LENGTH_UNITS = {"m", "cm", "um", "µm", "micron", "microns", "nm", "in", "inch", "mil", "mils", "thou"}
# How alike (difflib's ratio) an unread column must be to a read one to be taken for a typo of it:
# one wrong, missing or swapped letter in a name of 8 or more ('u_twist_arcmn' 0.96, 'Torque_Nm'
# 0.89), not two names that merely share a unit ('u_arcmin' and 'u_twist_arcmin' 0.73).
_MISSPELLED_CUTOFF = 0.85


def form_of(columns) -> str | None:
    """The first documented form whose columns are all there, or None."""
    for form, cols in FORMS.items():
        if all(c in columns for c in cols):
            return form
    return None


def header_problems(cols: list[str]) -> tuple[str | None, list[tuple]]:
    """The form the columns give, and what is wrong with them: wrong units, missing columns, and
    columns that look meant for the loader but would be ignored (``(row, field, value, message)``,
    as ``MeasurementError`` takes them; row is None)."""
    cols = [str(c) for c in cols]
    sep = next((sep for sep in (";", "\t", "|") if sep in cols[0]), None) if len(cols) == 1 else None
    if sep:
        return None, [(None, None, None, f"the header is one column, {cols[0][:60]!r}: the columns are separated by "
                                         f"{sep!r}, not commas; save the file as comma-separated CSV")]
    problems = []
    for quantity, (right, wrongs) in _WRONG_UNITS.items():
        for w in wrongs:
            if w in cols and right not in cols:
                problems.append((None, w, None, f"wrong unit: give {quantity} as '{right}'"))
    in_other_units = _parameters_in_other_units(cols)
    for right, found in in_other_units.items():
        problems.append((None, found, None, f"wrong unit or name: give {right.removesuffix('_mm')} in mm as '{right}'"))
    form = form_of(cols)
    if form is None:
        problems.append((None, None, None,           # no one column is at fault: name none
                         "no measured quantity: need step, torque_Nm, twist_arcmin (curve), or phi_plus_arcmin, "
                         "phi_minus_arcmin, or lost_motion_arcmin; found " + ", ".join(map(str, cols))))
    for c in ID_COLUMNS:
        if c not in cols and c not in in_other_units:
            problems.append((None, c, None, "missing column"))
    problems += _unread_columns(cols, form, set(in_other_units.values()))
    return form, problems


def _parameters_in_other_units(cols: list[str]) -> dict[str, str]:
    """Missing parameter columns (``rFS_mm``) given under the same name in another unit or none
    (``rFS_um``, ``rfs``, ``d_in``): ``{the column needed: the column there}``."""
    stems = [right.removesuffix("_mm") for right in PARAMETER_COLUMNS]
    folded = [stem.lower() for stem in stems]
    found = {}
    for right, stem in zip(PARAMETER_COLUMNS, stems):
        if right in cols:
            continue
        # d and D differ only in case: their stems must match exactly; the others in any case
        same = (lambda a, b: a == b) if folded.count(stem.lower()) > 1 else (lambda a, b: a.lower() == b.lower())
        given = [c for c in cols if c not in PARAMETER_COLUMNS and same(c.split("_")[0], stem)
                 and (c.count("_") == 0 or c.split("_", 1)[1].lower() in _LENGTH_UNITS)]
        if given:
            found[right] = given[0]
    return found


def _unread_columns(cols: list[str], form: str | None, named: set[str] = frozenset()) -> list[tuple]:
    """Columns the loader would ignore that look meant for it: another form's uncertainty, or a read
    column that is absent and mistyped here (``u_twist_arcmn``, ``Torque_Nm``). Ignored, their values
    would be lost unseen. With no form, every form's columns are candidates."""
    if form is None:
        read = [*ID_COLUMNS, *(c for cs in FORMS.values() for c in cs), *dict.fromkeys(UNCERTAINTY_COLUMN.values())]
    else:
        read = [*ID_COLUMNS, *FORMS[form], UNCERTAINTY_COLUMN[form]]
    wrong_units = {w for _, wrongs in _WRONG_UNITS.values() for w in wrongs} | named   # named as such above
    absent = {r.lower(): r for r in read if r not in cols}
    problems = []
    for c in map(str, cols):
        if c in read or c in wrong_units:
            continue
        if form is not None and c in UNCERTAINTY_COLUMN.values():
            problems.append((None, c, None, f"the {form} form's uncertainty column is '{UNCERTAINTY_COLUMN[form]}': "
                                            "this one would be ignored"))
            continue
        near = difflib.get_close_matches(c.lower(), absent, n=1, cutoff=_MISSPELLED_CUTOFF)
        if near:
            problems.append((None, c, None, f"not a column the loader reads: '{absent[near[0]]}' misspelled? Other "
                                            "columns are ignored, so its values would be lost; rename it"))
    return problems
