import numpy as np
import pytest

import armaxmodal as am
from armaxmodal.modal import modal_frf
from armaxmodal.spectra import measured_frf

# Normalised random error of an H1 magnitude (Bendat & Piersol): sqrt(1 - g^2) / (|g| sqrt(2 nd)).
# Welch with 50 % overlap: count independent averages conservatively as half the segments.
# Allow four of those standard errors per bin plus 0.5 % for bias (window, leakage).
SIGMAS = 4.0
BIAS = 0.005


def test_modal_sum_rebuilds_the_transmissibility_exactly():
    s = am.supine_human()
    m = s.modes()
    f = np.linspace(0.2, 29.0, 200)
    rebuilt = modal_frf(f, m.freq_hz, m.damping, m.modal_constants)
    np.testing.assert_allclose(rebuilt, s.transmissibility(f), rtol=1e-9, atol=1e-12)


def test_h1_estimate_matches_the_exact_transmissibility():
    s = am.supine_human()
    u = am.random_vibration(60.0, 120.0, (0.5, 28.0), seed=3)
    rec = am.simulate_recording(s, u, 60.0, noise=0.01, seed=4, hold="bandlimited")
    f, h, coh = measured_frf(rec)
    nperseg = 2 * (f.size - 1)
    n_segments = (rec.n_samples - nperseg) // (nperseg // 2) + 1
    band = (f > 1.0) & (f < 27.0)
    exact = s.transmissibility(f[band])
    g2 = coh[band]
    bound = SIGMAS * np.sqrt(1 - g2) / (np.sqrt(g2) * np.sqrt(2 * n_segments / 2)) + BIAS
    assert np.all(np.abs(h[band] - exact) / np.abs(exact) < bound)


def test_h1_relative_error_matches_the_scatter_around_the_true_transmissibility(fixtures_dir):
    """Bendat & Piersol's random error of H1, from the coherence, against the actual scatter
    of the H1 estimate around the exact transmissibility of the simulated ride."""
    from armaxmodal.spectra import default_nperseg, h1_relative_error, measured_frf

    rec = am.read_recording(fixtures_dir / "supine_random.csv")
    f, h, coh = measured_frf(rec)
    keep = (f > 0.5) & (np.min(coh, axis=1) >= 0.8)
    sigma = h1_relative_error(coh[keep], rec.n_samples, default_nperseg(rec))
    ratio = h[keep] / am.supine_human().transmissibility(f[keep])
    part_sd = np.tile(sigma.ravel() / np.sqrt(2), 2)  # log magnitude and phase, each
    z = np.concatenate([np.log(np.abs(ratio)).ravel(), np.angle(ratio).ravel()]) / part_sd
    assert 0.8 < np.sqrt(np.mean(z**2)) < 1.25


@pytest.mark.parametrize("nperseg", [256, 301])
def test_welch_spectra_equal_scipy_welch_and_csd(nperseg):
    import scipy.signal

    from armaxmodal.spectra import welch_spectra

    rng = np.random.default_rng(3)
    u = rng.standard_normal(5000) + 0.3
    y = np.column_stack([np.convolve(u, [0.5, 1.0, -0.2])[:5000], rng.standard_normal(5000)])
    f, puu, puy, pyy = welch_spectra(u, y, 60.0, nperseg)
    f_ref, puu_ref = scipy.signal.welch(u, 60.0, nperseg=nperseg)
    np.testing.assert_allclose(f, f_ref, rtol=1e-14)
    np.testing.assert_allclose(puu, puu_ref, rtol=1e-10)
    for k in range(2):
        np.testing.assert_allclose(puy[:, k], scipy.signal.csd(u, y[:, k], 60.0, nperseg=nperseg)[1], rtol=1e-10)
        np.testing.assert_allclose(pyy[:, k], scipy.signal.welch(y[:, k], 60.0, nperseg=nperseg)[1], rtol=1e-10)


def test_model_simulation_equals_lfilter():
    import scipy.signal

    from armaxmodal.armax import ArmaxModel

    rng = np.random.default_rng(4)
    u = rng.standard_normal(2000)
    a = np.array([2.0, -2.4, 1.6])  # not monic: B/A is normalised as lfilter does
    model = ArmaxModel(a, np.array([[0.3, 0.2, 0.1]]), np.array([1.0]), 1, 100.0)
    expected = scipy.signal.lfilter(np.r_[0.0, 0.3, 0.2, 0.1], a, u)
    np.testing.assert_allclose(model.simulate(u), expected, rtol=1e-10, atol=1e-12)


def test_segment_longer_than_the_record_is_a_clear_error(fixtures_dir):
    from armaxmodal.exceptions import DataError

    rec = am.read_recording(fixtures_dir / "supine_random.csv")
    with pytest.raises(DataError, match="nperseg"):
        measured_frf(rec, nperseg=rec.n_samples + 1)


def test_a_recording_computes_its_spectra_once_per_segment_length():
    """A recording keeps its Welch spectra: the same segment length gives the very same
    (read-only) arrays, another gives new ones, each equal to a fresh computation; a record
    made from it (another object) computes its own."""
    from dataclasses import replace

    from armaxmodal.recording import Recording
    from armaxmodal.spectra import welch_segments, welch_spectra

    rng = np.random.default_rng(4)
    u, y = rng.standard_normal(4000), rng.standard_normal((4000, 3))
    rec = Recording(50.0, u, y)
    first = rec.welch(256)
    assert all(a is b for a, b in zip(first, rec.welch(256), strict=True))
    assert not any(a.flags.writeable for a in first)
    for got, fresh in zip(first, welch_spectra(u, y, 50.0, 256), strict=True):
        np.testing.assert_array_equal(got, fresh)
    assert rec.welch(512)[0].size == 257
    changed = replace(rec, response=y + np.eye(4000, 3)[:, ::-1] * 1e-3)
    assert changed.welch(256)[2] is not first[2] and not np.array_equal(changed.welch(256)[2], first[2])
    f, uf, yf, scale = welch_segments(u, y, 50.0, 256)
    np.testing.assert_array_equal(first[1], scale * np.mean(np.abs(uf) ** 2, axis=0))
    np.testing.assert_array_equal(first[2], scale[:, None] * np.mean(np.conj(uf)[:, :, None] * yf, axis=0))


def test_other_metadata_keeps_the_spectra_and_wrong_metadata_is_refused(fixtures_dir):
    from armaxmodal.exceptions import DataError
    from armaxmodal.spectra import welch_spectra

    rec = am.read_recording(fixtures_dir / "supine_random.csv")
    first = rec.welch(512)
    renamed = rec.with_meta({"subject": "S1"})
    assert renamed.meta == {"subject": "S1"} and renamed.fs == rec.fs
    assert renamed.welch(512)[2] is first[2]  # shared, not recomputed
    # and they are the record's spectra
    np.testing.assert_array_equal(renamed.welch(512)[2], welch_spectra(rec.base, rec.response, rec.fs, 512)[2])
    with pytest.raises(DataError, match="meta: expected a dict"):
        rec.with_meta("subject S1")
