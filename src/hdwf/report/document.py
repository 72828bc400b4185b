"""The document model of the report: headings, markup, tables and figures collected as blocks,
the text helpers that write typst markup (``fmt`` for numbers, ``lit`` for literal text,
``math_label`` for parameter names), and typesetting to PDF with typst's embedded fonts and a
fixed date, so the same blocks give the same PDF on any machine."""

from __future__ import annotations

import json
import re
import shutil
import tempfile
from importlib import resources
from pathlib import Path

import numpy as np
import typst

from hdwf import PARAMETER_LABELS
from hdwf.common.io import atomic_path

UNIT_NAMES = {"hd42": "HD 42", "hd120": "HD 120"}

# What typst markup reads as syntax in literal text: escapes and markup (\ * _ ` # $ @ < > [ ] ~),
# comment openers (// and /*) and the shorthands -- --- -? and ... anywhere; at the start of a
# line the list, enumeration, heading and term markers ("- ", "+ ", "1. ", "= ", "/ "). Quotes
# and a minus before a digit are left to typst's typography (curly quotes, a minus sign), as in
# the prose around the literal text.
_MARKUP = re.compile(r"[\\*_`#$@<>\[\]~]|/(?=[/*])|-(?=[-?])|\.(?=\.\.)")
_LINE_START = re.compile(r"(?m)^([ \t]*)(\d+\.|=+|[-+/])(?=\s|$)")


def fmt(x, digits: int = 4) -> str:
    """A number as a table cell.

    Parameters
    ----------
    x
        The number; ``None`` or a non-finite float is missing.
    digits
        Digits after the decimal point (scientific notation keeps ``digits - 2``).

    Returns
    -------
    str
        Fixed digits, scientific when tiny or huge, an en dash for a missing value; integers
        as they are.
    """
    if x is None or (isinstance(x, float) and not np.isfinite(x)):
        return "–"
    if isinstance(x, (int, np.integer)):
        return str(int(x))
    x = float(x)
    if x != 0 and (abs(x) < 10 ** -(digits - 1) or abs(x) >= 1e6):
        return f"{x:.{max(digits - 2, 1)}e}"
    return f"{x:.{digits}f}"


def significant(value: float, digits: int = 4) -> str:
    """``value`` to ``digits`` significant figures, never in exponent notation (a calibrated value)."""
    return np.format_float_positional(value, precision=digits, unique=False, fractional=False, trim="-")


def with_uncertainty(value: float, sd: float | None, digits: int = 2) -> str:
    """``value ± sd`` with the sd to ``digits`` significant figures and the value to the same
    decimal place (``48600 ± 1800``, ``10.950 ± 0.094``); without a finite, positive sd the value
    to four significant figures."""
    if sd is None or not np.isfinite(sd) or sd <= 0:
        return significant(value, 4)
    place = int(np.floor(np.log10(sd))) - (digits - 1)    # the decimal place of the last digit kept
    if place >= 0:
        return f"{round(value, -place):.0f} ± {round(sd, -place):.0f}"
    return f"{value:.{-place}f} ± {sd:.{-place}f}"


def unit_suffix(unit: str) -> str:
    """A unit to follow a number (" N·m/rad"), nothing for a dimensionless one ("", "1", "–")."""
    return "" if unit in ("", "1", "–", "-") else " " + lit(unit)


def lit(text) -> str:
    """Literal text (a term such as ``d*D``, an id, a path) as typst markup.

    Parameters
    ----------
    text
        Anything; it is shown as ``str(text)`` reads.

    Returns
    -------
    str
        The text with a backslash before every character typst would read as syntax.
    """
    escaped = _MARKUP.sub(lambda m: "\\" + m.group(0), str(text))
    return _LINE_START.sub(r"\1\\\2", escaped)


def math_label(parameter: str) -> str:
    """A study parameter's name as the paper writes it, in typst math.

    Parameters
    ----------
    parameter
        One of ``hdwf.PARAMETERS``.

    Returns
    -------
    str
        ``$d$``, ``$G_r$`` or ``$r_"FS"$`` (a subscript of several letters stays upright).
    """
    lab = PARAMETER_LABELS[parameter]
    if "_" in lab:
        base, sub = lab.split("_", 1)
        return f'${base}_"{sub}"$' if len(sub) > 1 else f"${base}_{sub}$"
    return f"${lab}$"


