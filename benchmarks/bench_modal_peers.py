"""Modal identification side by side with a Python peer, on identical data, in one run.

Peer: sdypy-EMA (LSCF on the H1 FRFs; ``pip install sdypy-EMA``). It has no automatic pole
selection, so it is handed the frequencies armaxmodal selected as its picks
(``select_closest_poles``) -- generous to the peer. pyOMA2 is not available from the package
registry reachable here. Reports time and the frequency / damping errors against the exact
modes for the bundled supine-human rides (random and sweep) and the Chapter 2 system.

    python benchmarks/bench_modal_peers.py
"""

from __future__ import annotations

import contextlib
import io
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

import armaxmodal as am
from armaxmodal.modes.diagram import stabilisation_diagram
from armaxmodal.modes.pipeline import select_modes
from armaxmodal.spectra import measured_frf

ROOT = Path(__file__).resolve().parents[1]
CASES = {
    "supine_random.csv": am.supine_human,
    "supine_sweep.csv": am.supine_human,
    "chapter2_random_zoh.csv": am.chapter2_system,
}


def errors(freqs, damps, truth):
    idx = [int(np.argmin(np.abs(np.asarray(freqs) - f))) for f in truth.freq_hz]
    ef = 100 * (np.asarray(freqs)[idx] / truth.freq_hz - 1)
    ex = 100 * (np.asarray(damps)[idx] / truth.damping - 1)
    return ef, ex


def sdypy(rec, picks):
    import sdypy.EMA as EMA

    f, h, _ = measured_frf(rec)
    band = (f >= 1.0) & (f <= 0.45 * rec.fs)
    sink = io.StringIO()
    with contextlib.redirect_stdout(sink), contextlib.redirect_stderr(sink):  # it prints progress
        model = EMA.Model(frf=h[band].T, freq=f[band], lower=1.0, upper=0.45 * rec.fs, pol_order_high=60)
        model.get_poles(show_progress=False)
        model.select_closest_poles(list(picks), f_window=2.0)
    return np.asarray(model.nat_freq), np.asarray(model.nat_xi)


def main() -> None:
    print(f"{'recording':26s} {'method':14s} {'time s':>7s}  {'f error % per mode':34s} {'damping error %'}")
    for name, system in CASES.items():
        rec = am.read_recording(ROOT / "fixtures" / name)
        truth = system().modes()
        t = time.perf_counter()
        cmd = [
            sys.executable,
            "-m",
            "armaxmodal",
            "--quiet",
            "stabilise",
            str(ROOT / "fixtures" / name),
            "--plot",
            "/tmp/_peer_stab.png",
        ]
        subprocess.run(cmd, check=True)
        t_cli = time.perf_counter() - t
        selection = select_modes(stabilisation_diagram(rec))
        ef, ex = errors(selection.modes.freq_hz, selection.modes.damping, truth)
        print(
            f"{name:26s} {'armaxmodal':14s} {t_cli:7.2f}  {np.array2string(ef, precision=2):34s} "
            f"{np.array2string(ex, precision=1)}  ({len(selection.modes)} modes, automatic)"
        )
        t = time.perf_counter()
        try:
            f_peer, x_peer = sdypy(rec, selection.modes.freq_hz)
            ef, ex = errors(f_peer, x_peer, truth)
            print(
                f"{'':26s} {'sdypy-EMA':14s} {time.perf_counter() - t:7.2f}  {np.array2string(ef, precision=2):34s} "
                f"{np.array2string(ex, precision=1)}  (picks given)"
            )
        except Exception as exc:  # noqa: BLE001 - report any peer failure and go on
            print(f"{'':26s} {'sdypy-EMA':14s} failed: {type(exc).__name__}: {exc}")


if __name__ == "__main__":
    main()
