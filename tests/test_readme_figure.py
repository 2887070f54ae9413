"""The committed landing figure is the one the README's command draws with today's drawing code
(``tools/readme_figure.py`` tags it with that code's SHA-256; CI redraws it before the docs)."""

import sys
from pathlib import Path

from PIL import Image

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tools"))
import readme_figure  # noqa: E402


def test_the_landing_figure_was_drawn_by_todays_drawing_code():
    tags = Image.open(readme_figure.FIGURE).text
    assert tags.get(readme_figure.TAG) == readme_figure.drawing_hash(), (
        "the diagram's drawing changed since docs/images/stabilisation.png was drawn: run python tools/readme_figure.py"
    )
    assert tags["command"].startswith("armaxmodal stabilise fixtures/supine_random.csv --plot")
