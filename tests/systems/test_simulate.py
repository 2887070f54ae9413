import numpy as np
import pytest
import scipy.signal

import armaxmodal as am
from armaxmodal._kernels import hold_recursion
from armaxmodal.exceptions import DataError
from tests import naive

# Kernel and reference do the same float operations in a different order.
KERNEL_RTOL = 1e-10
# The convergence criterion: halving the internal step moves the output by < 1e-6.
CONVERGENCE_RTOL = 1e-6
# Steady-state sinusoid against the analytic transmissibility: limited by the cubic hold's
# error at 32x oversampling (~2e-7 of the peak).
STEADY_STATE_RTOL = 2e-6


def _sinusoid(fs, n, cycles):
    """A sinusoid periodic over the record (exactly band-limited)."""
    t = np.arange(n) / fs
    f = cycles * fs / n
    return np.sin(2 * np.pi * f * t), f, t


def test_kernel_matches_naive_reference():
    rng = np.random.default_rng(0)
    phi = rng.standard_normal((5, 5)) * 0.3
    gam = rng.standard_normal((5, 4))
    u = rng.standard_normal(403)
    got = hold_recursion(phi, gam, u, 400, 4)
    ref = naive.hold_recursion(phi, gam, u, 400, 4)
    np.testing.assert_allclose(got, ref, rtol=KERNEL_RTOL, atol=1e-12)


def test_zoh_matches_scipy_cont2discrete():
    """ZOH against scipy's exact ZOH discretisation and dlsim (an established library)."""
    s = am.supine_human()
    u = am.random_vibration(60.0, 20.0, seed=3)
    for quantity, frame in [
        ("acceleration", "absolute"),
        ("acceleration", "relative"),
        ("displacement", "relative"),
    ]:
        a, b, c, d = s.state_space(quantity, frame)
        ad, bd, cd, dd, _ = scipy.signal.cont2discrete((a, b, c, d), 1 / 60.0, method="zoh")
        _, ref, _ = scipy.signal.dlsim((ad, bd, cd, dd, 1 / 60.0), u)
        got = am.simulate(s, u, 60.0, hold="zoh", quantity=quantity, frame=frame)
        np.testing.assert_allclose(got, ref, rtol=1e-9, atol=1e-12 * np.abs(ref).max())


def test_zoh_is_exact_at_any_internal_step():
    s = am.chapter2_system()
    u = am.random_vibration(100.0, 10.0, (0.5, 45.0), seed=1)
    y1 = am.simulate(s, u, 100.0, hold="zoh", oversample=1)
    y8 = am.simulate(s, u, 100.0, hold="zoh", oversample=8)
    np.testing.assert_allclose(y8, y1, rtol=0, atol=1e-12 * np.abs(y1).max())


@pytest.mark.parametrize(
    "system, fs, band",
    [(am.supine_human, 60.0, (0.5, 28.0)), (am.chapter2_system, 100.0, (0.5, 45.0))],
)
def test_bandlimited_converges_when_internal_step_halves(system, fs, band):
    s = system()
    u = am.random_vibration(fs, 30.0, band, seed=5)
    y = am.simulate(s, u, fs, hold="bandlimited")
    y_half = am.simulate(s, u, fs, hold="bandlimited", oversample=64)
    assert np.abs(y - y_half).max() < CONVERGENCE_RTOL * np.abs(y_half).max()


