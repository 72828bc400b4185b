"""Stages of ``workflow/rules/report.smk``: the rule's named inputs become typed artefact records
(``hdwf.report.artefacts``) and go to the report builder, which reads them and typesets the PDF.

The rules give one named input per kind of artefact (``sobol``, ``diagnosis``, …), each a list of
paths, and in the parameter ``owners`` the same names with, per path, whose artefact it is:
``[study, unit]`` for a drive of a study, ``[campaign]`` for a validation campaign.
"""

from __future__ import annotations

from pathlib import Path
from typing import Mapping, Sequence

from hdwf.drive.design import MeshSettings
from hdwf.drive.geometry import assumptions_table
from hdwf.report.artefacts import CampaignArtefacts, DriveArtefacts, FeSettings, ReportInputs, StudyArtefacts
from hdwf.report.build import full_report, study_report


def artefacts_by_owner(inputs: Mapping[str, Sequence[str]],
                       owners: Mapping[str, Sequence[Sequence[str]]]) -> dict[tuple[str, ...], dict[str, Path]]:
    """Regroup the rule's inputs by whose artefacts they are.

    Parameters
    ----------
    inputs
        Artefact kind -> its paths (the rule's named inputs).
    owners
        Artefact kind -> per path its owner, ``[study, unit]`` or ``[campaign]``.

    Returns
    -------
    dict
        Owner (a tuple) -> artefact kind -> path.
    """
    grouped: dict[tuple[str, ...], dict[str, Path]] = {}
    for kind, paths in inputs.items():
        for owner, path in zip(owners[kind], paths, strict=True):
            grouped.setdefault(tuple(owner), {})[kind] = Path(path)
    return grouped


def study_artefacts(name: str, config: Mapping,
                    grouped: Mapping[tuple[str, ...], Mapping[str, Path]]) -> StudyArtefacts:
    """One study's record from its config and the grouped inputs.

    Parameters
    ----------
    name
        The study (a key of config ``studies``).
    config
        Its config (``source``, ``units``, ``designs``, ``surrogate_bounds``).
    grouped
        The output of ``artefacts_by_owner``.

    Returns
    -------
    StudyArtefacts
        The study with a record per drive, in config order.
    """
    drives = tuple(DriveArtefacts(unit=u, **grouped[(name, u)]) for u in config["units"])
    return StudyArtefacts(name=name, source=config["source"], designs=config.get("designs", "paper"),
                          surrogate_bounds=config.get("surrogate_bounds", "table3"), drives=drives)


def study_report_stage(study: str, config: Mapping, inputs: Mapping[str, Sequence[str]],
                       owners: Mapping[str, Sequence[Sequence[str]]], data_dir, provenance: dict, out) -> Path:
    """Rule ``study_report``: ``results/{study}/report.pdf`` from the study's artefacts.

    Parameters
    ----------
    study
        The study.
    config
        Its config (``studies.<study>``).
    inputs, owners
        The rule's named inputs and its parameter ``owners``.
    data_dir, provenance, out
        As for ``hdwf.report.build.study_report``.

    Returns
    -------
    Path
        The PDF.
    """
    artefacts = study_artefacts(study, config, artefacts_by_owner(inputs, owners))
    return study_report(artefacts, Path(data_dir), provenance, out)


def full_report_stage(studies: Mapping[str, Mapping], fe: Mapping, inputs: Mapping[str, Sequence[str]],
                      owners: Mapping[str, Sequence[Sequence[str]]], data_dir, provenance: dict, out) -> Path:
    """Rule ``full_report``: ``results/report.pdf`` from every study's and campaign's artefacts.

    Parameters
    ----------
    studies
        Config ``studies``, in its order.
    fe
        Config ``fe`` (the mesh and the load steps the report quotes).
    inputs, owners
        The rule's named inputs and its parameter ``owners``; campaigns in the order they appear.
    data_dir, provenance, out
        As for ``hdwf.report.build.study_report``.

    Returns
    -------
    Path
        The PDF.
    """
    grouped = artefacts_by_owner(inputs, owners)
    campaigns = tuple(CampaignArtefacts(name=owner[0], **files) for owner, files in grouped.items() if len(owner) == 1)
    report = ReportInputs(
        studies=tuple(study_artefacts(name, cfg, grouped) for name, cfg in studies.items()),
        campaigns=campaigns, data_dir=Path(data_dir),
        fe_settings=FeSettings(mesh=MeshSettings.from_mapping(fe), steps_per_ramp=fe["steps_per_ramp"],
                               effects=fe.get("effects", {}), calibrated_on=fe.get("calibrated_on"),
                               tip_round_m=float(fe.get("tip_round_m", 0.0)),
                               flank_layer_fs_pass_only=bool(fe.get("flank_layer_fs_pass_only", False))),
        assumptions=tuple(assumptions_table()), provenance=provenance)
    return full_report(report, out)
