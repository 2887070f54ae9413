"""The F-16 multisine's modes by an established peer, beside the product's.

The peer is sdypy-EMA's LSCF (poly-reference least-squares complex frequency, the Polymax family)
on the FRF of the steady-state periods averaged (the first of nine is transient), 2-15 Hz, the
three accelerometers against the force. For each mode of a ``stabilise --json`` run, every LSCF
order from 40 to 80 in steps of 10 gives its physical pole nearest the mode (damping 0-0.2). The
orders whose pole lies within 1 % of the mode are the ones that found it; their mean and spread
are printed beside the product's value and 95 % interval.

There is no truth on a measured structure: the script shows how far two estimators of the same
record disagree, against the width of the product's intervals. Needs the ``peers`` extra
(``pip install -e ".[peers]"``)::

    armaxmodal stabilise F16Data_FullMSine_Level1.mat --input Force \\
        --outputs Acceleration_1,Acceleration_2,Acceleration_3 --orders 2:50 --json level1.json
    python scripts/f16_peer_lscf.py F16Data_FullMSine_Level1.mat level1.json
"""

from __future__ import annotations

import argparse
import json
import warnings

import numpy as np
from scipy.io import loadmat

PERIOD, PERIODS, BAND_HZ, ORDERS = 8192, 9, (2.0, 15.0), (40, 50, 60, 70, 80)


def averaged_frf(path: str) -> tuple[np.ndarray, np.ndarray]:
    """The accelerance FRF (3 outputs, lines in BAND_HZ) of the averaged steady-state periods."""
    d = loadmat(path)
    missing = [k for k in ("Fs", "Force", "Acceleration") if k not in d]
    samples = d["Force"].size if "Force" in d else 0
    if missing or samples != PERIODS * PERIOD:
        raise SystemExit(f"{path}: not an F16Data_FullMSine file (needs Fs, Force and Acceleration of "
                         f"{PERIODS} x {PERIOD} samples; missing: {missing or 'none'}, "
                         f"Force: {samples} samples)")  # fmt: skip
    fs = float(d["Fs"][0, 0])
    u = d["Force"][0].reshape(PERIODS, PERIOD)[1:]
    y = d["Acceleration"].reshape(3, PERIODS, PERIOD)[:, 1:]
    f = np.fft.rfftfreq(PERIOD, 1 / fs)
    band = (f >= BAND_HZ[0]) & (f <= BAND_HZ[1])
    frf = np.fft.rfft(y, axis=-1).mean(1)[:, band] / np.fft.rfft(u, axis=-1).mean(0)[band]
    return f[band], frf


def lscf_nearest(freq: np.ndarray, frf: np.ndarray, targets: list[float]) -> tuple[np.ndarray, np.ndarray]:
    """Per order of ORDERS, the physical LSCF pole nearest each target: ``(freq_hz, damping)``,
    each of shape ``(len(ORDERS), len(targets))``."""
    try:
        from sdypy import EMA
    except ImportError as err:
        raise SystemExit("sdypy-EMA is not installed: pip install -e \".[peers]\"") from err

    model = EMA.Model(frf=frf, freq=freq, lower=BAND_HZ[0], upper=float(freq[-1]), pol_order_high=max(ORDERS),
                      frf_form="accelerance")  # fmt: skip
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        model.get_poles("lscf", show_progress=False)
    fs, xs = [], []
    for order in ORDERS:
        p = np.asarray(model.all_poles[order - 1])
        p = p[p.imag > 0]
        fn, xi = np.abs(p) / (2 * np.pi), -p.real / np.abs(p)
        keep = (xi > 0) & (xi < 0.2)
        near = [int(np.argmin(np.abs(fn[keep] - t))) for t in targets]
        fs.append(fn[keep][near])
        xs.append(xi[keep][near])
    return np.array(fs), np.array(xs)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("mat", help="an F16Data_FullMSine_Level*.mat file")
    parser.add_argument("json", help="the stabilise --json output of the same file")
    args = parser.parse_args()
    modes = json.load(open(args.json)).get("modes")
    if not modes:
        raise SystemExit(f"{args.json}: no modes (the JSON of 'armaxmodal stabilise --json' with modes is needed)")
    f_lscf, x_lscf = lscf_nearest(*averaged_frf(args.mat), [m["freq_hz"] for m in modes])
    print("| product f (Hz) [95 %] | damping | LSCF orders within 1 % | LSCF f (Hz), mean ± SD | damping "
          "| LSCF - product (half-widths) |")
    print("|---|---|---|---|---|---|")
    for k, m in enumerate(modes):
        lo, hi = m["freq_ci95"]
        found = np.abs(f_lscf[:, k] / m["freq_hz"] - 1) <= 0.01
        head = f"| {m['freq_hz']:.4f} [{lo:.4f}, {hi:.4f}] | {m['damping']:.4f} | {found.sum()} of {len(ORDERS)} |"
        if not found.any():
            print(head + " - | - | - |")
            continue
        f, x = f_lscf[found, k], x_lscf[found, k]
        gap = (f.mean() - m["freq_hz"]) / ((hi - lo) / 2)
        print(f"{head} {f.mean():.4f} ± {f.std():.4f} | {x.mean():.4f} | {gap:+.1f} |")


if __name__ == "__main__":
    main()
