"""A headless look at the built documentation: every page opens in Chromium, shows its title,
and every figure it shows exists; no example printed a traceback, an object's repr, a pandas
table cut short or a wall of NaN, and no Markdown table row was left as raw text (a blank line
inside a table ends it); and no page of the
site, API pages included, shows a cross-reference that did not resolve (the build is nitpicky too;
this catches a page built without it). Run by .ci/run after the build.

Run:  python tools/check_docs_pages.py [docs/_build/html]
"""

from __future__ import annotations

import builtins
import html
import re
import shutil
import subprocess
import sys
from pathlib import Path

PAGES = {
    "index.html": "armaxmodal",
    "install.html": "Install",
    "getting_started.html": "Getting started",
    "user_guide/index.html": "User guide",
    "auto_examples/index.html": "Examples",
    "method.html": "The method",
    "architecture.html": "How the code is laid out",
    "validation/index.html": "Validation",
    "validation/simulated.html": "Validation: simulated systems",
    "validation/real.html": "Validation: measured records",
    "validation/limits.html": "Validation: limits",
    "validation/bridges.html": "Bridges under earthquakes",
    "user_guide/track.html": "Many events of one structure",
    "user_guide/glossary.html": "Glossary",
    "measurement_log.html": "Measurement log",
    "user_guide/warnings.html": "Notes and warning codes",
    "user_guide/cli.html": "Command-line reference",
    "performance.html": "Performance",
    "api.html": "API reference",
    "release_notes.html": "Release notes",
    "changelog.html": "Development notes",
}


def rendered(browser: str, page: Path) -> str:
    """The page's DOM after Chromium has run its scripts."""
    out = subprocess.run(
        [browser, "--headless", "--no-sandbox", "--disable-gpu", "--dump-dom", page.as_uri()],
        capture_output=True, text=True, timeout=120,
    )  # fmt: skip
    if out.returncode != 0 or "<html" not in out.stdout:
        raise SystemExit(f"{page}: Chromium could not render it ({out.stderr.strip()[-300:]})")
    return out.stdout


#: an object's default repr in printed output (a gallery cell ending in a call that returns one)
OBJECT_REPR = re.compile(r"&lt;[\w.]+ object at 0x[0-9a-f]+&gt;")
#: a paragraph that is a Markdown table row: the table ended early at a blank line
RAW_TABLE_ROW = re.compile(r"<p>\s*\|(?:(?!</p>).)*\|\s*</p>", re.S)
#: a pandas table printed truncated: its shape line, a column of "..." between numbers, or a row of them
PANDAS_TRUNCATED = re.compile(
    r"\[\d+ rows x \d+ columns\]|\d\s+\.\.\.\s+-?\d|^\s*\d*\s*\.\.\.(?:\s+\.\.\.){2,}\s*$", re.M
)
#: a printed table row of three or more missing values in a row: a frame mostly NaN
NAN_WALL = re.compile(r"(?:\bNaN\b\s+){2,}\bNaN\b")
PRE = re.compile(r"<pre[^>]*>(.*?)</pre>", re.S)


#: the development's own bookkeeping, which a user page should not show: issue numbers and paths
#: outside the repository (the changelog, a dated development record, may name issues)
INTERNALS = re.compile(r"\bissues? #?\d+|\.\./shared|/work/")


#: the history of the work, which belongs in the development notes: a commit's short hash, a round of work
COMMIT = re.compile(r"\b(?=[0-9a-f]{7,12}\b)(?=[0-9a-f]*[a-f])[0-9a-f]*[0-9][0-9a-f]*\b")
ROUND = re.compile(r"\b(?:sessions?|rounds? of (?:the )?work)\b", re.I)
#: the pages that keep that history (dated notes, the measurement log) and say which version holds what
DEVELOPMENT = {"changelog.html", "measurement_log.html", "release_notes.html"}
#: pages that must show what they measure in at least one figure, within a reader's length
MEASURED = ("validation/simulated.html", "validation/real.html", "validation/limits.html",
            "validation/bridges.html", "performance.html")  # fmt: skip
MAX_LINES = 300
INCLUDE = re.compile(r"^```\{include\}\s+(\S+)", re.M)


def history(dom: str) -> list[str]:
    """Commit hashes and rounds of work in a page's visible text."""
    text = re.sub(r"<(style|script)\b.*?</\1>", " ", dom, flags=re.S)
    text = html.unescape(re.sub(r"<[^>]+>", " ", text))
    shown = sorted(set(COMMIT.findall(text)) | {m.lower() for m in ROUND.findall(text)})
    return [f"shows the history of the work (development notes' matter): {m!r}" for m in shown]


def source_lines(source: Path) -> int:
    """Lines of a page's Markdown source with the files it includes."""
    text = source.read_text()
    return len(text.splitlines()) + sum(
        source_lines((source.parent / name).resolve()) for name in INCLUDE.findall(text) if name.endswith(".md")
    )


