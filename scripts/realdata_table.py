"""The README's real-data table: `armaxmodal stabilise` with default settings (except the
F-16's order range and output choice, stated) on the recordings in shared/realdata, and on
fixture copies damaged as real data are. Prints Markdown rows and the time of each run.

Run:  python scripts/realdata_table.py [--shared ../shared]
"""

from __future__ import annotations

import argparse
import json
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
import pandas as pd

ROOT = Path(__file__).resolve().parents[1]
CLI = [sys.executable, "-P", "-m", "armaxmodal"]  # -P: the package on the path, not the working directory's


def _damaged(tmp: Path) -> dict:
    d = pd.read_csv(ROOT / "fixtures" / "supine_random.csv", comment="#")
    outs = ["head", "chest", "pelvis", "legs"]
    cases = {}

    def save(name, frame):
        path = tmp / f"{name}.csv"
        # a shifted channel's unknown first samples are dropped, not filled: a filled run of
        # equal samples is a (true) stuck_samples finding the damage did not intend
        frame.dropna().to_csv(path, index=False)
        cases[name] = [str(path)]

    g = d.copy()
    g[outs] += 9.81
    g["head"] = g["head"].shift(2)  # the first two rows, unknown, are dropped below
    save("gravity + head 2 samples late", g)
    late = d.copy()
    late["base"] = late["base"].shift(3)
    save("input 3 samples late", late)
    dup = d.copy()
    dup["head_copy"] = dup["head"]
    save("head exported twice", dup)
    inv = d.copy()
    inv["chest"] = -inv["chest"]
    save("chest inverted", inv)
    mg = d.copy()
    mg["head"] *= 1000 / 9.80665
    save("head in mg", mg)
    g_base = d.copy()
    g_base["base"] /= 9.80665
    save("base in g", g_base)
    stuck = d.copy()
    stuck.loc[3000:3051, "pelvis"] = stuck.loc[2999, "pelvis"]
    save("pelvis stuck for 53 samples", stuck)
    hum = d.copy()
    hum["legs"] += 0.3 * np.sin(2 * np.pi * 12.5 * hum["time"])
    save("hum 0.3 m s⁻² at 12.5 Hz on legs", hum)
    jump = d.copy()
    jump.loc[len(d) // 2 :, "pelvis"] += 0.8
    save("pelvis offset jumps +0.8 at 60 s", jump)
    drift = d.copy()
    drift[outs] += 0.05 * np.arange(len(d))[:, None] / 60.0
    save("drift 0.05 m per s^3", drift)
    temperature = d.copy()
    noise = np.random.default_rng(0).standard_normal(len(d))
    temperature["temperature"] = 20 + d["time"] / d["time"].iloc[-1] + 0.01 * noise
    save("a temperature channel beside the sensors", temperature)
    clipped = d.copy()
    clipped["head"] = clipped["head"].clip(upper=np.sort(clipped["head"])[-40])  # peaks clipped in single samples
    save("head clipped at its 40th-largest sample", clipped)
    flipped = d.copy()
    flipped["base"] = -flipped["base"]
    save("base inverted", flipped)
    held = d.copy()
    held["head"] = held["head"].to_numpy()[np.arange(len(d)) // 2 * 2]  # 30 Hz, forward-filled to 60
    save("head sampled at 30 Hz and held to 60 Hz", held)
    lines = d.copy()
    lines["head"] = np.interp(np.arange(len(d)), np.arange(0, len(d), 2), d["head"].to_numpy()[::2])
    save("head sampled at 30 Hz and interpolated to 60 Hz", lines)
    gap = tmp / "rows 3000-3001 dropped.csv"
    d.drop(index=[3000, 3001]).to_csv(gap, index=False)
    cases["rows 3000-3001 dropped by the logger"] = [str(gap)]
    path = tmp / "pandas index column.csv"
    d.to_csv(path)  # pandas' default: the row index as an unnamed first column
    cases["exported with pandas' index column"] = [str(path)]
    return cases


def _run(args: list[str]) -> tuple[dict | None, float, str]:
    with tempfile.TemporaryDirectory() as tmp:
        out = Path(tmp) / "m.json"
        start = time.perf_counter()
        proc = subprocess.run([*CLI, "--quiet", "stabilise", *args, "--json", str(out)], capture_output=True, text=True)
        elapsed = time.perf_counter() - start
        data = json.loads(out.read_text()) if out.exists() else None
        return data, elapsed, proc.stderr.strip().splitlines()[-1] if proc.returncode else ""


def main() -> None:
    parser = argparse.ArgumentParser()
    parser.add_argument("--shared", default=str(ROOT.parent / "shared"))
    parser.add_argument("--results", help="write every run's modes and verdict to this JSON file (the validation "
                        "page is drawn from benchmarks/results/validation/realdata.json)")  # fmt: skip
    options = parser.parse_args()
    real = Path(options.shared) / "realdata"
    results = []
    f16 = ["--input", "Force", "--outputs", "Acceleration_1,Acceleration_2,Acceleration_3", "--orders", "2:50"]
    runs = {
        f"F-16 multisine level {k}": [str(real / "f16_gvt" / f"F16Data_FullMSine_Level{k}.mat"), *f16]
        for k in (1, 3, 5, 7)
    }
    for model in ("flex3", "stiff3"):
        for event in ("northridge", "sine2.0"):
            folder = real / "mini_shake_table_imu" / model
            files = [str(folder / f"{event}__{s}.csv.gz") for s in ("g", "f1", "f2", "f3")]
            runs[f"{model} {event}"] = [*files, "--input", "g"]
    with tempfile.TemporaryDirectory() as tmp:
        runs.update(_damaged(Path(tmp)))
        print("| recording | analysis fs | modes (Hz, damping %) | flagged model error | warnings | time |")
        print("|---|---|---|---|---|---|")
        for name, args in runs.items():
            data, elapsed, err = _run(args)
            results.append(_result(name, data, elapsed, err))
            if data is None:
                print(f"| {name} | | failed: {err} | | | {elapsed:.1f} s |")
                continue
            modes = ", ".join(f"{m['freq_hz']:.2f} ({100 * m['damping']:.2f})" for m in data["modes"])
            flagged = ", ".join(f"{m['freq_hz']:.2f}" for m in data["modes"] if m.get("model_error_dominates")) or "-"
            codes = ", ".join(sorted({w["code"] for w in data["warnings"]})) or "-"
            print(f"| {name} | {data['analysis_fs']:.4g} Hz | {modes} | {flagged} | {codes} | {elapsed:.1f} s |")
    if options.results:
        from armaxmodal import __version__
        from armaxmodal.io.write import strict_json

        summary = {"runs": results, "armaxmodal_version": __version__}
        Path(options.results).write_text(json.dumps(strict_json(summary), indent=1, allow_nan=False) + "\n")


def _result(name: str, data: dict | None, elapsed: float, err: str) -> dict:
    """One run for the validation page: its modes with their intervals, verdict, notes and time."""
    if data is None:
        return {"record": name, "failed": err, "seconds": elapsed}
    modes = [{"freq_hz": m["freq_hz"], "freq_ci95": m["freq_ci95"], "damping": m["damping"]} for m in data["modes"]]
    return {"record": name, "analysis_fs": data["analysis_fs"], "quality": data["quality"], "modes": modes,
            "codes": sorted({w["code"] for w in data["warnings"]}), "seconds": elapsed}  # fmt: skip


if __name__ == "__main__":
    main()
