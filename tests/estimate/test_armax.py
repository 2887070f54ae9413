import numpy as np
import scipy.signal

import armaxmodal as am
from armaxmodal.armax import ArmaxModel
from armaxmodal.systems.simulation import exact_armax

RTOL = 1e-10


def _model(nk):
    return ArmaxModel(
        np.array([1.0, -1.1, 0.6, -0.1]), np.array([[0.3, -0.2, 0.5, 0.1]]), np.array([1.0, 0.2]), nk, 50.0
    )


def test_residues_match_scipy_residuez():
    m = _model(0)
    r, p, _ = scipy.signal.residuez(m.b[0], m.a)
    ours = m.residues(p)[0]
    np.testing.assert_allclose(ours, r, rtol=1e-8)


def test_delay_multiplies_residues_by_pole_power():
    base, delayed = _model(0), _model(2)
    mu = base.poles()
    np.testing.assert_allclose(delayed.residues(mu), base.residues(mu) * mu**-2, rtol=RTOL)
    # and the partial fractions rebuild the transfer function up to its polynomial part
    r, p, k = scipy.signal.residuez(np.r_[0.0, 0.0, delayed.b[0]], delayed.a)
    np.testing.assert_allclose(np.sort_complex(delayed.residues(p)[0]), np.sort_complex(r), rtol=1e-8)


def test_frf_matches_freqz_and_simulation_matches_lfilter():
    for nk in (0, 2, -2):
        m = _model(nk)
        f = np.linspace(0.1, 24.9, 50)
        num = m.b[0]
        _, h = scipy.signal.freqz(num, m.a, worN=f, fs=50.0)
        np.testing.assert_allclose(m.frf(f)[:, 0], h * np.exp(-2j * np.pi * f / 50.0 * nk), rtol=RTOL)
    u = np.random.default_rng(0).standard_normal(300)
    m = _model(1)
    np.testing.assert_allclose(m.simulate(u), scipy.signal.lfilter(np.r_[0.0, m.b[0]], m.a, u), rtol=RTOL, atol=1e-12)


def test_prediction_plus_error_is_the_output():
    m = _model(0)
    rng = np.random.default_rng(1)
    u, y = rng.standard_normal(200), rng.standard_normal(200)
    np.testing.assert_allclose(m.predict(y, u) + m.prediction_errors(y, u), y, rtol=RTOL)


def test_exact_model_of_a_structure_gives_table_4_3_and_its_modal_constants():
    s = am.supine_human()
    truth = s.modes()
    models = exact_armax(s, 60.0)
    u = am.random_vibration(60.0, 30.0, seed=5)
    y = am.simulate(s, u, 60.0)
    mu = np.exp(truth.eigenvalues / 60.0)
    for k, m in enumerate(models):
        np.testing.assert_allclose(m.simulate(u), y[:, k], atol=1e-10 * np.abs(y).max())
        _, f, xi, _ = m.modal_parameters()
        np.testing.assert_allclose(f, truth.freq_hz, rtol=1e-8)
        np.testing.assert_allclose(xi, truth.damping, rtol=1e-8)
        np.testing.assert_allclose(m.modal_constants(mu, hold="zoh")[0], truth.modal_constants[k], rtol=1e-7)
