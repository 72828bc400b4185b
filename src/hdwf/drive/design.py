"""One design, from its table row to a mesh: parameters -> ``DriveGeometry`` -> ``DriveMesh``.

The mesh settings live here in one dataclass (``MeshSettings``) so every caller — the FE study,
the validation campaigns, the CLI and the benchmarks — meshes the same way.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass
from typing import Mapping

import pyarrow.parquet as pq

from hdwf import PARAMETER_COLUMNS
from hdwf.drive.geometry import DriveGeometry, drive_geometry
from hdwf.drive.mesh import BODY_NAMES, DriveMesh, build_mesh, flank_segments


@dataclass(frozen=True)
class MeshSettings:
    """How fine the section is meshed and which part of it is modelled.

    ``elements_over_height`` and ``elements_over_thickness`` are counts over a tooth (the
    paper's rule is 10 and 6); ``refinement`` multiplies both; ``symmetry`` is ``"full"`` or
    ``"half"`` (the half section with its cut tied, see ``docs/fe-model.md``);
    ``flank_refinement`` multiplies the segments along every flank only (``build_mesh``).
    """

    elements_over_height: int = 10
    elements_over_thickness: int = 6
    refinement: float = 1.0
    symmetry: str = "full"
    flank_refinement: float = 1.0

    @classmethod
    def from_mapping(cls, settings: Mapping) -> "MeshSettings":
        """Settings from a config-style mapping; keys it does not name keep their defaults."""
        known = {k: settings[k] for k in ("elements_over_height", "elements_over_thickness", "refinement",
                                          "symmetry", "flank_refinement") if k in settings}
        return cls(**known)

    def as_dict(self) -> dict:
        return asdict(self)

    @property
    def segments_per_flank(self) -> int:
        """The segments along every flank of this mesh."""
        return flank_segments(self.elements_over_height, self.refinement, self.flank_refinement)

    def mesh(self, geom: DriveGeometry, path: str | None = None, bodies: tuple[str, ...] = BODY_NAMES) -> DriveMesh:
        """Mesh ``geom`` (its ``bodies``); with ``path`` gmsh also writes its ``.msh`` there."""
        return build_mesh(geom, self.elements_over_height, self.elements_over_thickness, self.refinement,
                          path=path, symmetry=self.symmetry, bodies=bodies, flank_refinement=self.flank_refinement)


def design_parameters(designs_path, design_id: str) -> dict[str, float]:
    """The five parameters (``d_mm`` … ``rCS_mm``) of one design of a design table."""
    table = pq.read_table(designs_path, columns=["design_id", *PARAMETER_COLUMNS]).to_pydict()
    rows = [i for i, d in enumerate(table["design_id"]) if d == design_id]
    if len(rows) != 1:
        raise KeyError(f"{designs_path}: design '{design_id}' not found (have {len(table['design_id'])} designs)")
    return {c: float(table[c][rows[0]]) for c in PARAMETER_COLUMNS}


def geometry_of(unit: str, params: Mapping[str, float], interference_m: float = 0.0,
                tip_relief: float = 0.0, **shape) -> DriveGeometry:
    """The drive geometry of ``unit`` at the design parameters ``params`` (keys ``d_mm`` …), with
    the preloaded engagement and tip relief of ``drive_geometry`` (default: none); ``shape``
    passes ``tip_round_m``, ``deflection_coeff``, ``addendum_frac`` and ``offset_direction`` on."""
    return drive_geometry(unit, params["d_mm"], params["D_mm"], params["Gr_mm"], params["rFS_mm"], params["rCS_mm"],
                          interference_m=interference_m, tip_relief=tip_relief, **shape)


def mesh_design(unit: str, params: Mapping[str, float], settings: Mapping | MeshSettings) -> DriveMesh:
    """Mesh one design with the given settings (a ``MeshSettings`` or a config mapping)."""
    if not isinstance(settings, MeshSettings):
        settings = MeshSettings.from_mapping(settings)
    return settings.mesh(geometry_of(unit, params))
