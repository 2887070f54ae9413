"""Every code block of the user guide and of getting started runs as a reader would run it, and
what it prints is what the page says it prints.

Each page runs in a fresh folder holding the bundled rides (``fixtures/``), the tools
(``tools/``) and this environment (``.venv``): its Python blocks in one namespace, in order, its
``bash`` blocks in bash with this environment's commands first on the path. A ``text`` block the
page marks with the comment line ``% output of the command above`` is the output of the block
before it: compared line by line, whitespace runs as one space, ``...`` standing for the rest of a
line or for lines left out, and each number within two units of its last printed digit (or 0.2 %),
so that no page depends on the last digit of a LAPACK result. The install block (``python3 -m
venv ...``) is the CI's own first line and is not run again here.
"""

from __future__ import annotations

import contextlib
import io
import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
DOCS = ROOT / "docs"
#: pages written at build time from the code's own definitions (no code blocks), and the
#: command-line reference (a directive, not a block)
GENERATED = {"warnings.md", "glossary.md", "cli.md"}
PAGES = [DOCS / "getting_started.md"] + sorted(
    p for p in (DOCS / "user_guide").glob("*.md") if p.name not in GENERATED
)
BLOCK = re.compile(r"^(% output[^\n]*\n)?```(\w+)\n(.*?)^```$", re.M | re.S)
NUMBER = re.compile(r"[-+]?\d+(?:\.\d+)?(?:[eE][-+]?\d+)?")
INSTALL = "python3 -m venv"


def blocks(page: Path) -> list[tuple[str, str, str | None]]:
    """``(language, code, expected output or None)`` for each python and bash block."""
    found: list[tuple[str, str, str | None]] = []
    for match in BLOCK.finditer(page.read_text()):
        marked, language, code = match.groups()
        if marked and language == "text":
            assert found and found[-1][2] is None, f"{page.name}: an output block follows no code block"
            found[-1] = (found[-1][0], found[-1][1], code)
        elif language in ("python", "bash"):
            found.append((language, code, None))
    return found


def same_output(expected: str, got: str) -> bool:
    """The printed text matches the page's: see the module's rules.

    Examples
    --------
    >>> same_output("f 5.831 Hz ...", "f  5.832 Hz, damping 0.2576")
    True
    >>> same_output("f 5.831 Hz", "f 5.840 Hz")
    False
    """
    pattern, numbers = [], []
    for piece in re.split(r"(\.\.\.|" + NUMBER.pattern + ")", " ".join(expected.split())):
        if piece == "...":
            pattern.append(".*?")
        elif piece and NUMBER.fullmatch(piece):
            pattern.append(f"({NUMBER.pattern})")
            numbers.append(piece)
        else:
            pattern.append(re.escape(piece))
    match = re.fullmatch("".join(pattern), " ".join(got.split()), re.S)
    if match is None:
        return False
    for text, value in zip(numbers, match.groups(), strict=True):
        digits = len(text.split(".")[1]) if "." in text and "e" not in text.lower() else 0
        if abs(float(value) - float(text)) > max(2 * 10.0**-digits, 2e-3 * abs(float(text))):
            return False
    return True


def _folder(tmp_path: Path) -> Path:
    for name in ("fixtures", "tools"):
        (tmp_path / name).symlink_to(ROOT / name)
    (tmp_path / ".venv").symlink_to(Path(sys.executable).parents[1])
    return tmp_path


def _bash(code: str, folder: Path) -> str:
    env = {**os.environ, "PATH": f"{Path(sys.executable).parent}{os.pathsep}{os.environ['PATH']}",
           "MPLBACKEND": "Agg"}  # fmt: skip
    run = subprocess.run(["bash", "-euo", "pipefail", "-c", code], cwd=folder, env=env, capture_output=True,
                         text=True, timeout=900)  # fmt: skip
    assert run.returncode == 0, f"{code}\n{run.stderr[-3000:]}"
    return run.stdout


@pytest.mark.parametrize("page", PAGES, ids=lambda p: p.name)
def test_every_block_of_the_page_runs_and_prints_what_the_page_says(page, tmp_path, monkeypatch):
    folder = _folder(tmp_path)
    monkeypatch.chdir(folder)
    monkeypatch.setenv("MPLBACKEND", "Agg")
    namespace: dict = {}
    for language, code, expected in blocks(page):
        if code.startswith(INSTALL):
            continue
        if language == "bash":
            printed = _bash(code, folder)
        else:
            with contextlib.redirect_stdout(io.StringIO()) as out:
                exec(compile(code, f"{page.name} block", "exec"), namespace)  # noqa: S102 - the page's own code
            printed = out.getvalue()
        if expected is not None:
            assert same_output(expected, printed), f"{page.name}: expected\n{expected}\ngot\n{printed}"


def test_the_pages_hold_blocks_and_outputs_to_check():
    """The harness reads what it should: the pages' blocks and their marked outputs."""
    counted = {page.name: blocks(page) for page in PAGES}
    assert sum(len(b) for b in counted.values()) >= 12
    assert sum(expected is not None for b in counted.values() for _, _, expected in b) >= 3
    assert same_output("a 1.00 b ...", "a 1.01 b c d") and not same_output("a 1.00 b", "a 1.03 b")
