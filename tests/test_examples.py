"""Every top-level public function and class has a numpydoc ``Examples`` section, and each runs as
a doctest and prints what it says (the values are rounded or compared within a tolerance, so
no example depends on the last digit of a LAPACK result)."""

import doctest
import inspect

import pytest

import armaxmodal as am

FUNCTIONS = [name for name in am.__all__ if inspect.isfunction(getattr(am, name))]
CLASSES = [name for name in am.__all__ if inspect.isclass(getattr(am, name))]


def test_every_top_level_function_and_class_has_examples():
    missing = [name for name in FUNCTIONS + CLASSES if "Examples\n" not in (inspect.getdoc(getattr(am, name)) or "")]
    assert not missing


@pytest.mark.parametrize("name", FUNCTIONS + CLASSES)
def test_the_examples_run(name):
    (test,) = doctest.DocTestFinder(recurse=False).find(getattr(am, name), name, globs={})
    assert test.examples, f"{name}: no example"
    runner = doctest.DocTestRunner(optionflags=doctest.NORMALIZE_WHITESPACE)
    result = runner.run(test, out=lambda text: print(text, end=""))
    assert result.failed == 0, f"{name}: {result.failed} of {result.attempted} examples failed (see the output)"
