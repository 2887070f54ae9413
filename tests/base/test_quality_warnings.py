"""The warning codes: every code the source raises is defined, every definition is raised, and
each says what was measured, what is done and what to do (the docs' page is built from them)."""

import re
from pathlib import Path

import pytest

from armaxmodal.quality_warnings import CODES, UNCERTAIN_CODES, WARNING_CODES, QualityWarning

SOURCE = Path(__file__).resolve().parents[2] / "armaxmodal"


def _raised() -> set[str]:
    """The codes the package's source passes to QualityWarning (or to not_run)."""
    text = "\n".join(p.read_text() for p in SOURCE.rglob("*.py"))
    found = set(re.findall(r'QualityWarning\(\s*"([a-z_]+)"', text))
    if "not_run(" in text:
        found.add("check_not_run")
    return found


def test_every_raised_code_is_defined_and_every_defined_code_is_raised():
    assert _raised() == set(WARNING_CODES)


def test_each_definition_is_complete_and_the_codes_are_unique():
    assert len(set(WARNING_CODES)) == len(WARNING_CODES) == len(CODES)
    for c in CODES:
        assert c.stage and len(c.measured) > 20 and c.done and c.advice.endswith("."), c.code
    assert set(UNCERTAIN_CODES) == {"count_undecided", "modes_not_separated", "pick_not_supported", "drift",
                                    "periodic_disturbance", "stuck_samples", "held_samples",
                                    "dropped_packet", "undriven_resonance"}  # fmt: skip


def test_an_unknown_code_is_refused():
    with pytest.raises(ValueError, match="unknown warning code"):
        QualityWarning("made_up", (), "x")
