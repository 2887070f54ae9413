"""The docs page checker (tools/check_docs_pages.py) on hand-written HTML: what it must catch and
what it must leave alone. The checker itself runs on the built site in .ci/run."""

import importlib.util
from pathlib import Path

_spec = importlib.util.spec_from_file_location(
    "check_docs_pages", Path(__file__).resolve().parents[1] / "tools" / "check_docs_pages.py"
)
checker = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(checker)

LINKED = (
    '<a class="reference internal" href="generated/armaxmodal.fit_armax.html" title="armaxmodal.fit_armax">'
    '<code class="xref py py-func docutils literal notranslate"><span class="pre">fit_armax()</span></code></a>'
)
BARE = '<code class="xref py py-func docutils literal notranslate"><span class="pre">fit_armx()</span></code>'


def test_a_reference_that_did_not_resolve_is_named():
    assert checker.unresolved_references(f"<p>see {LINKED} and {BARE}</p>") == ["fit_armx()"]


def test_linked_references_and_builtins_pass():
    builtin = '<code class="xref py py-class docutils literal notranslate"><span class="pre">ValueError</span></code>'
    assert checker.unresolved_references(f"<p>{LINKED}, raises {builtin}</p>") == []


def test_raw_table_rows_and_object_reprs_are_named():
    dom = (
        "<p>| a | b |</p><pre>&lt;matplotlib.legend.Legend object at 0x7f00ab&gt;</pre>"
        "<table><tr><td>ok</td></tr></table>"
    )
    found = checker.shown_as_text(dom)
    assert found == [
        "prints an object's repr: &lt;matplotlib.legend.Legend object at 0x7f00ab&gt;",
        "a table row shown as raw text: | a | b |",
    ]


def test_every_module_has_its_page():
    """docs/modules.rst names each module of the package once, so a new or moved module is
    documented (the CLI's modules and private ones excepted)."""
    root = Path(__file__).resolve().parents[1]
    modules = {
        ".".join(path.relative_to(root).with_suffix("").parts)
        for path in (root / "armaxmodal").rglob("*.py")
        if path.name != "__init__.py"
        and not any(part.startswith("_") for part in path.relative_to(root).parts)
        and "cli" not in path.relative_to(root).parts
    }
    lines = (root / "docs" / "modules.rst").read_text().splitlines()
    listed = [line.strip() for line in lines if line.startswith("   armaxmodal.")]  # the autosummary entries
    assert sorted(listed) == sorted(modules)


def test_issue_numbers_and_outside_paths_are_named():
    assert checker.internals("<p>fixed (issue 29), data in <code>../shared/realdata</code></p>") == [
        "shows the project's bookkeeping: '../shared'",
        "shows the project's bookkeeping: 'issue 29'",
    ]
    assert checker.internals("<p>an issue of damping; 29 modes</p>") == []
