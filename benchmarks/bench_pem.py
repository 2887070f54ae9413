"""PEM benchmark: armaxmodal against its peers on identical data, in one run.

Peers, all fitting the same ARMAX structure to the same recording:
* statsmodels SARIMAX (exact Gaussian ML by Kalman filter) with the lagged outputs and inputs as
  exogenous regressors and MA(nc) errors -- the same model, A y = B u + C e;
* a plain scipy Levenberg-Marquardt PEM (scipy.optimize.least_squares, method "lm") with
  residuals and an analytic Jacobian from scipy.signal.lfilter, started where ours starts.

Every loss is the same number: the mean squared one-step prediction error of the fitted
parameters, evaluated by one function. Then: a whole order sweep (na 2..40, four sensors),
record-length scaling (1e4..1e6 samples: time and peak memory per sample) and the cost of the
first call after install (numba compilation) versus a later process (on-disk cache).

    python benchmarks/bench_pem.py [--quick]

The ratio the performance page reports (one fit against scipy's) is timed by pytest-benchmark in
``benchmarks/test_peers.py``; this script prints the wider comparison around it.
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
import tempfile
import time
import tracemalloc
import warnings
from pathlib import Path

import numpy as np
import scipy.optimize
import scipy.signal

import armaxmodal as am
from armaxmodal.armax import ArmaxModel
from armaxmodal.estimate import starts as starts_mod

ROOT = Path(__file__).resolve().parents[1]
NA, NB, NC, NK = 8, 9, 4, 0


def pem_loss(theta, y, u, t0):
    model = ArmaxModel(np.r_[1.0, theta[:NA]], theta[NA : NA + NB][None], np.r_[1.0, theta[NA + NB :]], NK, 60.0)
    e = model.prediction_errors(y, u)[t0:]
    return float(np.mean(e**2))


def best_of(func, repeat):
    times = []
    for _ in range(repeat):
        t = time.perf_counter()
        out = func()
        times.append(time.perf_counter() - t)
    return min(times), out


def ours(y, u):
    fit = am.fit_armax((u, y), NA, NB, NC, NK, fs=60.0)
    m = fit.models[0]
    return np.concatenate([m.a[1:], m.b[0], m.c[1:]]), bool(fit.converged[0])


def scipy_pem(y, u, t0):
    """Plain LM PEM: lfilter residuals and an lfilter Jacobian (what one writes with scipy)."""
    u_t = np.ascontiguousarray(u[None])
    start = starts_mod.hannan_rissanen(np.ascontiguousarray(y), u_t, NA, NB, NC, NK, t0, y.size)

    def residual(theta):
        a, b, c = np.r_[1.0, theta[:NA]], theta[NA : NA + NB], np.r_[1.0, theta[NA + NB :]]
        w = scipy.signal.lfilter(a, [1.0], y) - scipy.signal.lfilter(b, [1.0], u)
        return scipy.signal.lfilter([1.0], c, w)[t0:]

    def jac(theta):
        c = np.r_[1.0, theta[NA + NB :]]
        e = np.r_[np.zeros(t0), residual(theta)]
        yf, uf, ef = (scipy.signal.lfilter([1.0], c, s) for s in (y, u, e))
        cols = [np.r_[np.zeros(i), yf[:-i]] for i in range(1, NA + 1)]
        cols += [-np.r_[np.zeros(j), uf[: uf.size - j]] for j in range(NB)]
        cols += [-np.r_[np.zeros(i), ef[:-i]] for i in range(1, NC + 1)]
        return np.column_stack(cols)[t0:]

    res = scipy.optimize.least_squares(residual, start, jac=jac, method="lm", xtol=1e-10, ftol=1e-10)
    return res.x, res.success


def sarimax(y, u, t0, maxiter):
    from statsmodels.tsa.statespace.sarimax import SARIMAX

    lagged = [-y[t0 - i : y.size - i] for i in range(1, NA + 1)] + [u[t0 - j : u.size - j] for j in range(NB)]
    model = SARIMAX(y[t0:], exog=np.column_stack(lagged), order=(0, 0, NC), trend="n")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        res = model.fit(disp=False, maxiter=maxiter)
    return np.asarray(res.params[: NA + NB + NC]), bool(res.mle_retvals["converged"])


def one_fit(rec, quick):
    y, u = rec.response[:, 1].copy(), rec.base.copy()
    t0 = max(NA, NB - 1, NC)
    ours(y, u)  # compile / load the kernels
    rows = []
    t, (theta, ok) = best_of(lambda: ours(y, u), 20)
    rows.append(("armaxmodal PEM", t, pem_loss(theta, y, u, t0), ok))
    t, (theta, ok) = best_of(lambda: scipy_pem(y, u, t0), 3)
    rows.append(("scipy LM PEM (lfilter)", t, pem_loss(theta, y, u, t0), ok))
    for maxiter in (50,) if quick else (50, 1000):
        t, (theta, ok) = best_of(lambda m=maxiter: sarimax(y, u, t0, m), 1)
        rows.append((f"statsmodels SARIMAX maxiter={maxiter}", t, pem_loss(theta, y, u, t0), ok))
    print(f"\nOne fit: 7200 samples, na={NA} nb={NB} nc={NC} nk={NK}, one sensor (chest), warm")
    print(f"{'method':38s} {'time s':>10s} {'loss':>14s} {'converged':>9s} {'time / ours':>11s}")
    for name, t, loss, ok in rows:
        print(f"{name:38s} {t:10.4f} {loss:14.8e} {ok!s:>9s} {t / rows[0][1]:11.1f}")
    return rows


def sweep(rec, quick):
    from armaxmodal.modes.diagram import stabilisation_diagram

    orders = range(2, 21 if quick else 41)
    print(
        f"\nOrder sweep: na {orders.start}..{orders.stop - 1} (every order), nb = na + 1, nc = na, nk = 0, "
        "7200 samples, one process"
    )
    for shared in (False, True):
        t = time.perf_counter()
        iters = 0
        for na in orders:
            fit = am.fit_armax(rec, na, na + 1, na, 0, shared_poles=shared, warn=False)
            iters += int(fit.iterations.sum())
        label = "shared poles, 4 sensors jointly" if shared else "per sensor, 4 sensors"
        print(f"  {label:32s} {time.perf_counter() - t:8.2f} s  ({iters} LM iterations)")
    print("Stabilisation sweep as `stabilise` runs it (even na, shared + 4 sensors, 2 worker threads):")
    for top in (30, 40):
        t = time.perf_counter()
        diagram = stabilisation_diagram(rec, range(2, top + 1, 2), nk=-5)
        print(f"  na 2..{top}: {len(diagram.fits)} fits in {time.perf_counter() - t:.2f} s")
    t = time.perf_counter()
    subprocess.run(
        [
            sys.executable,
            "-m",
            "armaxmodal",
            "--quiet",
            "stabilise",
            "fixtures/supine_random.csv",
            "--plot",
            str(Path(tempfile.gettempdir()) / "_bench_stab.png"),
        ],
        cwd=ROOT,
        check=True,
    )
    print(
        f"  whole `armaxmodal stabilise` command (process start, nk choice, sweep, selection, plot): "
        f"{time.perf_counter() - t:.2f} s"
    )


def scaling(quick):
    s = am.supine_human()
    print("\nScaling (one sensor, orders as above): time and peak Python-heap memory per sample")
    print(f"{'samples':>10s} {'time s':>9s} {'us/sample':>10s} {'peak MB':>9s} {'bytes/sample':>13s}")
    for n in (10_000, 100_000) if quick else (10_000, 100_000, 1_000_000):
        u = am.random_vibration(60.0, n / 60.0, seed=1)
        y = am.simulate(s, u, 60.0)[:, 1] + 0.05 * np.random.default_rng(2).standard_normal(n)
        tracemalloc.start()
        t = time.perf_counter()
        am.fit_armax((u, y), NA, NB, NC, NK, fs=60.0, warn=False)
        dt = time.perf_counter() - t
        peak = tracemalloc.get_traced_memory()[1]
        tracemalloc.stop()
        print(f"{n:10d} {dt:9.3f} {1e6 * dt / n:10.2f} {peak / 1e6:9.1f} {peak / n:13.1f}")


def first_call():
    code = (
        "import time; t=time.perf_counter(); import armaxmodal as am; "
        "r=am.read_recording('fixtures/supine_random.csv'); am.fit_armax(r, 8, 9, 4, 0); "
        "print(f'{time.perf_counter()-t:.2f}')"
    )
    with tempfile.TemporaryDirectory() as cache:
        env = dict(os.environ, NUMBA_CACHE_DIR=cache)
        runs = [
            subprocess.run(
                [sys.executable, "-c", code], cwd=ROOT, env=env, capture_output=True, text=True, check=True
            ).stdout.strip()
            for _ in range(2)
        ]
    print(f"\nImport + read + first fit in a new process: empty numba cache {runs[0]} s, cached {runs[1]} s")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="smaller sweep and sizes")
    args = parser.parse_args()
    rec = am.read_recording(ROOT / "fixtures" / "supine_random.csv")
    print(f"machine: {os.cpu_count()} cores; numpy {np.__version__}")
    one_fit(rec, args.quick)  # the saved ratio against scipy is benchmarks/test_peers.py's
    sweep(rec, args.quick)
    scaling(args.quick)
    first_call()


if __name__ == "__main__":
    main()
