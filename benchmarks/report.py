"""The performance page's tables, written from the benchmarks' saved results
(``benchmarks/results/*.json``): ``python benchmarks/report.py`` after running the benchmarks,
and the docs build runs it too (``docs/conf.py``). No figure on the page is typed by hand.

    python benchmarks/run.py            # every benchmark below, then this report
    python benchmarks/report.py         # the page again from the saved results
"""

from __future__ import annotations

import json
from pathlib import Path

HERE = Path(__file__).resolve().parent
RESULTS = HERE / "results"
PAGE = HERE.parent / "docs" / "performance_ratios.md"
#: the whole-command benchmarks (scripts: fresh processes, peak memory, clusters), in the
#: page's order, with their commands
SCRIPTS = {
    "ratio": "benchmarks/bench_ratio.py",
    "long": "benchmarks/bench_long.py",
    "study": "benchmarks/bench_study.py",
    "size": "benchmarks/bench_size.py",
}
#: the in-process pairs timed by pytest-benchmark (benchmarks/test_peers.py)
PEERS = "benchmarks/test_peers.py"


def _met(value) -> str:
    return {True: "met", False: "**not met**", None: "—"}[value]


HEADER = ["| what | benchmark | goal | measured | | when |", "|---|---|---|---|---|---|"]


def peer_rows() -> list[str]:
    """One row per pytest-benchmark group: the peer's median time over ours."""
    path = RESULTS / "peers.json"
    if not path.is_file():
        return [f"| (not run) | `{PEERS}` | | no saved result | | |"]
    record = json.loads(path.read_text())
    machine = record["machine_info"]
    when = (f"{record['datetime'][:10]}, {record['commit_info']['id'][:7]}, {machine['cpu'].get('count', '?')} "
            f"cores, {machine['machine']}, Python {machine['python_version']}")  # fmt: skip
    groups: dict[str, dict] = {}
    for bench in record["benchmarks"]:
        groups.setdefault(bench["group"], {})[bench["extra_info"]["role"]] = bench
    rows = []
    for group, pair in groups.items():
        ours, peer = pair["ours"], pair["peer"]
        ratio = peer["stats"]["median"] / ours["stats"]["median"]
        info = ours["extra_info"]
        met = None if info["goal_ratio"] is None else ratio >= info["goal_ratio"]
        measured = (f"{ratio:.1f} ({1e3 * ours['stats']['median']:.1f} ms against "
                    f"{1e3 * peer['stats']['median']:.1f} ms, medians)")  # fmt: skip
        rows.append(f"| {info['what']} | `{PEERS}::{group}` | {info['goal']} | {measured} | {_met(met)} | {when} |")
    return rows


def ratio_table() -> str:
    """The table of ratios measured side by side in one run, one row per saved result."""
    lines = [*HEADER, *peer_rows()]
    for name, command in SCRIPTS.items():
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
