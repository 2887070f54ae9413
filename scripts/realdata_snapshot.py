"""Write every JSON and pole CSV of the real-data table into one folder, to compare a refactor's
outputs byte for byte (issue 28: a layout move keeps every output identical).

Run:  python scripts/realdata_snapshot.py OUT_DIR [--shared ../shared]
      diff -r BEFORE_DIR AFTER_DIR
"""

from __future__ import annotations

import argparse
import re
import subprocess
import sys
import tempfile
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from realdata_table import _damaged  # noqa: E402  (the damaged fixture copies of the table)

# -P: the command line runs the package on the path, as this script does; without it "python -m" puts
# the working directory first, so run from a checkout with PYTHONPATH at a copy it ran the checkout
CLI = [sys.executable, "-P", "-m", "armaxmodal", "--quiet", "stabilise"]


def _runs(real: Path) -> dict[str, list[str]]:
    f16 = ["--input", "Force", "--outputs", "Acceleration_1,Acceleration_2,Acceleration_3", "--orders", "2:50"]
    runs = {f"f16_level{k}": [str(real / "f16_gvt" / f"F16Data_FullMSine_Level{k}.mat"), *f16] for k in (1, 3, 5, 7)}
    table = real / "mini_shake_table_imu"
    for model, events in (("flex3", ("northridge", "sine2.0")), ("stiff3", ("northridge", "sine2.0")),
                          ("stiff1", ("elcentro1", "northridge1"))):
        sensors = ("g", "f1") if model == "stiff1" else ("g", "f1", "f2", "f3")
        for event in events:
            files = [str(table / model / f"{event}__{s}.csv.gz") for s in sensors]
            runs[f"{model}_{event}"] = [*files, "--input", "g"]
    for path in sorted((real / "bridge_capistrano").glob("*.csv")):
        runs[f"bridge_{path.stem.split('_')[1]}"] = [str(path)]
    return runs


def main() -> None:
    parser = argparse.ArgumentParser()
    parser.add_argument("out")
    parser.add_argument("--shared", default=str(Path(__file__).resolve().parents[2] / "shared"))
    args = parser.parse_args()
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    with tempfile.TemporaryDirectory() as tmp:
        runs = _runs(Path(args.shared).resolve() / "realdata")
        runs.update(_damaged(Path(tmp)))
        for name, run in runs.items():
            stem = re.sub(r"[^A-Za-z0-9_.-]+", "_", name)
            proc = subprocess.run([*CLI, *run, "--json", str(out / f"{stem}.json"), "--csv", str(out / f"{stem}.csv")],
                                  capture_output=True, text=True)
            text = (proc.stdout + proc.stderr).replace(tmp, "TMP")
            (out / f"{stem}.txt").write_text(f"rc {proc.returncode}\n{text}")
            print(name, proc.returncode, flush=True)


if __name__ == "__main__":
    main()
