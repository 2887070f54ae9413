"""Every top-level public function and class has a numpydoc ``Examples`` section, and each runs as
a doctest and prints what it says (the values are rounded or compared within a tolerance, so
no example depends on the last digit of a LAPACK result)."""

import doctest
import importlib
import inspect
import re
from pathlib import Path

import pytest

import armaxmodal as am

FUNCTIONS = [name for name in am.__all__ if inspect.isfunction(getattr(am, name))]
CLASSES = [name for name in am.__all__ if inspect.isclass(getattr(am, name))]
API = Path(__file__).resolve().parents[1] / "docs" / "api.rst"


def _api_object(path: str):
    module, _, attr = path.rpartition(".")
    return getattr(importlib.import_module(module), attr)


TOP_LEVEL = {id(getattr(am, name)) for name in am.__all__}
#: the API reference's functions and classes beyond the top level whose docstrings carry examples
DOCUMENTED = [
    path for path in re.findall(r"^ {3}(armaxmodal\.[\w.]+\.[\w]+)$", API.read_text(), re.M)
    if not inspect.ismodule(obj := _api_object(path)) and id(obj) not in TOP_LEVEL
    and "Examples\n" in (inspect.getdoc(obj) or "")
]


def test_every_top_level_function_and_class_has_examples():
    missing = [name for name in FUNCTIONS + CLASSES if "Examples\n" not in (inspect.getdoc(getattr(am, name)) or "")]
    assert not missing


def test_the_api_reference_beyond_the_top_level_has_examples_to_run():
    assert len(DOCUMENTED) >= 5  # the list was read from the reference, not left empty


@pytest.mark.parametrize("name", FUNCTIONS + CLASSES + DOCUMENTED)
def test_the_examples_run(name):
    obj = getattr(am, name) if "." not in name else _api_object(name)
    (test,) = doctest.DocTestFinder(recurse=False).find(obj, name, globs={})
    assert test.examples, f"{name}: no example"
    runner = doctest.DocTestRunner(optionflags=doctest.NORMALIZE_WHITESPACE)
    result = runner.run(test, out=lambda text: print(text, end=""))
    assert result.failed == 0, f"{name}: {result.failed} of {result.attempted} examples failed (see the output)"


def test_every_function_and_class_of_the_api_reference_points_to_its_relatives():
    """A See Also on each: what makes an object, what takes it, what runs beside it."""
    listed = re.findall(r"^ {3}(armaxmodal\.[\w.]+)$", API.read_text(), re.M)
    objects = [(path, obj) for path in listed if not inspect.ismodule(obj := _api_object(path))]
    assert len(objects) > 90
    missing = [path for path, obj in objects if "See Also\n" not in (inspect.getdoc(obj) or "")]
    assert not missing
