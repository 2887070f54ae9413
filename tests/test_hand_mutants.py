"""The hand mutants of ``tools/mutation_check.py`` are data about the code as it is: each one's
pattern must be found exactly once in its file, or the mutant tests nothing. A refactor that moves
a pattern fails here, in the suite, not later in a mutation run."""

import importlib.util
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def _mutants():
    spec = importlib.util.spec_from_file_location("mutation_check", ROOT / "tools" / "mutation_check.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module.MUTANTS


def test_every_hand_mutant_finds_its_pattern_once():
    mutants = _mutants()
    assert len(mutants) > 40  # the table was read, not an empty stand-in
    stale = [f"{what} ({path})" for path, old, _, what in mutants
             if not (ROOT / path).is_file() or (ROOT / path).read_text().count(old) != 1]  # fmt: skip
    assert not stale, stale


def test_every_hand_mutant_changes_its_file():
    same = [what for _, old, new, what in _mutants() if old == new]
    assert not same, same
