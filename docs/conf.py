"""Sphinx configuration of the armaxmodal documentation.

Built by ``.ci/run`` with warnings as errors and no network: no intersphinx inventories are
fetched; the gallery's figures are made when the docs build (sphinx-gallery).
"""

from __future__ import annotations

import os
import re
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
os.environ.setdefault("MPLBACKEND", "Agg")  # the gallery draws without a display

from armaxmodal import __version__  # noqa: E402
from armaxmodal.quality_warnings import CODES, severity  # noqa: E402


def _warning_page() -> str:
    """The warning codes' page, written from their own definitions
    (:data:`armaxmodal.quality_warnings.CODES`) so that it cannot go stale."""
    lines = [
        "# Notes and warning codes",
        "",
        "Every note the product raises, as `armaxmodal.quality_warnings.CODES` defines it (this page is",
        "generated from those definitions when the docs build). A note travels with its result: the JSON's",
        "`warnings` list (code, channels, message, value, and `freq_hz`: the frequencies it is about), the",
        "report's notes and, on stderr even with `--quiet`, per code after the verdict its channels,",
        "frequencies and finding, and for a warning or a problem what to do (every full text with",
        "`--verbose`). Each code has a",
        "severity that says how it moves the verdict: **problem** (the verdict is poor), **warning** (the",
        "verdict is uncertain, or the data hold a fault to act on) or **info** (said, and dealt with). Codes",
        'marked **uncertain** make a selection that passes its check say `"quality": "uncertain"`.',
        "",
    ]
    for c in CODES:
        flag = " (**uncertain**)" if c.uncertain else ""
        lines += [f"## `{c.code}`", "", f"*Raised by:* {c.stage}{flag}; *severity:* {severity(c.code)}", "",
                  f"**Measured:** {c.measured}", "", f"**What is done:** {c.done}", "", f"**What to do:** {c.advice}",
                  ""]  # fmt: skip
    return "\n".join(lines)


# the performance page's ratios, from the benchmarks' saved results (benchmarks/report.py)
sys.path.insert(0, str(ROOT / "benchmarks"))
import report as _benchmark_report  # noqa: E402

_benchmark_report.write()

# the bridges' validation page and its figures, from the saved track results (scripts/track_bridges.py)
sys.path.insert(0, str(ROOT / "scripts"))
import track_bridges as _track_bridges  # noqa: E402

_track_bridges.write_page()

# the validation pages' tables and figures, from the saved results of their scripts
sys.path.insert(0, str(ROOT / "tools"))
import validation_pages as _validation_pages  # noqa: E402

_validation_pages.write()

def _glossary_page() -> str:
    """The glossary, written from the terms the reports print (:data:`armaxmodal.io.report.glossary.TERMS`)."""
    from armaxmodal.io.report.glossary import TERMS

    lines = ["# Glossary", "", "The terms the command line, the JSON and the reports use (each report ends with",
             "this list; this page is generated from the same definitions when the docs build).", ""]  # fmt: skip
    for term, text in TERMS.items():
        lines += [f"**{term}**", f": {text}", ""]
    return "\n".join(lines)


_glossary = Path(__file__).parent / "user_guide" / "glossary.md"
if not _glossary.exists() or _glossary.read_text() != _glossary_page():
    _glossary.write_text(_glossary_page())

_page = Path(__file__).parent / "user_guide" / "warnings.md"
if not _page.exists() or _page.read_text() != _warning_page():
    _page.write_text(_warning_page())

project = "armaxmodal"
author = "the armaxmodal developers"
copyright = "2026, the armaxmodal developers"
version = release = __version__

extensions = [
    "sphinx.ext.autodoc",
    "sphinx.ext.autosummary",
    "sphinx.ext.mathjax",
    "numpydoc",
    "myst_parser",
    "sphinx_gallery.gen_gallery",
    "sphinxarg.ext",
    "sphinx_copybutton",
    # MathJax 3 served with the pages (no CDN): an offline reader sees the method's equations
    "sphinx-mathjax-offline",
]
source_suffix = {".rst": "restructuredtext", ".md": "markdown"}
templates_path = ["_templates"]
exclude_patterns = ["_build", "examples", "generated_results/*.md", "auto_examples/*.ipynb", "auto_examples/*.py",
                    "auto_examples/*.zip"]
myst_heading_anchors = 3
# $...$ and $$...$$ for the method page's equations (rendered by MathJax)
myst_enable_extensions = ["dollarmath", "deflist"]
suppress_warnings = ["myst.header"]

autosummary_generate = True
autodoc_default_options: dict = {}  # members only on class pages (docs/_templates): no object twice
autodoc_typehints = "none"  # numpydoc's Parameters sections say the types
numpydoc_show_class_members = False
numpydoc_class_members_toctree = False
# the types in Parameters and Returns link to their pages: every class the API reference
# documents, by its short name; other words (ndarray, DataFrame, shapes) stay text, since the
# offline build has no inventory to link them to
numpydoc_xref_param_type = True
numpydoc_xref_ignore = "all"
from numpydoc.xref import DEFAULT_LINKS  # noqa: E402

numpydoc_xref_aliases = {word: word for word in DEFAULT_LINKS}  # numpydoc's links need inventories
numpydoc_xref_aliases |= {
    name.rsplit(".", 1)[-1]: name
    for name in re.findall(r"^ {3}(armaxmodal\.[\w.]+)$", (Path(__file__).parent / "api.rst").read_text(), re.M)
    if name.rsplit(".", 1)[-1][:1].isupper()
}
# every cross-reference must resolve (the build runs with -W): a renamed function breaks the build,
# not a link
nitpicky = True

sphinx_gallery_conf = {
    "examples_dirs": "examples",
    "gallery_dirs": "auto_examples",
    "filename_pattern": r"/plot_",
    "download_all_examples": False,
    "remove_config_comments": True,
    "plot_gallery": "True",
    "abort_on_example_error": True,
    "within_subsection_order": "FileNameSortKey",
    "show_memory": False,
    "reference_url": {"armaxmodal": None},
}

html_theme = "pydata_sphinx_theme"
html_title = f"armaxmodal {version}"
html_theme_options = {
    "navigation_with_keys": False,
    "show_toc_level": 2,
    "use_edit_page_button": False,
    # the reader's pages in the top bar, the API reference among them; the rest under "More"
    "header_links_before_dropdown": 6,
}
# pages without sub-pages have no section navigation: no empty left column beside them
html_sidebars = {page: [] for page in ("index", "install", "getting_started", "method", "architecture",
                                       "performance", "performance_ratios", "api", "modules", "release_notes",
                                       "changelog")}  # fmt: skip
html_static_path = ["_static"]
html_css_files = ["wrap.css"]  # long code lines wrap instead of running out of their box
copybutton_prompt_text = r"\$ |>>> |\.\.\. "
copybutton_prompt_is_regexp = True
