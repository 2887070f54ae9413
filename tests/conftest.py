import os
from pathlib import Path

import matplotlib
import pytest

matplotlib.use("Agg")

ROOT = Path(__file__).resolve().parents[1]
FIXTURES = ROOT / "fixtures"
# CI clones main with shared/ beside it; a developer's checkout sits at the same place.
SHARED = Path(os.environ.get("ARMAXMODAL_SHARED", ROOT.parent / "shared"))


@pytest.fixture(scope="session")
def fixtures_dir() -> Path:
    return FIXTURES


@pytest.fixture(scope="session")
def realdata_dir() -> Path:
    path = SHARED / "realdata"
    if not path.is_dir():
        pytest.skip(f"real data not found at {path} (set ARMAXMODAL_SHARED)")
    return path
