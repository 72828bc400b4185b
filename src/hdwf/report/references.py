"""The works the report cites: ``cite(key)`` gives the number a text quotes, ``references_section``
lists them at the end. Numbered in the order of ``REFERENCES``, so a report's numbers do not
depend on which parts it holds."""

from __future__ import annotations

from dataclasses import dataclass

from hdwf.report.document import Document


@dataclass(frozen=True)
class Reference:
    """One cited work: the key a text cites it by, and its entry (typst markup)."""

    key: str
    entry: str


REFERENCES: tuple[Reference, ...] = (
    Reference("paper", "S. Hrcek, F. Brumercik, L. Smetanka, M. Lukac, B. Patin, A. Glowacz: Global sensitivity "
                       "analysis of chosen harmonic drive parameters affecting its lost motion. _Materials_ 14 (17), "
                       "5057 (2021), doi:10.3390/ma14175057. Its Tables 1–5 are the project's `data/paper`."),
    Reference("catalogue", "Harmonic Drive: CSF and CSG series component sets and units, the makers' catalogue "
                           "(torsional stiffness $K_1$ below the torque $T_1$, ratio 50; `hdwf.study.catalogue`)."),
    Reference("iso76", "ISO 76:2006: Rolling bearings — Static load ratings (4200 MPa contact pressure for ball bearings "
                       "other than self-aligning)."),
    Reference("celik", "I. B. Celik, U. Ghia, P. J. Roache, C. J. Freitas, H. Coleman, P. E. Raad: Procedure for "
                       "estimation and reporting of uncertainty due to discretization in CFD applications. "
                       "_J. Fluids Eng._ 130 (7), 078001 (2008)."),
    Reference("saltelli", "A. Saltelli, P. Annoni, I. Azzini, F. Campolongo, M. Ratto, S. Tarantola: Variance based "
                          "sensitivity analysis of model output. Design and estimator for the total sensitivity "
                          "index. _Comput. Phys. Commun._ 181, 259–270 (2010)."),
    Reference("jansen", "M. J. W. Jansen: Analysis of variance designs for model output. _Comput. Phys. Commun._ "
                        "117, 35–43 (1999)."),
    Reference("salib", "J. Herman, W. Usher: SALib: an open-source Python library for sensitivity analysis. "
                       "_J. Open Source Softw._ 2 (9), 97 (2017)."),
    Reference("statsmodels", "S. Seabold, J. Perktold: statsmodels: econometric and statistical modeling with "
                             "Python. _Proc. 9th Python in Science Conf._, 92–96 (2010)."),
    Reference("gmsh", "C. Geuzaine, J.-F. Remacle: Gmsh: a 3-D finite element mesh generator with built-in pre- "
                      "and post-processing facilities. _Int. J. Numer. Methods Eng._ 79 (11), 1309–1331 (2009)."),
    Reference("skfem", "T. Gustafsson, G. D. McBain: scikit-fem: a Python package for finite element assembly. "
                       "_J. Open Source Softw._ 5 (52), 2369 (2020)."),
    Reference("snakemake", "F. Mölder, K. P. Jablonski, B. Letcher et al.: Sustainable data analysis with Snakemake. "
                           "_F1000Research_ 10, 33 (2021)."),
)

_NUMBERS = {ref.key: i for i, ref in enumerate(REFERENCES, start=1)}


def cite(*keys: str) -> str:
    """The citation of ``keys`` as typst markup, e.g. ``[1]`` or ``[5, 6]``.

    Raises
    ------
    KeyError
        For a key not in ``REFERENCES``, naming it.
    """
    unknown = [k for k in keys if k not in _NUMBERS]
    if unknown:
        raise KeyError(f"no reference {', '.join(unknown)} in hdwf.report.references.REFERENCES")
    # brackets escaped: in typst markup they open and close content
    return "\\[" + ", ".join(str(_NUMBERS[k]) for k in keys) + "\\]"


def references_section(doc: Document) -> None:
    """The numbered list of every work in ``REFERENCES``, as the report's last section."""
    doc.heading("References", 1, numbered=False)
    for i, ref in enumerate(REFERENCES, start=1):
        doc.text(f"\\[{i}\\] {ref.entry}")
