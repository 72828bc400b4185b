"""The report's references: numbered as listed, every one cited, an unknown key named."""

import re
from pathlib import Path

import pytest

from hdwf.report.document import Document
from hdwf.report.references import REFERENCES, cite, references_section

REPORT_SOURCES = Path(__file__).resolve().parents[2] / "src" / "hdwf" / "report"


def test_a_citation_is_the_works_place_in_the_list():
    keys = [r.key for r in REFERENCES]
    assert cite("paper") == "\\[1\\]"      # the paper the study reproduces comes first
    assert cite("saltelli", "jansen") == f"\\[{keys.index('saltelli') + 1}, {keys.index('jansen') + 1}\\]"


def test_an_unknown_key_is_named():
    with pytest.raises(KeyError, match="no reference nobody"):
        cite("paper", "nobody")


def test_every_listed_work_is_cited_by_some_part_of_the_report():
    """A list entry no text cites is a reference the reader cannot place."""
    cited = set()
    for src in REPORT_SOURCES.glob("*.py"):
        for args in re.findall(r"cite\(([^)]*)\)", src.read_text()):
            cited |= set(re.findall(r"'(\w+)'", args))
    assert {r.key for r in REFERENCES} <= cited
    assert len({r.key for r in REFERENCES}) == len(REFERENCES)


def test_the_section_lists_each_work_with_its_number():
    doc = Document("t", "s", {})
    references_section(doc)
    heading, *entries = doc.blocks
    assert heading == {"type": "heading", "level": 1, "text": "References", "numbered": False}
    assert [b["text"].split(" ", 1)[0] for b in entries] == [f"\\[{i}\\]" for i in range(1, len(REFERENCES) + 1)]
    assert "doi:10.3390/ma14175057" in entries[0]["text"]
