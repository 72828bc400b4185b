"""A synthetic campaign's finding against what was hidden in its data (``diagnosis.json``'s
``recovery``, ``hdwf.validation.recovery``): a table in the campaign's chapter and a line of the
report's summary."""

from __future__ import annotations

from hdwf.report.document import Document, lit, significant, with_uncertainty
from hdwf.validation.effects import get as get_effect


def _unit(effect: str, param: str) -> str:
    return lit(get_effect(effect).param(param).unit)


def effect_cell(name: str) -> str:
    """An effect as a table cell: its title, and the name the config knows it by in raw text."""
    return f"{lit(get_effect(name).title)} (`{name}`)"


def _found(p: dict) -> str:
    """The found value with its sd and unit ('12.058 ± 0.068 K'), or why there is none."""
    if p["found"] is None:
        return "not named"
    told = "" if p["named"] else " (calibrated as told, not named)"
    return f"{with_uncertainty(p['found'], p['sd'])} {_unit(p['effect'], p['param'])}{told}"


def recovery_summary(rec: dict) -> str:
    """The finding in a few words: how many hidden parameters were recovered, the worst in sd."""
    params = rec["parameters"]
    n_ok = sum(p["recovered"] for p in params)
    offs = [abs(p["off_by_sd"]) for p in params if p["off_by_sd"] is not None]
    worst = f", each within {max(offs):.2f} sd" if offs and n_ok == len(params) else ""
    extra = "; also named, not hidden: " + ", ".join(lit(e) for e in rec["not_hidden"]) if rec["not_hidden"] else ""
    return f"{n_ok} of {len(params)} recovered{worst}{extra}"


def hidden_text(hidden: dict) -> str:
    """The hidden effects and values, as a cell: ``thermal 12 K, fs_cup_torsion 50000 N·m/rad``."""
    return ", ".join(f"{lit(e)} {significant(v, 5)} {_unit(e, p)}" for e, ps in hidden.items() for p, v in ps.items())


def _verdict(rec: dict) -> str:
    if rec["all_recovered"]:
        return "The campaign recovered every hidden effect"
    if rec["every_hidden_recovered"]:
        return "The campaign recovered every hidden effect, but named more than was hidden"
    return "The campaign did not recover every hidden effect"


def recovery_section(doc: Document, diag: dict, level: int) -> None:
    """What was hidden in the data, what the campaign found, and whether it recovered each value."""
    rec = diag.get("recovery")
    if not rec:
        return
    doc.heading("Against what was hidden", level)
    rows = [[effect_cell(p["effect"]), f"`{p['param']}`", f"{significant(p['hidden'], 5)} {_unit(p['effect'], p['param'])}",
             _found(p), "–" if p["off_by_sd"] is None else f"{p['off_by_sd']:+.2f}",
             "yes" if p["recovered"] else "*no*"] for p in rec["parameters"]]
    doc.table(["effect", "parameter", "hidden in the data", "found (final, ± 1 sd)", "found − hidden (sd)",
               "recovered"], rows,
              f"The data were made with these effects switched on; the campaign was not told them. Recovered: named "
              f"by the search, and its final calibrated value within {rec['within_sd']:g} standard uncertainties of "
              "the hidden one (a value without a finite uncertainty is not counted).")
    order = diag.get("verdict", {}).get("found_in_order") or []
    doc.text(f"{_verdict(rec)} ({recovery_summary(rec)}); it named "
             + (", then ".join(lit(o) for o in order) if order else "nothing") + ". " + _what_it_checks(diag))


def _mesh_text(mesh: dict) -> str:
    refined = f", refined {mesh['refinement']:g}×" if mesh.get("refinement", 1.0) != 1.0 else ""
    return f"{mesh['elements_over_height']} × {mesh['elements_over_thickness']} elements a tooth{refined}"


def _what_it_checks(diag: dict) -> str:
    """What a recovery shows: against the noise only when the data were made on the campaign's own
    mesh; through the mesh's own error, a stand-in for model error, when made on another."""
    mesh, data_mesh = diag.get("mesh") or {}, diag.get("data_mesh")
    if data_mesh and "elements_over_height" in mesh:
        return (f"The data were made by our FE model on another mesh ({_mesh_text(data_mesh)}) than the campaign "
                f"fits ({_mesh_text(mesh)}), so the mesh's own error is in them as a stand-in for model error, "
                "which the standard uncertainties above do not count; it still does not test the model's physics: "
                "only bench data can.")
    on = f" on the campaign's own mesh ({_mesh_text(mesh)})" if "elements_over_height" in mesh else ""
    return (f"The data were made by the same FE model the campaign fits{on}, so this checks the search and "
            "its calibration against the noise, not the model's physics: only bench data can test that.")
