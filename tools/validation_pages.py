"""The validation pages' tables and figures, written from the saved results of the scripts that
measure them (``benchmarks/results/validation/*.json``, ``benchmarks/results/*.json``), so that a
page cannot show a number its script no longer gives. The docs build runs :func:`write` (from
``docs/conf.py``); the pages include the fragments it writes to ``docs/generated_results/``.

    python scripts/count_battery.py --six 6 --results benchmarks/results/validation/count_battery.json
    python scripts/mc_coverage.py --hold bandlimited \
        --results benchmarks/results/validation/mc_coverage_bandlimited.json
    python scripts/realdata_table.py --results benchmarks/results/validation/realdata.json
    python tools/validation_pages.py      # the fragments again, without the docs
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
RESULTS = ROOT / "benchmarks" / "results"
OUT = ROOT / "docs" / "generated_results"
#: the supine body's exact modes, the truth of the damaged copies (thesis Table 4.3)
SUPINE_HZ = (5.832, 8.305, 13.504, 16.246)
#: what the records' READMEs give (quick checks by their authors or by us, not published truths)
REFERENCES = {
    "F-16 multisine level 1": "3.54, 5.12, 6.42, 7.32, 9.17, 12.36 (ARX, README)",
    "F-16 multisine level 7": "3.38, 4.97, 6.15, 7.18, 9.05, 12.27 (ARX, README)",
    "flex3 northridge": "3.52 (H1), 3.8 / 12.9 (ARX), README",
    "flex3 sine2.0": "3.65 (period), README",
    "stiff3 northridge": "7.73 (H1), 7.79 / 24.9 / 39.8 (ARX), README",
    "stiff3 sine2.0": "7.85 (period), README",
}


def _load(name: str) -> dict | None:
    path = RESULTS / name
    return json.loads(path.read_text()) if path.is_file() else None


def _save(fig, name: str) -> None:
    import matplotlib.pyplot as plt

    fig.tight_layout()
    fig.savefig(OUT / name, dpi=90)
    plt.close(fig)


def _missing(script: str) -> str:
    return f"*No saved result: run `{script}`.*\n"


def count_battery() -> str:
    """Bodies never seen: right per kind, and each mode's frequency error in Cramér-Rao bounds."""
    import matplotlib.pyplot as plt

    data = _load("validation/count_battery.json")
    if data is None:
        return _missing("python scripts/count_battery.py --results ...")
    cases = [{**c, "kind": "light chains" if c["kind"].startswith("light") else c["kind"]} for c in data["cases"]]
    kinds = sorted({c["kind"] for c in cases}, key=[c["kind"] for c in cases].index)
    lines = [
        "| systems | rides | right | wrong, said `uncertain` or `poor` | wrong, said `good` |",
        "|---|---|---|---|---|",
    ]
    for kind in kinds:
        group = [c for c in cases if c["kind"] == kind]
        wrong = [c for c in group if not c["right"]]
        good = sum(c["quality"] == "good" for c in wrong)
        lines.append(f"| {kind} | {len(group)} | {len(group) - len(wrong)} | {len(wrong) - good} | {good} |")
    fig, ax = plt.subplots(figsize=(9, 3.2))
    for k, kind in enumerate(kinds):
        errors = [m["error_bounds"] for c in cases if c["kind"] == kind for m in c["modes"]]
        errors = np.array([e for e in errors if e is not None and np.isfinite(e)])
        jitter = np.random.default_rng(k).uniform(-0.25, 0.25, errors.size)
        ax.scatter(np.clip(errors, -10, 10), k + jitter, s=8, alpha=0.6)
    ax.axvspan(-2, 2, color="#2a7", alpha=0.1, label="within 2 bounds")
    ax.set_yticks(range(len(kinds)), kinds)
    ax.set_xlabel("frequency error of each exact mode's nearest reported mode, in Cramér–Rao bounds (clipped at ±10)")
    ax.legend(loc="lower right", fontsize=8)
    _save(fig, "count_battery.png")
    wrong = [c for c in cases if not c["right"]]
    listed = "\n".join(f"- {c['case']} (`{c['quality']}`): {'; '.join(c['why'])}" for c in wrong)
    return (
        f"Seed {data['seed']}, {len(cases)} rides (`scripts/count_battery.py`):\n\n"
        + "\n".join(lines)
        + "\n\n![Frequency errors in Cramér–Rao bounds](count_battery.png)\n\n"
        + (f"The wrong ones, and why:\n\n{listed}\n" if wrong else "")
    )


