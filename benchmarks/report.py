"""The performance page's tables, written from the benchmarks' saved results
(``benchmarks/results/*.json``): ``python benchmarks/report.py`` after running the benchmarks,
and the docs build runs it too (``docs/conf.py``). No figure on the page is typed by hand.

    python benchmarks/bench_ratio.py && python benchmarks/bench_pem.py --quick \\
        && python benchmarks/bench_long.py && python benchmarks/bench_study.py
    python benchmarks/report.py
"""

from __future__ import annotations

import json
from pathlib import Path

HERE = Path(__file__).resolve().parent
RESULTS = HERE / "results"
PAGE = HERE.parent / "docs" / "performance_ratios.md"
#: the benchmarks whose rows make the page's first table, in its order, with their commands
RATIOS = {
    "ratio": "benchmarks/bench_ratio.py",
    "pem": "benchmarks/bench_pem.py --quick",
    "long": "benchmarks/bench_long.py",
    "study": "benchmarks/bench_study.py",
}


def _met(value) -> str:
    return {True: "met", False: "**not met**", None: "—"}[value]


def ratio_table() -> str:
    """The table of ratios measured side by side in one run, one row per saved result."""
    lines = ["| what | benchmark | goal | measured | | when |", "|---|---|---|---|---|---|"]
    for name, command in RATIOS.items():
        path = RESULTS / f"{name}.json"
        if not path.is_file():
            lines.append(f"| (not run) | `{command}` | | no saved result | | |")
            continue
        record = json.loads(path.read_text())
        for row in record["rows"]:
            when = f"{record['date']}, {record['commit']}, {record['machine']}"
            lines.append(f"| {row['what']} | `{command}` | {row['goal']} | {row['measured']} | {_met(row['met'])} "
                         f"| {when} |")  # fmt: skip
    return "\n".join(lines) + "\n"


def write() -> Path:
    """Write the generated part of the performance page (only when it changed)."""
    text = ("<!-- written by benchmarks/report.py from benchmarks/results/*.json; do not edit -->\n\n"
            + ratio_table())  # fmt: skip
    if not PAGE.is_file() or PAGE.read_text() != text:
        PAGE.write_text(text)
    return PAGE


if __name__ == "__main__":
    print(write())
