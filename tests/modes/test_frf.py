"""The modal model against the measured FRF: the reconstruction error separates a complete
selection from one missing modes, and a clear coherent peak no selected mode explains is named."""

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays
from scipy.signal import find_peaks

import armaxmodal as am
from armaxmodal.modes.diagram import stabilisation_diagram
from armaxmodal.modes.frf import unexplained_peaks
from armaxmodal.modes.pipeline import select_modes
from armaxmodal.modes.settings import PEAK_RESOLUTION
from armaxmodal.spectra import peak_prominences, resolving_nperseg


@pytest.fixture(scope="module")
def supine(fixtures_dir):
    rec = am.read_recording(fixtures_dir / "supine_random.csv")
    return select_modes(stabilisation_diagram(rec, range(2, 31, 2)))


def test_the_error_separates_a_complete_selection_from_an_incomplete_one(supine):
    from armaxmodal.modes.modal_check import check_modes

    rec, m = supine.diagram.recording, supine.modes
    full = check_modes(rec, m.freq_hz, m.damping)
    assert full.overall_error < 0.02 and supine.reconstruction_error == full.overall_error
    for keep in ([0, 1], [0, 2, 3], [1, 2, 3]):
        assert check_modes(rec, m.freq_hz[keep], m.damping[keep]).overall_error > 0.08
    # heavily damped modes make no prominent peak of their own: nothing is called unexplained
    assert not [w for w in supine.warnings if w.code == "unexplained_peak"]


@pytest.fixture(scope="module")
def light(light_ride):
    return light_ride


def test_a_missing_lightly_damped_mode_is_named_at_its_frequency(light):
    s, rec = light
    modes = s.modes()
    assert np.all(modes.damping < 0.02)
    res = PEAK_RESOLUTION
    n = resolving_nperseg(rec, modes.freq_hz, modes.damping, res.lines_per_bandwidth, res.min_segments)
    assert n >= 512  # lines fine enough for 1 % damping
    assert unexplained_peaks(rec, modes.freq_hz, modes.damping) == []
    (w,) = unexplained_peaks(rec, modes.freq_hz[:1], modes.damping[:1])
    assert w.code == "unexplained_peak" and w.value == pytest.approx(modes.damped_freq_hz[1], rel=0.01)
    assert set(w.channels) == {"m1", "m2"}


def test_mode_support_merges_a_fake_split_and_keeps_real_close_modes(light, fixtures_dir):
    from armaxmodal.modes.frf import mode_support, overlapping_neighbour
    from armaxmodal.modes.modal_check import check_modes

    def support(rec, f, x, m):
        return mode_support(rec, f, x, m, check_modes(rec, f, x))

    # one lightly damped peak given two modes 1 % apart: the FRF does not need the second
    s, rec = light
    m = s.modes()
    f = np.r_[m.freq_hz[0], 1.01 * m.freq_hz[0], m.freq_hz[1]]
    x = np.r_[m.damping[0], m.damping[0], m.damping[1]]
    assert overlapping_neighbour(f, x, 1) == 0 and overlapping_neighbour(f, x, 2) is None
    fake = support(rec, f, x, 1)
    assert fake.refitted_neighbour == 0 and not fake.needed and fake.rise < 0.01
    # each true mode of that record is needed many times over
    assert min(support(rec, m.freq_hz, m.damping, k).rise for k in range(2)) > 0.5
    # two real modes within each other's half-power band (4.57 and 4.92 Hz, 4 %): both needed
    c = am.Structure.from_chain([10.0, 10.0], [8000.0, 9000.0], [25.0, 25.0], [400.0], [0.0], ("a", "b"))
    mc = c.modes()
    assert overlapping_neighbour(mc.freq_hz, mc.damping, 0) == 1
    u = am.random_vibration(50.0, 240.0, (0.5, 24.0), seed=5)
    rc = am.simulate_recording(c, u, 50.0, noise=0.05, seed=6, hold="bandlimited")
    for k in range(2):
        real = support(rc, mc.freq_hz, mc.damping, k)
        assert real.needed and real.p_value < 1e-10
    # the supine human's heavily damped modes all overlap their neighbours; each is needed
    sup = am.read_recording(fixtures_dir / "supine_random.csv")
    t = am.supine_human().modes()
    assert all(overlapping_neighbour(t.freq_hz, t.damping, k) is not None for k in range(4))
    assert all(support(sup, t.freq_hz, t.damping, k).needed for k in range(4))


def test_the_count_takes_a_fake_split_out_and_keeps_real_close_modes(light):
    """The one keep-or-drop: one lightly damped peak started as two modes 1 % apart comes out as
    one, and so does one started with a 20 %-damped pole 15 % above it (as measured beside the
    stiff 1-storey model's storey mode); two real modes within each other's half-power band (4.57
    and 4.92 Hz) stay two."""
    from armaxmodal.estimate.dft_model import DftLines
    from armaxmodal.modes.count_search import count_modes

    s, rec = light
    m = s.modes()
    f = np.r_[m.freq_hz[0], 1.01 * m.freq_hz[0], m.freq_hz[1]]
    x = np.r_[m.damping[0], m.damping[0], m.damping[1]]
    halves = tuple(DftLines.from_recording(h, (0.5, 24.0)) for h in rec.split(2))
    split = count_modes(DftLines.from_recording(rec, (0.5, 24.0)), f, x, hold="bandlimited", halves=halves)
    kept = split.model.freq_hz[split.verdicts() == "needed"]
    np.testing.assert_allclose(np.sort(kept), m.freq_hz, rtol=0.005)
    f[1], x[1] = 1.15 * m.freq_hz[0], 0.2
    wide = count_modes(DftLines.from_recording(rec, (0.5, 24.0)), f, x, hold="bandlimited", halves=halves)
    np.testing.assert_allclose(np.sort(wide.model.freq_hz[wide.verdicts() == "needed"]), m.freq_hz, rtol=0.005)
    c = am.Structure.from_chain([10.0, 10.0], [8000.0, 9000.0], [25.0, 25.0], [400.0], [0.0], ("a", "b"))
    mc = c.modes()
    assert abs(mc.freq_hz[1] - mc.freq_hz[0]) < mc.damping @ mc.freq_hz  # the half-power bands overlap
    rc = am.simulate_recording(c, am.random_vibration(50.0, 240.0, (0.5, 24.0), seed=5), 50.0, noise=0.05, seed=6,
                               hold="bandlimited")  # fmt: skip
    halves = tuple(DftLines.from_recording(h, (0.5, 24.0)) for h in rc.split(2))
    close = count_modes(DftLines.from_recording(rc, (0.5, 24.0)), mc.freq_hz, mc.damping, hold="bandlimited",
                        halves=halves)  # fmt: skip
    assert (close.verdicts() == "needed").sum() == 2
    np.testing.assert_allclose(np.sort(close.model.freq_hz), mc.freq_hz, rtol=0.01)


@given(
    arrays(np.float64, st.integers(0, 80), elements=st.integers(0, 4).map(float))
    | arrays(np.float64, st.integers(0, 80), elements=st.floats(-1e3, 1e3, allow_nan=False))
)
def test_peak_prominences_equal_scipy_find_peaks(x):
    """Our peak finder (it spares every run scipy.signal's import) against scipy's, on
    plateau-rich integer data and on arbitrary floats."""
    peaks, props = find_peaks(x, prominence=0.0)
    ours, prominences = peak_prominences(x)
    np.testing.assert_array_equal(ours, peaks)
    np.testing.assert_allclose(prominences, props["prominences"], rtol=0, atol=0)
