"""Build the synthetic study of the thesis's spread: 15 subjects x 2 rides (sweep, random),
masses 76.96 +- 8.71 kg, modes varying like Table 3.2, six subjects with a feet sensor
(rigid on five, a separate mass on Sub12), with ``manifest.csv`` and ``truth.json``.

    python tools/make_study.py OUT_FOLDER [--subjects 15] [--seed 2024]
    armaxmodal study OUT_FOLDER --out OUT_FOLDER/results --lump legs,feet
"""

from __future__ import annotations

import argparse

import pandas as pd

from armaxmodal.study import make_study


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("out")
    parser.add_argument("--subjects", type=int, default=15)
    parser.add_argument("--seed", type=int, default=2024)
    args = parser.parse_args()
    truth = make_study(args.out, args.subjects, seed=args.seed)
    print(f"wrote {args.subjects} subjects x 2 rides, manifest.csv and truth.json to {args.out}")
    print(pd.DataFrame(truth["summary"]).round(4).to_string(index=False))


if __name__ == "__main__":
    main()
