"""Every public function and method on the API page documents each parameter, and what it
returns (numpydoc's PR01, PR02 and RT01 checks). Properties and functions that return None need
no Returns section."""

import importlib
import inspect
import re
from pathlib import Path

import pytest
from numpydoc import validate  # a test dependency: the check must run, not skip

API_PAGE = Path(__file__).resolve().parents[1] / "docs" / "api.rst"


def _object(name: str):
    parts = name.split(".")
    for k in range(len(parts), 0, -1):
        try:
            obj = importlib.import_module(".".join(parts[:k]))
        except ImportError:
            continue
        for attribute in parts[k:]:
            obj = getattr(obj, attribute)
        return obj
    raise ImportError(name)


def _documented() -> list[str]:
    """The API page's functions, and the public methods of its classes."""
    names = []
    for name in re.findall(r"^   (armaxmodal\.[\w.]+)$", API_PAGE.read_text(), re.M):
        obj = _object(name)
        if inspect.isfunction(obj):
            names.append(name)
        elif inspect.isclass(obj) and not issubclass(obj, BaseException):
            for attribute, member in vars(obj).items():
                if not attribute.startswith("_") and inspect.isfunction(member):
                    names.append(f"{name}.{attribute}")
    return names


def _returns_nothing(name: str) -> bool:
    return inspect.signature(_object(name)).return_annotation in (None, "None")


@pytest.mark.parametrize("name", _documented())
def test_parameters_and_returns_are_documented(name):
    errors = validate.validate(name)["errors"]
    found = [f"{code}: {message}" for code, message in errors if code in ("PR01", "PR02")]
    if not _returns_nothing(name):
        found += [f"{code}: {message}" for code, message in errors if code == "RT01"]
    assert not found, f"{name}: " + "; ".join(found)


@pytest.mark.parametrize("name", _documented())
def test_every_returned_and_parameter_type_is_a_type(name):
    """A sentence left after the last section reads as one more entry, its text as the type: a
    type never ends a sentence."""
    from numpydoc.docscrape import FunctionDoc

    doc = FunctionDoc(_object(name))
    entries = [*doc["Parameters"], *doc["Returns"]]
    sentences = [f"{entry.name} : {entry.type}".strip(" :") for entry in entries
                 if (entry.type or entry.name).rstrip().endswith(".")]  # fmt: skip
    assert not sentences, f"{name}: " + "; ".join(sentences)
