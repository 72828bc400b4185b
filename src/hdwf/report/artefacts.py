"""What the report reads: the paths of each study's per-drive artefacts and of each validation
campaign's, and the settings it quotes, as typed records. Paths, and one figure the summary
and Part III both read (a campaign's measured scale); the parts of the report open the files
themselves."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Mapping
from pathlib import Path

import numpy as np
import pandas as pd

from hdwf.drive.design import MeshSettings


@dataclass(frozen=True)
class DriveArtefacts:
    """One drive's artefacts in one study (``results/{study}/{unit}/``).

    ``curves`` exist for FE studies, ``convergence`` for the mesh-convergence study and
    ``deformed_png`` for the study whose deformed mesh is pictured; ``None`` elsewhere.
    """

    unit: str
    lost_motion: Path
    doe: Path
    correlation: Path
    correlation_png: Path
    surrogate: Path
    surrogate_png: Path
    sobol: Path
    sobol_png: Path
    curves: Path | None = None
    convergence: Path | None = None
    deformed_png: Path | None = None


@dataclass(frozen=True)
class StudyArtefacts:
    """A study (config ``studies.<name>``) and its drives' artefacts, drives in config order."""

    name: str
    source: str
    designs: str
    surrogate_bounds: str
    drives: tuple[DriveArtefacts, ...]

    @property
    def units(self) -> list[str]:
        """The study's drives (``hd42``, ``hd120``) in config order."""
        return [d.unit for d in self.drives]

    def drive(self, unit: str) -> DriveArtefacts:
        """The artefacts of drive ``unit``; a ``KeyError`` when the study has no such drive."""
        for d in self.drives:
            if d.unit == unit:
                return d
        raise KeyError(f"study '{self.name}' has no drive {unit}")


@dataclass(frozen=True)
class CampaignArtefacts:
    """A validation campaign's artefacts (``results/validation/{campaign}/``); ``points`` is the
    comparison table (one row per observation, the measured value in ``D``), None where not given."""

    name: str
    diagnosis: Path
    ladder: Path
    measured_png: Path
    residuals_png: Path
    ladder_png: Path
    points: Path | None = None

    def measured_rms_arcmin(self) -> float | None:
        """The RMS of the measured values, the scale the campaign's errors are read against; None
        where the report was given no comparison points."""
        if self.points is None:
            return None
        measured = pd.read_parquet(self.points, columns=["D"])["D"].to_numpy(float)
        return float(np.sqrt(np.nanmean(measured ** 2)))


@dataclass(frozen=True)
class FeSettings:
    """The FE settings the report quotes (config ``fe``): the default mesh, the load steps, the
    effects switched on in the FE studies (``{name: {parameter: value}}``), the drive whose
    data set their values (the other drive's agreement is then a blind prediction) and the tooth
    contact's options (``fe.tip_round_m``, ``fe.flank_layer_fs_pass_only``)."""

    mesh: MeshSettings
    steps_per_ramp: int
    effects: Mapping[str, Mapping[str, float]] = field(default_factory=dict)
    calibrated_on: str | None = None
    tip_round_m: float = 0.0
    flank_layer_fs_pass_only: bool = False


@dataclass(frozen=True)
class ReportInputs:
    """Everything ``results/report.pdf`` shows: every study and campaign, in config order, the
    paper's tables, the FE settings and assumptions it quotes, and the provenance it prints."""

    studies: tuple[StudyArtefacts, ...]
    campaigns: tuple[CampaignArtefacts, ...]
    data_dir: Path
    fe_settings: FeSettings
    assumptions: tuple[dict, ...]
    provenance: dict

    @property
    def paper_studies(self) -> list[StudyArtefacts]:
        """The studies on the paper's own FEA tables (source ``paper``)."""
        return [s for s in self.studies if s.source == "paper"]

    @property
    def fe_studies(self) -> list[StudyArtefacts]:
        """The studies solved with our FE model (source ``fe``)."""
        return [s for s in self.studies if s.source == "fe"]
