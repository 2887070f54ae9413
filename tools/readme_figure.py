"""The README's and the docs' landing figure, drawn by the README's own command (issue 69, item 9).

    python tools/readme_figure.py

runs ``armaxmodal stabilise fixtures/supine_random.csv --plot ...`` and writes the figure to
``docs/images/stabilisation.png``, tagged with the SHA-256 of the code that draws it
(``armaxmodal/io/report/diagram_plot.py``). ``.ci/run`` runs this before the docs build, so the
site's figure is the command's; ``tests/test_readme_figure.py`` fails when the committed figure's
tag is not the drawing code's, i.e. when the drawing changed and the figure was not redrawn.
"""

from __future__ import annotations

import hashlib
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
FIGURE = ROOT / "docs" / "images" / "stabilisation.png"
DRAWING = ROOT / "armaxmodal" / "io" / "report" / "diagram_plot.py"
TAG = "armaxmodal-drawing-sha256"


def drawing_hash() -> str:
    """The first 16 hex digits of the drawing code's SHA-256."""
    return hashlib.sha256(DRAWING.read_bytes()).hexdigest()[:16]


def main() -> int:
    from PIL import Image
    from PIL.PngImagePlugin import PngInfo

    with tempfile.TemporaryDirectory() as tmp:
        drawn = Path(tmp) / "stab.png"
        command = [sys.executable, "-m", "armaxmodal", "--quiet", "stabilise", "fixtures/supine_random.csv",
                   "--plot", str(drawn)]  # fmt: skip
        subprocess.run(command, cwd=ROOT, check=True, stdout=subprocess.DEVNULL)
        info = PngInfo()
        info.add_text(TAG, drawing_hash())
        info.add_text("command", "armaxmodal stabilise fixtures/supine_random.csv --plot stab.png")
        Image.open(drawn).save(FIGURE, pnginfo=info)
    print(FIGURE)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