def coverage() -> str:
    """Monte Carlo coverage of the 95 % intervals, per mode."""
    import matplotlib.pyplot as plt

    data = _load("validation/mc_coverage_bandlimited.json")
    if data is None:
        return _missing("python scripts/mc_coverage.py --hold bandlimited --results ...")
    modes = data["modes"]
    lines = [
        "| mode (Hz) | found | frequency interval holds the truth | damping interval holds it | "
        "spread / reported SD, frequency | damping |",
        "|---|---|---|---|---|---|",
    ]
    for m in modes:
        lines.append(
            f"| {m['freq_hz']:.2f} | {m['found']}/{m['rides']} | {m['freq_covered']:.0%} | "
            f"{m['damping_covered']:.0%} | {m['freq_sd_over_se']:.2f} | {m['damping_sd_over_se']:.2f} |"
        )
    fig, ax = plt.subplots(figsize=(7, 3))
    x = np.arange(len(modes))
    ax.bar(x - 0.2, [100 * m["freq_covered"] for m in modes], 0.4, label="frequency")
    ax.bar(x + 0.2, [100 * m["damping_covered"] for m in modes], 0.4, label="damping")
    ax.axhline(95, color="k", lw=1, ls="--", label="nominal 95 %")
    ax.set_xticks(x, [f"{m['freq_hz']:.2f} Hz" for m in modes])
    ax.set_ylim(50, 100)
    ax.set_ylabel("rides whose interval holds the truth (%)")
    ax.legend(fontsize=8, loc="lower right")
    _save(fig, "coverage.png")
    return (
        f"{data['seeds']} rides of the supine body, {data['duration_s']:g} s at 60 Hz, 5 % sensor noise, "
        f"simulated {data['hold']} (`scripts/mc_coverage.py`):\n\n"
        + "\n".join(lines)
        + "\n\n![Coverage of the 95 % intervals](coverage.png)\n"
    )


def efficiency() -> str:
    """The modal model's spread and bias against the Cramér-Rao bound, per mode and variant."""
    import matplotlib.pyplot as plt

    data = _load("validation/efficiency.json")
    if data is None:
        return _missing("python scripts/mc_crb_modal.py --results ...")
    rows = data["rows"]
    names = {
        "as_fitted": "as the refit fits",
        "inner_band": "the band's edges left out",
        "zoh": "the zero-order-hold form",
    }
    lines = [
        "| fitted | mode (Hz) | frequency: RMS error | bias | damping: RMS error | bias |",
        "|---|---|---|---|---|---|",
    ]
    for r in rows:
        lines.append(
            f"| {names[r['variant']]} | {r['freq_hz']:.2f} | {r['freq_rms']:.2f} | {r['freq_bias']:+.2f} | "
            f"{r['damping_rms']:.2f} | {r['damping_bias']:+.2f} |"
        )
    fig, ax = plt.subplots(figsize=(7, 3))
    variants = [v for v in names if any(r["variant"] == v for r in rows)][:2]
    for k, variant in enumerate(variants):
        sub = [r for r in rows if r["variant"] == variant]
        x = np.arange(len(sub)) + (k - 0.5) * 0.35
        ax.bar(x, [r["freq_rms"] for r in sub], 0.35, label=f"frequency, {names[variant]}")
    ax.axhline(1, color="k", lw=1, ls="--", label="the bound")
    ax.set_xticks(range(len(sub)), [f"{r['freq_hz']:.2f} Hz" for r in sub])
    ax.set_ylabel("RMS error in Cramér–Rao bounds")
    ax.legend(fontsize=8)
    _save(fig, "efficiency.png")
    return (
        f"{data['records']} rides of the five-segment body (`scripts/mc_crb_modal.py`), errors in units of "
        "each record's own bound (1: as good as any unbiased estimator can be):\n\n"
        + "\n".join(lines)
        + "\n\n![RMS error of each mode's frequency in Cramér–Rao bounds](efficiency.png)\n"
    )


