"""The selection system's size in what packing lines cannot change (issue 67, item 4), printed by CI.

The selection system is ``armaxmodal/modes/`` with ``estimate/dft_model.py``, ``_separable.py``,
``spectra.py``, ``stats.py`` and ``modal.py``. Printed, each with the issue's limit:

* **branches**, counted on the AST: ``if``, ``for``, ``while``, ``try``, each extra operand of a
  boolean operator, conditional expressions and comprehensions' loops and conditions;
* **characters** of the source;
* **named thresholds**: numeric fields of the settings classes of ``modes/settings.py`` and of
  ``modes.poles.Tolerances``;
* files ``ruff format --check`` would reformat, and ``# fmt: skip`` markers.

    python tools/selection_shape.py [--strict] [--hold MEASURE ...]

``--strict`` exits 1 when a number is over its limit; ``--hold MEASURE`` when that one is (CI holds
the measures met, so that they stay met: the named thresholds and the formatting).
"""

from __future__ import annotations

import argparse
import ast
import dataclasses
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1] / "armaxmodal"
OTHERS = ("estimate/dft_model.py", "_separable.py", "spectra.py", "stats.py", "modal.py")
LIMITS = {"branches": 560, "characters": 290_000, "named thresholds": 40, "files ruff would reformat": 0}


def selection_files() -> list[Path]:
    return sorted((ROOT / "modes").glob("*.py")) + [ROOT / other for other in OTHERS]


def branches(tree: ast.AST) -> int:
    count = 0
    for node in ast.walk(tree):
        if isinstance(node, ast.If | ast.For | ast.AsyncFor | ast.While | ast.Try | ast.IfExp):
            count += 1
        elif isinstance(node, ast.BoolOp):
            count += len(node.values) - 1
        elif isinstance(node, ast.comprehension):
            count += 1 + len(node.ifs)
    return count


def named_thresholds() -> int:
    sys.path.insert(0, str(ROOT.parent))
    from armaxmodal.modes import settings
    from armaxmodal.modes.poles import Tolerances

    # the classes, not their instances (``SWEEP = SweepSettings()`` counted the sweep's five twice),
    # and the diagram's stability and rejection rules (``Tolerances``, which the issue counts too)
    classes = [c for c in vars(settings).values() if isinstance(c, type) and dataclasses.is_dataclass(c)]
    classes = [c for c in classes if c.__module__ == settings.__name__] + [Tolerances]
    return sum(1 for c in classes for f in dataclasses.fields(c)
               if isinstance(f.default, int | float) and not isinstance(f.default, bool))  # fmt: skip


def fixed_numbers() -> int:
    """Numbers ``modes/settings.py`` holds outside the settings classes (module constants and the
    fields of instances of classes without defaults: the H1's resolutions): not overridable, so
    not thresholds by the issue's measure, but printed beside them."""
    from armaxmodal.modes import settings

    count = 0
    for name, value in vars(settings).items():
        if name.isupper() and isinstance(value, int | float) and not isinstance(value, bool):
            count += 1
        elif dataclasses.is_dataclass(value) and not isinstance(value, type):
            defaults = [f for f in dataclasses.fields(value) if f.default is not dataclasses.MISSING]
            numbers = [getattr(value, f.name) for f in dataclasses.fields(value)]
            count += 0 if defaults else sum(isinstance(n, int | float) and not isinstance(n, bool) for n in numbers)
    return count


def reformatted(files: list[Path]) -> int:
    done = subprocess.run([sys.executable, "-m", "ruff", "format", "--check", "--output-format", "concise",
                           *map(str, files)], capture_output=True, text=True)  # fmt: skip
    return len({line.split(":")[0] for line in done.stdout.splitlines() if "File would be reformatted" in line})


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--strict", action="store_true", help="exit 1 when a number is over its limit")
    held = "exit 1 when this measure is over its limit (CI holds the ones met); repeatable"
    parser.add_argument("--hold", action="append", default=[], choices=list(LIMITS), metavar="MEASURE", help=held)
    args = parser.parse_args()
    files = selection_files()
    texts = [path.read_text() for path in files]
    shape = {
        "branches": sum(branches(ast.parse(text)) for text in texts),
        "characters": sum(len(text) for text in texts),
        "named thresholds": named_thresholds(),
        "files ruff would reformat": reformatted(files),
    }
    skips = sum(text.count("# fmt: skip") for text in texts)
    over = False
    print(f"selection system: {len(files)} files")
    for name, value in shape.items():
        verdict = "within" if value <= LIMITS[name] else "OVER"
        over |= value > LIMITS[name] and (args.strict or name in args.hold)
        print(f"  {name}: {value:,} ({verdict} the limit {LIMITS[name]:,}{', held' if name in args.hold else ''})")
    print(f"  '# fmt: skip' markers: {skips}")
    print(f"  fixed numbers beside the thresholds in modes/settings.py: {fixed_numbers()}")
    return int(over)


if __name__ == "__main__":
    raise SystemExit(main())
