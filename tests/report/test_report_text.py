"""The report's text helpers: ``lit`` escapes typst syntax in literal text, ``fmt`` formats numbers,
``math_label`` names parameters, and ``Document`` collects blocks."""

import shutil
import subprocess

import numpy as np
import pytest

from hdwf.report.document import Document, fmt, lit, math_label

PROVENANCE = {"config_hash": "0" * 64, "git_commit": "0" * 40, "python": "3.11", "packages": {"typst": "x"}}


@pytest.mark.parametrize("ch", list("\\*_`#$@<>[]~"))
def test_lit_escapes_markup_characters_anywhere(ch):
    assert lit(f"a{ch}b") == f"a\\{ch}b"
    assert lit(ch) == f"\\{ch}"


@pytest.mark.parametrize("text, escaped", [
    ("results//paper", "results\\//paper"),           # // starts a comment
    ("http://x.org/a", "http:\\//x.org/a"),           # ... and would make a link
    ("a/*b*/c", "a\\/\\*b\\*/c"),                     # /* starts a block comment
    ("N/mm", "N/mm"),                                 # a single slash is text
    ("a--b", "a\\--b"),                               # en dash
    ("a---b", "a\\-\\--b"),                           # em dash
    ("a-?b", "a\\-?b"),                               # soft hyphen
    ("a...b", "a\\...b"),                             # ellipsis
    ("hd42-lhs-01", "hd42-lhs-01"),                   # a hyphen in a word is text
    ("\\u{41}", "\\\\u{41}"),                         # a unicode escape
    ("d*D", "d\\*D"),
    ("rFS^2", "rFS^2"),
])
def test_lit_escapes_comments_and_shorthands(text, escaped):
    assert lit(text) == escaped


@pytest.mark.parametrize("text, escaped", [
    ("- x", "\\- x"),                                 # bullet list
    ("-", "\\-"),
    ("+ x", "\\+ x"),                                 # numbered list
    ("12. x", "\\12. x"),                             # enumeration
    ("= x", "\\= x"),                                 # heading
    ("== x", "\\== x"),
    ("/ Term: x", "\\/ Term: x"),                     # term list
    ("  - x", "  \\- x"),                             # indented marker
    ("a\n- b", "a\n\\- b"),                           # at the start of a later line
    ("a - b + c = d / e", "a - b + c = d / e"),       # mid-line they are text
])
def test_lit_escapes_markers_at_the_start_of_a_line(text, escaped):
    assert lit(text) == escaped


def test_lit_leaves_quotes_and_numbers_to_typst():
    assert lit("the paper's \"Table 3\"") == "the paper's \"Table 3\""
    assert lit(-0.5) == "-0.5"


@pytest.mark.skipif(shutil.which("pdftotext") is None, reason="needs pdftotext (poppler-utils)")
def test_lit_text_typesets_as_written(tmp_path):
    texts = ["a*b_c#d$e@f<g>h`i`j[k]l~m\\n", "results//paper and a/*b*/c", "a--b a---b a-?b a...b",
             "- x", "+ y", "12. z", "= h", "/ T: d", "\\u{41}", "hd42-lhs-01"]
    doc = Document("t", "s", PROVENANCE)
    for t in texts:
        doc.text(lit(t))
    pdf = doc.compile(tmp_path / "t.pdf")
    shown = subprocess.run(["pdftotext", str(pdf), "-"], capture_output=True, text=True,
                           check=True).stdout
    # pdftotext guesses spaces from gaps between glyphs: compare without them
    lines = {"".join(line.split()) for line in shown.splitlines()}
    for t in texts:
        assert "".join(t.split()) in lines, t


def test_fmt():
    assert fmt(None) == "–" and fmt(float("nan")) == "–" and fmt(np.inf) == "–"
    assert fmt(3) == "3" and fmt(np.int64(27)) == "27"
    assert fmt(0.123456) == "0.1235" and fmt(1.5, 1) == "1.5"
    assert fmt(1e-5) == "1.00e-05" and fmt(2.5e6) == "2.50e+06" and fmt(0.0) == "0.0000"


def test_math_label():
    assert math_label("d") == "$d$"
    assert math_label("Gr") == "$G_r$"
    assert math_label("rFS") == '$r_"FS"$'


def test_document_blocks():
    doc = Document("t", "s", PROVENANCE)
    doc.heading("H", 2)
    doc.table(["a", "b"], [["x", 0.5], ["y", None]], "cap")
    doc.figure("some/where/plot.png", "fig", width="50%")
    doc.pagebreak()
    assert doc.blocks == [
        {"type": "heading", "level": 2, "text": "H"},
        {"type": "table", "columns": ["a", "b"], "caption": "cap", "rows": [["x", "0.5000"], ["y", "–"]]},
        {"type": "figure", "path": "fig00.png", "caption": "fig", "width": "50%"},
        {"type": "pagebreak"},
    ]


@pytest.mark.skipif(shutil.which("pdftotext") is None, reason="needs pdftotext (poppler-utils)")
def test_an_unnumbered_heading_and_a_table_of_text_typeset(tmp_path):
    """The summary before Part I is not section 0.1, and its table of text has the given widths,
    left-aligned; the numbering of what follows starts at 1 as before."""
    doc = Document("t", "s", PROVENANCE)
    doc.heading("At a glance", 1, numbered=False)
    doc.table(["what", "value"], [["a long description of a figure", "0.99"]], "cap", widths=["3fr", "1fr"])
    doc.heading("Part I", 1)
    assert doc.blocks[0] == {"type": "heading", "level": 1, "text": "At a glance", "numbered": False}
    assert doc.blocks[1]["widths"] == ["3fr", "1fr"]
    with pytest.raises(ValueError, match="1 widths for 2 columns"):
        doc.table(["what", "value"], [], "cap", widths=["1fr"])
    shown = subprocess.run(["pdftotext", str(doc.compile(tmp_path / "t.pdf")), "-"], capture_output=True, text=True,
                           check=True).stdout
    assert "1 Part I" in shown and "At a glance" in shown and "0.1" not in shown and "1 At a glance" not in shown
