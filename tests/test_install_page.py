"""The install page says what exists: every extra of ``pyproject.toml`` with every package it adds,
and no placeholder for a repository that has no public address."""

import re
import tomllib
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
PAGE = (ROOT / "docs" / "install.md").read_text()


def _name(requirement: str) -> str:
    return re.split(r"[<>=!~\[ ;]", requirement, maxsplit=1)[0].lower()


def test_every_extra_lists_every_package_it_adds():
    extras = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]["optional-dependencies"]
    rows = {m.group(1): m.group(2).lower() for m in re.finditer(r"^\| `(\w+)` \| ([^|]+) \|", PAGE, re.M)}
    assert set(rows) == set(extras)
    for extra, requirements in extras.items():
        listed = {name.strip().split(" (")[0] for name in rows[extra].split(",")}
        assert {_name(r) for r in requirements} <= listed, (extra, listed)


def test_no_placeholder_and_no_clone_of_an_address_that_does_not_exist():
    assert "<the repository>" not in PAGE and "git clone" not in PAGE
    assert "pip install -q ." in PAGE and "python3 -m build --wheel" in PAGE
