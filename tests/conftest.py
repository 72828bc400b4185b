from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
DATA = ROOT / "data" / "paper"


@pytest.fixture
def paper_dir():
    return DATA