class Document:
    """A list of blocks that the typst template (``templates/report.typ``) renders.

    Texts, captions and cells are typst markup: pass literal text through ``lit``.

    Parameters
    ----------
    title, subtitle
        The report's title block.
    provenance
        The provenance of the artefacts, printed under the title.
    """

    def __init__(self, title: str, subtitle: str, provenance: dict):
        self.title, self.subtitle, self.provenance = title, subtitle, provenance
        self.blocks: list[dict] = []
        self._figures: list[Path] = []

    def heading(self, text: str, level: int = 1, numbered: bool = True) -> None:
        """Add a heading, numbered unless ``numbered`` is false.

        Parameters
        ----------
        text
            Plain text, shown as it is (not markup: do not escape it).
        level
            1 for a part or chapter, 2 for a section, and so on.
        numbered
            False for a heading outside the parts' numbering (a summary before Part I).
        """
        self.blocks.append({"type": "heading", "level": level, "text": text, **({} if numbered else {"numbered": False})})

    def text(self, markup: str) -> None:
        """Add a paragraph.

        Parameters
        ----------
        markup
            The paragraph in typst markup.
        """
        self.blocks.append({"type": "text", "text": markup})

    def table(self, columns: list[str], rows: list[list], caption: str, widths: list[str] | None = None) -> None:
        """Add a table with a caption.

        Parameters
        ----------
        columns
            Column heads (markup).
        rows
            Cells: markup strings as they are, anything else through ``fmt``.
        caption
            The caption (markup).
        widths
            Typst column widths (``"2fr"``, ``"auto"``) for a table of text: its columns are then
            all left-aligned. By default every column is as wide as its cells and all but the
            first, which hold numbers, are right-aligned.
        """
        if widths is not None and len(widths) != len(columns):
            raise ValueError(f"{len(widths)} widths for {len(columns)} columns")
        block = {"type": "table", "columns": columns, "caption": caption,
                 "rows": [[c if isinstance(c, str) else fmt(c) for c in r] for r in rows]}
        if widths is not None:
            block["widths"] = widths
        self.blocks.append(block)

    def figure(self, path, caption: str, width: str = "100%") -> None:
        """Add an image with a caption; the file is copied when the document is typeset.

        Parameters
        ----------
        path
            The image file (PNG).
        caption
            The caption (markup).
        width
            The width on the page, a typst length such as ``"75%"``.
        """
        name = f"fig{len(self._figures):02d}{Path(path).suffix}"
        self._figures.append(Path(path))
        self.blocks.append({"type": "figure", "path": name, "caption": caption, "width": width})

    def pagebreak(self) -> None:
        """Start a new page (none when the page is still empty)."""
        self.blocks.append({"type": "pagebreak"})

    def compile(self, out) -> Path:
        """Typeset the document to a PDF.

        Parameters
        ----------
        out
            The PDF's path; written through an atomic rename, so it is whole or absent.

        Returns
        -------
        Path
            ``out``.
        """
        template = resources.files("hdwf.report").joinpath("templates/report.typ").read_text()
        with tempfile.TemporaryDirectory(prefix="hdwf-report-") as build:
            build = Path(build)
            for i, src in enumerate(self._figures):
                shutil.copyfile(src, build / f"fig{i:02d}{src.suffix}")
            (build / "doc.json").write_text(json.dumps({"title": self.title, "subtitle": self.subtitle,
                                                        "provenance": self.provenance, "blocks": self.blocks}))
            (build / "report.typ").write_text(template)
            with atomic_path(out) as tmp:
                # Embedded fonts only and a fixed timestamp: identical PDFs on every machine.
                typst.compile(str(build / "report.typ"), output=str(tmp), root=str(build),
                              ignore_system_fonts=True, timestamp=0)
        return Path(out)