def measured_page(site: Path, name: str, dom: str) -> list[str]:
    """A validation or performance page: at least one figure, and under ``MAX_LINES`` lines."""
    found = [] if "<img" in dom else [f"{name}: no figure"]
    source = site.parents[1] / name.replace(".html", ".md")
    if source.is_file() and (n := source_lines(source)) >= MAX_LINES:
        found.append(f"{name}: {n} lines with what it includes (a reader's page: under {MAX_LINES})")
    return found


def internals(dom: str) -> list[str]:
    """Issue numbers and paths outside the repository in a page's text."""
    # MathJax writes its font files' absolute URLs into a <style> block: code, not text a reader sees
    text = re.sub(r"<(style|script)\b.*?</\1>", " ", dom, flags=re.S)
    text = re.sub(r"<[^>]+>", " ", text)
    return [f"shows the project's bookkeeping: {m!r}" for m in sorted(set(INTERNALS.findall(text)))]


def shown_as_text(dom: str) -> list[str]:
    """What a reader sees as debris: object reprs, and table rows left as raw text."""
    found = [f"prints an object's repr: {r}" for r in sorted(set(OBJECT_REPR.findall(dom)))]
    for row in RAW_TABLE_ROW.findall(dom):
        found.append("a table row shown as raw text: " + " ".join(re.sub(r"<[^>]+>", "", row).split())[:80])
    for block in PRE.findall(dom):
        text = html.unescape(re.sub(r"<[^>]+>", "", block))
        if text.lstrip().startswith((">>>", "$")):
            continue  # code the reader types, where "..." is a prompt
        for pattern, what in ((PANDAS_TRUNCATED, "a pandas table printed truncated"), (NAN_WALL, "a wall of NaN")):
            hit = pattern.search(text)
            if hit:
                line = text[text.rfind("\n", 0, hit.start()) + 1 : text.find("\n", hit.end())]
                found.append(f"{what}: {' '.join(line.split())[:80]!r}")
    return found


#: a cross-reference role's text: a link when it resolved, bare code when it did not
XREF = re.compile(r'<code class="xref [^"]*"')
LINK_OPENED = re.compile(r"<a [^>]*>\s*$")


def unresolved_references(html: str) -> list[str]:
    """The text of every cross-reference on a page that is not a link: a name Sphinx could not find.
    Python's builtins (``ValueError``) are not links without intersphinx, which the offline build
    cannot fetch; Sphinx leaves them as code on purpose."""
    found = []
    for m in XREF.finditer(html):
        if not LINK_OPENED.search(html[max(0, m.start() - 400) : m.start()]):
            end = html.find("</code>", m.end())
            name = " ".join(re.sub(r"<[^>]+>", "", html[m.end() : end]).split()).lstrip(">")
            if not hasattr(builtins, name):
                found.append(name)
    return found


def problems(site: Path, browser: str) -> list[str]:
    found = []
    for page in sorted(site.rglob("*.html")):
        names = unresolved_references(page.read_text())
        found += [f"{page.relative_to(site)}: unresolved reference {name!r}" for name in names]
    examples = sorted(p.relative_to(site).as_posix() for p in (site / "auto_examples").glob("plot_*.html"))
    if len(examples) < 6:
        found.append(f"only {len(examples)} gallery examples were built")
    for name in [*PAGES, *examples]:
        page = site / name
        if not page.exists():
            found.append(f"{name}: missing")
            continue
        dom = rendered(browser, page)
        title = re.search(r"<h1[^>]*>(.*?)</h1>", dom, re.S)
        text = re.sub(r"<[^>]+>", "", title.group(1)) if title else ""
        if name in PAGES and PAGES[name].lower() not in text.lower():
            found.append(f"{name}: heading {text.strip()[:60]!r}, expected {PAGES[name]!r}")
        for src in re.findall(r'<img[^>]+src="([^"]+)"', dom):
            if not src.startswith(("http:", "https:", "data:")) and not (page.parent / src).resolve().exists():
                found.append(f"{name}: image {src} not found")
        if "Traceback (most recent call last)" in dom:
            found.append(f"{name}: shows a traceback")
        found += [f"{name}: {problem}" for problem in shown_as_text(dom)]
        if name not in DEVELOPMENT:
            found += [f"{name}: {problem}" for problem in internals(dom) + history(dom)]
        if name in MEASURED:
            found += measured_page(site, name, dom)
        figure = "sphx-glr-single-img" in dom or "sphx-glr-multi-img" in dom
        if name.startswith("auto_examples/plot_") and not figure:
            found.append(f"{name}: no figure")
    return found


def main() -> None:
    site = Path(sys.argv[1] if len(sys.argv) > 1 else "docs/_build/html").resolve()
    browser = shutil.which("chromium") or shutil.which("chromium-browser")
    if browser is None:
        raise SystemExit("chromium is not installed (Debian package 'chromium'); .ci/run installs it")
    found = problems(site, browser)
    for line in found:
        print(line)
    if found:
        raise SystemExit(1)
    print(f"{site}: every page renders, with its title and figures")


if __name__ == "__main__":
    main()
