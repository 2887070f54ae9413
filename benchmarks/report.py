"""The performance page's tables, written from the benchmarks' saved results
(``benchmarks/results/*.json``): ``python benchmarks/report.py`` after running the benchmarks,
and the docs build runs it too (``docs/conf.py``). No figure on the page is typed by hand.

    python benchmarks/run.py            # every benchmark below, then this report
    python benchmarks/report.py         # the page again from the saved results
"""

from __future__ import annotations

import json
import re
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


HEADER = ["| # | what | target | measured | |", "|---|---|---|---|---|"]


def peer_rows() -> list[str]:
    """One row per pytest-benchmark group: the peer's median time over ours."""
    path = RESULTS / "peers.json"
    if not path.is_file():
        return [(f"(not run) | | no saved result (`{PEERS}`) | |", "")]
    record = json.loads(path.read_text())
    machine = record["machine_info"]
    when = (f"{record['datetime'][:10]}, {machine['cpu'].get('count', '?')} "
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
        rows.append((f"{info['what']} | {info['goal']} | {measured} | {_met(met)} |", f"`{PEERS}::{group}`, {when}"))
    return rows


def ratio_table() -> str:
    """The table of ratios measured side by side in one run, one row per saved result, then where and
    when each row was measured (a list: a column of dates squeezed the table)."""
    rows = peer_rows()
    for name, command in SCRIPTS.items():
        path = RESULTS / f"{name}.json"
        if not path.is_file():
            rows.append((f"(not run) | | no saved result (`{command}`) | |", ""))
            continue
        record = json.loads(path.read_text())
        for row in record["rows"]:
            when = f"`{command}`, {record['date']}, {record['machine']}"
            rows.append((f"{row['what']} | {row['goal']} | {row['measured']} | {_met(row['met'])} |", when))
    table = [*HEADER, *(f"| {k} | {cells}" for k, (cells, _) in enumerate(rows, 1))]
    measured_on = [f"{k}. {when}" for k, (_, when) in enumerate(rows, 1) if when]
    return "\n".join(table) + "\n\nMeasured by, on:\n\n" + "\n".join(measured_on) + "\n"


def _number(pattern: str, text: str, what: str) -> str:
    """The first group of ``pattern`` in a saved result's text; a format the page cannot read stops the build."""
    found = re.search(pattern, text)
    if found is None:
        raise ValueError(f"benchmarks/report.py cannot read {what} from {text!r}: update the page's reader")
    return found.group(1)


def expectations() -> str:
    """What a user can expect, in plain figures, from the saved results (a bullet per benchmark run)."""
    items = []
    peers = RESULTS / "peers.json"
    if peers.is_file():
        record = json.loads(peers.read_text())
        medians = {(b["group"], b["extra_info"]["role"]): b["stats"]["median"] for b in record["benchmarks"]}
        if ("pem-fit", "ours") in medians:
            ours, peer = medians["pem-fit", "ours"], medians["pem-fit", "peer"]
            items.append(f"One prediction-error fit of one sensor (7,200 samples, na 8) takes {1e3 * ours:.1f} ms; a "
                         f"scipy Levenberg-Marquardt PEM of the same model from the same start takes {1e3 * peer:.1f} "
                         f"ms, {peer / ours:.1f} times as long.")  # fmt: skip
    size = RESULTS / "size.json"
    if size.is_file():
        rows = json.loads(size.read_text())["rows"]
        first = _number(r"over ([\d,]+) x", rows[0]["what"], "the shortest record")
        sizes = [_number(r"at ([\d,]+) x", r["what"], "a record size") for r in rows]
        times = [f"{n} x 5 in {r['values'][0]:.1f} s" for n, r in zip(sizes, rows, strict=True)]
        items.append(f"`armaxmodal stabilise` on a five-mass chain at 100 Hz, wall time with both cores: {first} x 5 "
                     f"samples in {rows[0]['values'][1]:.1f} s, " + ", ".join(times) + ".")  # fmt: skip
    long = RESULTS / "long.json"
    if long.is_file():
        rows = json.loads(long.read_text())["rows"]
        n = _number(r"a ([\d,]+) x 4 ride", rows[0]["what"], "the long ride's length")
        seconds = _number(r"\(([\d.]+) s against", rows[0]["measured"], "the long ride's time")
        memory = _number(r"\(([\d,.]+ [MG]B)", rows[1]["measured"], "the long ride's peak memory")
        items.append(f"A one-hour supine ride ({n} x 4 samples at 120 Hz): {seconds} s and {memory} of memory at "
                     "its peak.")  # fmt: skip
    study = RESULTS / "study.json"
    if study.is_file():
        runs = json.loads(study.read_text())["rows"][0]["values"]
        said = ", ".join(f"{r['wall_s']:.0f} s {r['run']}" for r in runs)
        items.append(f"A study of {runs[0]['recordings']} synthetic recordings: {said}.")
    return "\n".join(f"- {item}" for item in items) + "\n"


GOAL = re.compile(r"(<=|>=)\s*([\d.]+)")
FIGURE = HERE.parent / "docs" / "generated_results" / "performance.png"


def ratios_figure() -> Path:
    """Each saved ratio against its target, as the share of the target it uses (at most 1 meets it)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    labels, shares = [], []
    for name in SCRIPTS:
        path = RESULTS / f"{name}.json"
        for row in json.loads(path.read_text())["rows"] if path.is_file() else []:
            goal = GOAL.search(row["goal"])
            measured = re.search(r"median ([\d.]+)", row["measured"]) or re.match(r"([\d.]+)", row["measured"])
            if goal is None or measured is None:
                continue
            value, target = float(measured.group(1)), float(goal.group(2))
            shares.append(value / target if goal.group(1) == "<=" else target / value)
            labels.append(row["what"][:60] + ("..." if len(row["what"]) > 60 else ""))
    fig, ax = plt.subplots(figsize=(8, 0.5 + 0.45 * len(shares)))
    ax.barh(range(len(shares)), shares, color=["#2a7" if s <= 1 else "#c22" for s in shares])
    ax.axvline(1, color="k", lw=1)
    ax.set_yticks(range(len(shares)), labels, fontsize=8)
    ax.set_xlabel("share of the target used (at most 1: met)")
    fig.tight_layout()
    FIGURE.parent.mkdir(exist_ok=True)
    fig.savefig(FIGURE, dpi=90)
    plt.close(fig)
    return FIGURE


def write() -> Path:
    """Write the generated part of the performance page (only when it changed), and its figure."""
    ratios_figure()
    intro = "On this project's 2-core machine (each figure from the last run of its benchmark):"
    text = ("<!-- written by benchmarks/report.py from benchmarks/results/*.json; do not edit -->\n\n"
            + f"## What to expect\n\n{intro}\n\n" + expectations()
            + "\n## Against their targets and peers\n\n"
            + "![Each ratio against its target](generated_results/performance.png)\n\n" + ratio_table())  # fmt: skip
    if not PAGE.is_file() or PAGE.read_text() != text:
        PAGE.write_text(text)
    return PAGE


if __name__ == "__main__":
    print(write())
