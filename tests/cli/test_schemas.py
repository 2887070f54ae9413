"""Every command's JSON validates against the schema published in ``schemas/`` (strict JSON:
a bare NaN fails to parse before the schema is even applied)."""

import json
from pathlib import Path

import pytest
from jsonschema import Draft202012Validator
from referencing import Registry, Resource

from armaxmodal.cli import main

SCHEMAS = Path(__file__).resolve().parents[2] / "schemas"


def _validator(name: str) -> Draft202012Validator:
    resources = []
    for path in SCHEMAS.glob("*.schema.json"):
        schema = json.loads(path.read_text())
        resources.append((schema["$id"], Resource.from_contents(schema)))
        resources.append((path.name, Resource.from_contents(schema)))
    schema = json.loads((SCHEMAS / f"{name}.schema.json").read_text())
    return Draft202012Validator(schema, registry=Registry().with_resources(resources))


def _strict(path: Path) -> dict:
    return json.loads(path.read_text(), parse_constant=lambda c: pytest.fail(f"bare {c} in {path.name}"))


@pytest.mark.parametrize(
    ("command", "extra"),
    [
        ("stabilise", ["--orders", "2:16"]),
        ("identify", ["--model", "10,16,10,-5"]),
        ("diagnose", ["--max-rounds", "1"]),
    ],
)
def test_command_json_matches_its_schema(tmp_path, fixtures_dir, command, extra):
    out = tmp_path / "out.json"
    assert main([command, str(fixtures_dir / "supine_random.csv"), *extra, "--json", str(out), "--quiet"]) == 0
    errors = sorted(_validator(command).iter_errors(_strict(out)), key=str)
    assert not errors, "\n".join(e.message for e in errors[:5])


def test_the_schema_rejects_a_broken_output():
    """The schemas can fail: a mode without a frequency, an effect outside the vocabulary."""
    bad_mode = {"freq_ci95": [1, 2], "damping_ci95": [0, 1], "damping": 0.1, "shape": {}}
    assert list(_validator("identify").iter_errors({"modes": [bad_mode]}))
    assert list(_validator("diagnose").iter_errors({"effects": [{"effect": "gremlins"}]}))
    assert list(_validator("track").iter_errors({"events": [{"quality": "great"}]}))
