"""`armaxmodal diagnose` on the measured recordings in ../shared/realdata, default settings, as a
user runs it (issue 10, item 8): prints the README's before/after table.

    python scripts/diagnose_realdata.py [--shared ../shared]
"""

from __future__ import annotations

import argparse
import json
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
CLI = [sys.executable, "-P", "-m", "armaxmodal"]  # -P: the package on the path, not the working directory's


def _runs(real: Path) -> dict[str, list[str]]:
    f16 = ["--input", "Force", "--outputs", "Acceleration_1,Acceleration_2,Acceleration_3"]
    runs = {
        f"F-16 multisine level {k}": [str(real / "f16_gvt" / f"F16Data_FullMSine_Level{k}.mat"), *f16] for k in (1, 7)
    }
    for model in ("flex3", "stiff3"):
        folder = real / "mini_shake_table_imu" / model
        runs[f"{model} northridge"] = [*(str(folder / f"northridge__{s}.csv.gz") for s in ("g", "f1", "f2", "f3"))]
        runs[f"{model} northridge"] += ["--input", "g"]
    for event in ("elcentro1", "northridge1"):  # the top IMU lags the table by about 2.3 samples
        folder = real / "mini_shake_table_imu" / "stiff1"
        runs[f"stiff1 {event}"] = [*(str(folder / f"{event}__{s}.csv.gz") for s in ("g", "f1")), "--input", "g"]
    for bridge in sorted(real.glob("bridge_*")):  # the column base or free field in, the deck out
        for record in sorted(bridge.glob("*.csv*")):
            runs[record.name.split(".")[0].replace("_", " ")] = [str(record)]
    return runs


def _delay(effect: dict) -> str:
    """A delay's size and interval, and the nk the move re-chose."""
    p = effect["parameters"]
    if effect["effect"] != "input_delay" or "delay_ci95_ms" not in p:
        return ""
    lo, hi = p["delay_ci95_ms"]
    return f"; {p['delay_ms']:.1f} ms, {lo:.1f}–{hi:.1f}; nk {p['nk_before']} → {p['nk_after']}"


def _fmt(values) -> str:
    return "/".join("–" if v is None else f"{v:.0f}" for v in values)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--shared", default=str(ROOT.parent / "shared"))
    real = Path(parser.parse_args().shared) / "realdata"
    columns = ["recording", "kept (p)", "held-out one-step error", "simulation fit % before → after"]
    print("| " + " | ".join([*columns, "unconfirmed", "verdict", "time"]) + " |")
    print("|---|---|---|---|---|---|---|")
    for name, args in _runs(real).items():
        with tempfile.TemporaryDirectory() as tmp:
            out = Path(tmp) / "d.json"
            start = time.perf_counter()
            command = [*CLI, "diagnose", *args, "--quiet", "--json", str(out)]
            proc = subprocess.run(command, capture_output=True, text=True)
            elapsed = time.perf_counter() - start
            if not out.exists():
                print(f"| {name} | failed: {proc.stderr.strip().splitlines()[-1:]} | | | | | {elapsed:.0f} s |")
                continue
            d = json.loads(out.read_text())
        kept = "; ".join(
            f"`{e['effect']}` {', '.join(e['channels'])} ({e['evidence']['p']:.1g}{_delay(e)})" for e in d["effects"]
        )
        errors = "; ".join(f"{e['error_before']:.4g} → {e['error_after']:.4g}" for e in d["effects"])
        fits = f"{_fmt(d['baseline']['fit_val_pct'])} → {_fmt(d['final']['fit_val_pct'])}"
        unsure = ", ".join(sorted({u["effect"] for u in d["unconfirmed"]})) or "–"
        print(f"| {name} | {kept or 'none'} | {errors or '–'} | {fits} | {unsure} | {d['verdict']} | {elapsed:.0f} s |")


if __name__ == "__main__":
    main()
