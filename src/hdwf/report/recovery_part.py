"""A synthetic campaign's finding against what was hidden in its data (``diagnosis.json``'s
``recovery``, ``hdwf.validation.recovery``): a table in the campaign's chapter and a line of the
report's summary."""

from __future__ import annotations

from hdwf.report.document import Document, fmt, lit, significant
from hdwf.validation.effects import get as get_effect


def _value(effect: str, param: str, value: float) -> str:
    return f"{value:.6g} {lit(get_effect(effect).param(param).unit)}"


def recovery_summary(rec: dict) -> str:
    """The finding in a few words: how many hidden parameters were recovered, the worst in sd."""
    params = rec["parameters"]
    n_ok = sum(p["recovered"] for p in params)
    offs = [abs(p["off_by_sd"]) for p in params if p["off_by_sd"] is not None]
    worst = f", each within {fmt(max(offs), 2)} sd" if offs and n_ok == len(params) else ""
    extra = f"; also named, not hidden: {lit(', '.join(rec['not_hidden']))}" if rec["not_hidden"] else ""
    return f"{n_ok} of {len(params)} recovered{worst}{extra}"


def hidden_text(hidden: dict) -> str:
    """The hidden effects and values, as a cell: ``thermal 12 K, fs_cup_torsion 50000 N·m/rad``."""
    return ", ".join(f"{lit(e)} {_value(e, p, v)}" for e, ps in hidden.items() for p, v in ps.items())


def recovery_section(doc: Document, diag: dict, level: int) -> None:
    """What was hidden in the data, what the campaign found, and whether it recovered each value."""
    rec = diag.get("recovery")
    if not rec:
        return
    doc.heading("Against what was hidden", level)
    rows = []
    for p in rec["parameters"]:
        found = "not named" if p["found"] is None else _value(p["effect"], p["param"], p["found"])
        if p["found"] is not None and p["sd"]:
            found += f" ± {significant(p['sd'], 2)}"
        rows.append([lit(p["effect"]), lit(p["param"]), _value(p["effect"], p["param"], p["hidden"]), found,
                     "–" if p["off_by_sd"] is None else fmt(p["off_by_sd"], 2),
                     "yes" if p["recovered"] else "*no*"])
    within = rec["within_sd"]
    doc.table(["effect", "parameter", "hidden in the data", "found (final, ± 1 sd)", "found − hidden (sd)",
               "recovered"], rows,
              f"The data were made with these effects switched on; the campaign was not told them. Recovered: named, "
              f"and its final calibrated value within {within:g} standard uncertainties of the hidden one.")
    order = diag.get("verdict", {}).get("found_in_order") or []
    verdict = ("The campaign recovered every hidden effect" if rec["all_recovered"] else
               "The campaign did not recover every hidden effect")
    doc.text(f"{verdict} ({recovery_summary(rec)}); it named "
             + (lit(", then ".join(order)) if order else "nothing") + ".")