@pytest.mark.parametrize("quantity", ["acceleration", "velocity", "displacement"])
@pytest.mark.parametrize("frame", ["absolute", "relative"])
def test_bandlimited_steady_state_matches_analytic_transmissibility(quantity, frame):
    """A periodic sinusoid settles to |T(w)| and arg T(w) of the exact structure."""
    s = am.supine_human()
    fs, n = 60.0, 1200
    u, f, t = _sinusoid(fs, n, 170)  # 8.5 Hz, near mode 2
    y = am.simulate(s, u, fs, hold="bandlimited", quantity=quantity, frame=frame)
    w = 2 * np.pi * f
    rel_acc = -s.epfrf([f])[0]  # relative acceleration per unit base acceleration
    gain = {
        "acceleration": rel_acc,
        "velocity": rel_acc / (1j * w),
        "displacement": rel_acc / (1j * w) ** 2,
    }[quantity]
    expected = np.imag(np.exp(1j * w * t)[:, None] * gain[None, :])  # response to sin(wt)
    if frame == "absolute":
        base = {
            "acceleration": u,
            "velocity": (1 - np.cos(w * t)) / w,
            "displacement": t / w - np.sin(w * t) / w**2,
        }[quantity]
        expected = expected + base[:, None]  # the base starts from rest: exact integrals
    settled = t > 5.0  # five seconds is > 40 time constants of the slowest mode
    scale = np.abs(expected[settled]).max()
    np.testing.assert_allclose(y[settled], expected[settled], atol=STEADY_STATE_RTOL * scale)


def test_relative_plus_base_is_absolute_acceleration():
    s = am.chapter2_system()
    u = am.sine_sweep(100.0, 10.0)
    for hold in ("zoh", "bandlimited"):
        absolute = am.simulate(s, u, 100.0, hold=hold)
        relative = am.simulate(s, u, 100.0, hold=hold, frame="relative")
        np.testing.assert_allclose(relative + u[:, None], absolute, atol=1e-10 * np.abs(absolute).max())


def test_random_vibration_band_rms_and_seed():
    fs = 60.0
    x = am.random_vibration(fs, 120.0, (0.5, 28.0), rms=2.0, seed=7)
    assert x.shape == (7200,)
    np.testing.assert_allclose(np.sqrt(np.mean(x**2)), 2.0)
    spec = np.abs(np.fft.rfft(x)) ** 2
    freqs = np.fft.rfftfreq(x.size, 1 / fs)
    outside = (freqs < 0.5) | (freqs > 28.0)
    assert spec[outside].sum() < 1e-20 * spec.sum()
    np.testing.assert_array_equal(x, am.random_vibration(fs, 120.0, (0.5, 28.0), rms=2.0, seed=7))
    assert not np.array_equal(x, am.random_vibration(fs, 120.0, (0.5, 28.0), rms=2.0, seed=8))


def test_sine_sweep_frequency_and_power_rise():
    fs = 60.0
    x = am.sine_sweep(fs, 120.0, 0.5, 20.0, amplitude=2.0)
    analytic = scipy.signal.hilbert(x)
    inst_f = np.diff(np.unwrap(np.angle(analytic))) * fs / (2 * np.pi)
    t = np.arange(x.size - 1) / fs
    mid = (t > 10) & (t < 110)
    np.testing.assert_allclose(inst_f[mid], 0.5 + 19.5 * t[mid] / 120.0, atol=0.05)
    env = np.abs(analytic)[:-1]
    assert env[(t > 100) & (t < 110)].mean() > 4 * env[(t > 10) & (t < 20)].mean()
    assert abs(x[0]) < 1e-12 and abs(x[-1]) < 1e-2


def test_noise_level_and_determinism():
    s = am.supine_human()
    u = am.random_vibration(60.0, 60.0, seed=2)
    clean = am.simulate(s, u, 60.0)
    rec = am.simulate_recording(s, u, 60.0, noise=0.05, seed=4)
    again = am.simulate_recording(s, u, 60.0, noise=0.05, seed=4)
    np.testing.assert_allclose(rec.response, again.response, rtol=1e-12, atol=0)  # the seed fixes the noise
    ratio = np.std(rec.response - clean, axis=0) / np.sqrt(np.mean(clean**2, axis=0))
    np.testing.assert_allclose(ratio, 0.05, rtol=0.05)
    np.testing.assert_array_equal(rec.base, u)  # no input noise asked for


def test_bad_simulation_input():
    s = am.supine_human()
    u = am.random_vibration(60.0, 5.0, seed=1)
    u[10] = np.nan
    with pytest.raises(DataError, match="NaN"):
        am.simulate(s, u, 60.0)
    with pytest.raises(ValueError, match="hold"):
        am.simulate(s, np.ones(10), 60.0, hold="foh")
    with pytest.raises(DataError, match="fs"):
        am.simulate(s, np.ones(10), -1.0)
