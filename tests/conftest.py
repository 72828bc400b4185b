from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
DATA = ROOT / "data" / "paper"


@pytest.fixture
def paper_dir():
    return DATA


def pytest_collection_modifyitems(items):
    # every end-to-end run of a Snakemake target is slow; `pytest -m "not slow"` leaves them out
    for item in items:
        if item.get_closest_marker("e2e"):
            item.add_marker(pytest.mark.slow)