def realdata() -> str:
    """The measured records and the damaged copies: modes, verdict, reference."""
    import matplotlib.pyplot as plt

    data = _load("validation/realdata.json")
    if data is None:
        return _missing("python scripts/realdata_table.py --results ...")
    measured = [r for r in data["runs"] if r["record"].split()[0] in ("F-16", "flex3", "stiff3")]
    damaged = [r for r in data["runs"] if r not in measured]
    lines = ["| record | modes (Hz) | verdict | the README's values (Hz) |", "|---|---|---|---|"]
    for r in measured:
        modes = ", ".join(f"{m['freq_hz']:.2f}" for m in r.get("modes", [])) or r.get("failed", "")
        lines.append(f"| {r['record']} | {modes} | {r.get('quality', 'failed')} | {REFERENCES.get(r['record'], '—')} |")
    copies = [
        "| damaged copy of the bundled ride | exact modes in their 95 % interval | largest error | verdict | notes |",
        "|---|---|---|---|---|",
    ]
    for r in damaged:
        modes = r.get("modes", [])
        found = np.array([m["freq_hz"] for m in modes])
        nearest = [int(np.argmin(np.abs(found / f - 1))) if found.size else -1 for f in SUPINE_HZ]
        inside = sum(
            k >= 0 and modes[k]["freq_ci95"][0] <= f <= modes[k]["freq_ci95"][1]
            for f, k in zip(SUPINE_HZ, nearest, strict=True)
        )
        errors = [abs(found[k] / f - 1) if k >= 0 else np.inf for f, k in zip(SUPINE_HZ, nearest, strict=True)]
        worst = f"{100 * max(errors):.1f} %" if np.isfinite(max(errors)) else "a mode missing"
        copies.append(
            f"| {r['record']} | {inside} of {len(SUPINE_HZ)} | {worst} | {r.get('quality', 'failed')} | "
            f"{', '.join(r.get('codes', []))} |"
        )
    fig, ax = plt.subplots(figsize=(7, 3.2))
    for r in [r for r in measured if r["record"].startswith("F-16")]:
        level = int(r["record"].split()[-1])
        for m in r.get("modes", []):
            lo, hi = m["freq_ci95"]
            ax.errorbar(m["freq_hz"], level, xerr=[[m["freq_hz"] - lo], [hi - m["freq_hz"]]], fmt="o", ms=4, color="C0")
    ax.set_yticks([1, 3, 5, 7], ["level 1", "level 3", "level 5", "level 7"])
    ax.set_xlabel("natural frequency (Hz), 95 % interval")
    ax.set_title("F-16 ground vibration test: the modes soften as the force grows", fontsize=10)
    _save(fig, "f16_levels.png")
    return (
        "\n".join(lines) + "\n\n![The F-16's modes at four force levels](f16_levels.png)\n\n" + "\n".join(copies) + "\n"
    )


def write() -> list[Path]:
    """Write every fragment and figure (only the text files that changed are rewritten)."""
    import matplotlib

    matplotlib.use("Agg")
    OUT.mkdir(exist_ok=True)
    written = []
    for name, make in (
        ("count_battery", count_battery),
        ("coverage", coverage),
        ("efficiency", efficiency),
        ("realdata", realdata),
    ):
        path = OUT / f"{name}.md"
        text = make()
        if not path.is_file() or path.read_text() != text:
            path.write_text(text)
        written.append(path)
    return written


if __name__ == "__main__":
    print(*write(), sep="\n")
