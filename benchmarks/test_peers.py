"""Ours and a peer on the same data, timed side by side in one run by pytest-benchmark.

Each comparison is one benchmark group: ``ours`` and ``peer`` run in the same session, so the
machine's drift (about 1.4x between hours here) cancels in their ratio. The JSON that
pytest-benchmark saves carries the machine, the commit and every round; ``benchmarks/report.py``
turns each group into a row of the performance page (the ratio of the medians). Each benchmark
also checks that the two solved the same problem equally well, so a ratio never compares a
fast wrong answer with a slow right one.

    python -m pytest benchmarks/test_peers.py -n 0 --benchmark-json=benchmarks/results/peers.json

Not part of the test suite (``testpaths`` is ``tests``): timings are measured, never asserted.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from bench_inverse import BOUNDS
from bench_pem import NA, NB, NC, ours, pem_loss, scipy_pem

import armaxmodal as am
from armaxmodal.inverse import inner_solve_sdp
from tests.naive import sdp_inner_cvxpy

#: what each group's ratio (peer's median over ours) is held to; saved with the result, so the
#: page is written from the JSON alone
GOALS = {
    "pem-fit": ">= 15 (well ahead of scipy)",
    "sdp-chain": "none (ahead of the modelling layer)",
    "sdp-full": "none (ahead of the modelling layer)",
}
#: what each group compares, for the page
WHAT = {
    "pem-fit": f"one PEM fit (7,200 samples, na {NA}, nb {NB}, nc {NC}, one sensor) against a scipy "
    "Levenberg-Marquardt PEM (lfilter residuals and Jacobian) from the same start",
    "sdp-chain": "the inner SDP of EVPHC, chain pattern (Chapter 2 system), against the same SDP in cvxpy + Clarabel",
    "sdp-full": "the inner SDP of EVPHC, full coupling pattern, against the same SDP in cvxpy + Clarabel",
}


@pytest.fixture(scope="module")
def chest():
    rec = am.read_recording(Path(__file__).resolve().parents[1] / "fixtures" / "supine_random.csv")
    y, u = rec.response[:, 1].copy(), rec.base.copy()
    ours(y, u)  # compile / load the kernels outside the timing
    return y, u, max(NA, NB - 1, NC)


@pytest.fixture(scope="module")
def noisy_modes():
    """The Chapter 2 system's modes with 10 % complex noise on the shapes (the thesis's P1)."""
    modes = am.chapter2_system().modes()
    rng = np.random.default_rng(0)
    z = (rng.standard_normal(modes.shapes.shape) + 1j * rng.standard_normal(modes.shapes.shape)) / np.sqrt(2)
    return modes.eigenvalues, modes.shapes * (1 + 0.1 * z)


@pytest.mark.benchmark(group="pem-fit")
def test_pem_fit_ours(benchmark, chest):
    y, u, t0 = chest
    benchmark.extra_info.update(role="ours", what=WHAT["pem-fit"], goal=GOALS["pem-fit"], goal_ratio=15.0)
    theta, _ = benchmark(ours, y, u)
    benchmark.extra_info["loss"] = pem_loss(theta, y, u, t0)
    theta_peer, _ = scipy_pem(y, u, t0)
    assert benchmark.extra_info["loss"] <= pem_loss(theta_peer, y, u, t0) * (1 + 1e-4)


@pytest.mark.benchmark(group="pem-fit")
def test_pem_fit_peer(benchmark, chest):
    y, u, t0 = chest
    benchmark.extra_info["role"] = "peer"
    theta, _ = benchmark(scipy_pem, y, u, t0)
    benchmark.extra_info["loss"] = pem_loss(theta, y, u, t0)


def _pattern(name: str) -> np.ndarray:
    if name == "full":
        return np.ones((4, 4), bool)
    return np.abs(np.subtract.outer(np.arange(4), np.arange(4))) <= 1


@pytest.mark.parametrize("pattern", ["chain", "full"])
def test_sdp_ours(benchmark, noisy_modes, pattern):
    benchmark.group = f"sdp-{pattern}"
    benchmark.extra_info.update(role="ours", what=WHAT[benchmark.group], goal=GOALS[benchmark.group], goal_ratio=None)
    lam, psi = noisy_modes
    solution = benchmark(inner_solve_sdp, lam, psi, pattern=_pattern(pattern), mass_ratio_bounds=BOUNDS)
    m_peer, _, k_peer = sdp_inner_cvxpy(lam, psi, _pattern(pattern), BOUNDS)
    np.testing.assert_allclose(solution.structure.masses, m_peer, rtol=1e-4)
    assert np.linalg.norm(solution.structure.K - k_peer) < 1e-4 * np.linalg.norm(k_peer)


@pytest.mark.parametrize("pattern", ["chain", "full"])
def test_sdp_peer(benchmark, noisy_modes, pattern):
    benchmark.group = f"sdp-{pattern}"
    benchmark.extra_info["role"] = "peer"
    lam, psi = noisy_modes
    benchmark(sdp_inner_cvxpy, lam, psi, _pattern(pattern), BOUNDS)
