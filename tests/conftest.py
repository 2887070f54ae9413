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


@pytest.fixture(scope="session")
def bundled_diagram(fixtures_dir):
    """The bundled supine ride's shared-pole diagram, orders 2-20 (no per-sensor sweeps)."""
    import armaxmodal as am

    rec = am.read_recording(fixtures_dir / "supine_random.csv")
    return am.stabilisation_diagram(rec, range(2, 21, 2), per_sensor=False)


@pytest.fixture(scope="session")
def light_ride():
    """Two lightly damped modes (about 4 and 11 Hz, 1-2 %) on a band-limited random ride
    with 2 % sensor noise: ``(structure, recording)``."""
    import armaxmodal as am

    s = am.Structure.from_chain([10.0, 5.0], [8000.0, 0.0], [8.0, 0.0], [12000.0], [5.0], ("m1", "m2"))
    u = am.random_vibration(50.0, 240.0, (0.5, 24.0), seed=3)
    return s, am.simulate_recording(s, u, 50.0, noise=0.02, seed=4, hold="bandlimited")


def open_in_headless_chromium(page: Path, profile: Path, width: int = 1400):
    """``(dom, console errors)`` of an HTML file opened in headless Chromium (Debian package
    'chromium'), or a skip where it is not installed: the reports are looked at as a reader would, in a
    window ``width`` pixels wide."""
    import shutil
    import subprocess

    chromium = shutil.which("chromium") or shutil.which("chromium-browser")
    if chromium is None:
        pytest.skip("Chromium not installed (Debian package 'chromium'); the static checks ran")
    flags = ["--headless", "--no-sandbox", "--disable-gpu", "--no-first-run", "--disable-background-networking",
             "--disable-component-update", "--disable-sync", f"--user-data-dir={profile}", "--enable-logging=stderr",
             "--v=0", "--virtual-time-budget=5000", f"--window-size={width},900", "--dump-dom"]  # fmt: skip
    run = subprocess.run([chromium, *flags, page.as_uri()], capture_output=True, text=True, timeout=120)
    return run.stdout, [line for line in run.stderr.splitlines() if "CONSOLE" in line and "rror" in line]
