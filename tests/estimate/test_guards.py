"""Direct tests of small pieces whose plausible bugs the end-to-end tests let through (a
deliberate-bug check of the suite killed 4 of 10): the delta-method pole uncertainty, the
output-error gradient, the MAC, the rejection ceiling, the nb rule, the zoh residue map."""

import json

import numpy as np
import pandas as pd
import pytest

import armaxmodal as am
import armaxmodal.estimate._gauss_newton as gn
import armaxmodal.estimate.fit as fitmod
import armaxmodal.estimate.parameters as parameters_mod
import armaxmodal.estimate.pem as pem_mod
import armaxmodal.estimate.starts as starts_mod
from armaxmodal.estimate.orders import default_nb
from armaxmodal.modal import discrete_modal_parameters, mac, pole_uncertainty
from armaxmodal.modes.poles import Tolerances, rejection_reasons
from armaxmodal.modes.state import refine_modes
from armaxmodal.spectra import excited_band

FS = 60.0


def _poles_after(a, fs):
    mu = np.roots(a)
    return mu[mu.imag > 0]


def test_pole_uncertainty_equals_the_finite_difference_propagation():
    rng = np.random.default_rng(4)
    lam = 2 * np.pi * np.array([-0.25 * 5.8 + 5.6j, -0.3 * 13.5 + 12.9j])
    mu = np.exp(np.r_[lam, lam.conj()] / FS)
    a = np.real(np.poly(mu))
    m = rng.standard_normal((4, 4))
    cov = 1e-8 * (m @ m.T + 4 * np.eye(4))
    base = _poles_after(a, FS)
    f0, x0, _ = discrete_modal_parameters(base, FS)
    jac_f, jac_x = np.zeros((2, 4)), np.zeros((2, 4))
    h = 1e-7
    for i in range(4):
        d = np.zeros(5)
        d[i + 1] = h
        fu, xu, _ = discrete_modal_parameters(_poles_after(a + d, FS), FS)
        fd, xd, _ = discrete_modal_parameters(_poles_after(a - d, FS), FS)
        order_u = [int(np.argmin(np.abs(fu - f))) for f in f0]
        order_d = [int(np.argmin(np.abs(fd - f))) for f in f0]
        jac_f[:, i] = (fu[order_u] - fd[order_d]) / (2 * h)
        jac_x[:, i] = (xu[order_u] - xd[order_d]) / (2 * h)
    sd_f, sd_x = pole_uncertainty(a, base, cov, FS)
    np.testing.assert_allclose(sd_f, np.sqrt(np.einsum("ki,ij,kj->k", jac_f, cov, jac_f)), rtol=1e-4)
    np.testing.assert_allclose(sd_x, np.sqrt(np.einsum("ki,ij,kj->k", jac_x, cov, jac_x)), rtol=1e-4)


def test_output_error_gradient_is_exact(fixtures_dir):
    rec = am.read_recording(fixtures_dir / "supine_random.csv")
    y = np.ascontiguousarray(rec.response[:1500, 0])
    u_t = np.ascontiguousarray(rec.base[None, :1500])
    na, nb, nc, nk = 4, 5, 0, 0
    t0, t1 = na + nb, y.size
    theta = starts_mod.hannan_rissanen(y, u_t, na, nb, 2, nk, t0, t1)[: na + nb]
    eps, _, c = pem_mod.residual_and_loss(y, u_t, theta, na, nb, nc, nk, t0, t1, oe=True)
    _, g = gn.normal_equations(y, u_t, eps, c, gn.columns(na, nb, nc, nk, 1), t0, t1, oe=True)
    numeric = np.zeros_like(theta)
    h = 1e-7
    for i in range(theta.size):
        step = np.zeros_like(theta)
        step[i] = h
        up = pem_mod.residual_and_loss(y, u_t, theta + step, na, nb, nc, nk, t0, t1, oe=True)[1]
        down = pem_mod.residual_and_loss(y, u_t, theta - step, na, nb, nc, nk, t0, t1, oe=True)[1]
        numeric[i] = (up - down) / (2 * h)
    np.testing.assert_allclose(-2 * g, numeric, rtol=0, atol=1e-4 * np.abs(numeric).max())


def test_mac_is_one_for_any_complex_scaling_and_is_conjugate_symmetric():
    rng = np.random.default_rng(1)
    a = rng.standard_normal(4) + 1j * rng.standard_normal(4)
    assert mac(a, a * (0.3 - 2.1j)) == pytest.approx(1.0, abs=1e-12)
    b = rng.standard_normal(4) + 1j * rng.standard_normal(4)
    expect = abs(np.sum(np.conj(a) * b)) ** 2 / (np.sum(np.abs(a) ** 2) * np.sum(np.abs(b) ** 2))
    assert mac(a, b) == pytest.approx(expect, rel=1e-12) and mac(b, a) == pytest.approx(expect, rel=1e-12)
    assert mac(a, np.conj(a)) < 0.99  # a complex shape is not its own conjugate
    assert mac(a, np.zeros(4)) == 0.0


def test_rejection_rules_and_their_ceiling(fixtures_dir):
    rec = am.read_recording(fixtures_dir / "supine_random.csv")
    tol = Tolerances()
    rows = [
        (8.0, 0.30, 1.0, ""),
        (8.0, 0.59, 1.0, ""),
        (8.0, 0.61, 1.0, "over-damped"),  # the 0.6 ceiling, not 1.0
        (8.0, -0.01, 1.0, "negative damping"),
        (8.0, 0.0, 1.0, "negative damping"),  # an undamped pole pair is a line, not a mode
        (0.01, 0.2, 1.0, "near 0 Hz"),
        (27.5, 0.05, 1.0, "near Nyquist"),
        (8.0, 0.3, 0.005, "negligible residue"),
    ]
    poles = pd.DataFrame(
        [{"source": "shared", "na": 10, "freq_hz": f, "damping": x, "energy": e} for f, x, e, _ in rows]
    )
    assert rejection_reasons(poles, tol, rec) == [r[3] for r in rows]


@pytest.mark.parametrize("na, nk, nb", [(10, 0, 11), (10, -5, 16), (8, -1, 10), (8, 3, 9)])
def test_default_nb_keeps_na_plus_one_causal_taps_plus_one_per_noncausal_step(na, nk, nb):
    assert default_nb(na, nk) == nb


def test_zoh_refit_shapes_match_the_exact_modal_constants(fixtures_dir):
    rec = am.read_recording(fixtures_dir / "supine_random_zoh.csv")
    truth = json.loads((fixtures_dir / "supine_random_zoh.truth.json").read_text())["modes"]
    f = np.array([m["freq_hz"] for m in truth])
    x = np.array([m["damping"] for m in truth])
    ref = refine_modes(rec, f * 1.01, x * 1.05, band_hz=excited_band(rec), hold="zoh")
    want = np.array(
        [
            [m["shape"][s]["mag"] * np.exp(1j * np.radians(m["shape"][s]["phase_deg"])) for m in truth]
            for s in rec.sensors
        ]
    )
    # absolute scale, not normalised: the zoh map r = R mu lambda / (mu - 1) sets magnitude and phase
    modal = am.supine_human().modes().modal_constants
    assert np.max(np.abs(ref.shapes - modal) / np.abs(modal).max(axis=0)) < 0.08
    got = ref.shapes / ref.shapes[np.argmax(np.abs(ref.shapes), axis=0), np.arange(4)]
    want = want / want[np.argmax(np.abs(want), axis=0), np.arange(4)]
    assert np.max(np.abs(got - want)) < 0.06


def test_mode_record_normalises_the_shape_and_keeps_the_supplemented_flags():
    from types import SimpleNamespace

    from armaxmodal.modal import mode_record

    row = SimpleNamespace(freq_hz=5.0, damping=0.2, damped_freq_hz=4.9, freq_ci95_lo=4.8, freq_ci95_hi=5.2,
                          damping_ci95_lo=0.1, damping_ci95_hi=0.3)  # fmt: skip
    shape = np.array([0.5j, -2.0 + 0j, 1.0 + 1.0j])
    rec = mode_record(row, shape, ("a", "b", "c"), np.array([False, True, False]))
    assert rec["shape"]["b"] == {"mag": 1.0, "phase_deg": 0.0, "supplemented": True}
    assert rec["shape"]["a"]["mag"] == pytest.approx(0.25) and rec["shape"]["a"]["phase_deg"] == pytest.approx(-90.0)
    assert rec["shape"]["c"]["supplemented"] is False
    assert rec["freq_ci95"] == [4.8, 5.2] and rec["damping_ci95"] == [0.1, 0.3]
    assert (rec["freq_hz"], rec["damping"], rec["damped_freq_hz"]) == (5.0, 0.2, 4.9)
    zero = mode_record(row, np.zeros(3, complex), ("a", "b", "c"))
    assert all(v["mag"] == 0.0 for v in zero["shape"].values())  # no division by a zero component


def test_thesis_equations_agree_with_the_log_map_at_the_nyquist_edge():
    from armaxmodal.modal import thesis_frequency_damping

    # a pole on the negative real axis (the Nyquist frequency) and one just inside it
    mu = np.array([-0.5 + 0j, 0.3 * np.exp(1j * np.pi * (1 - 1e-6))])
    f, x = thesis_frequency_damping(mu, 0.01)
    f_ref, x_ref, _ = discrete_modal_parameters(mu, 100.0)
    np.testing.assert_allclose(f, f_ref, rtol=1e-9)
    np.testing.assert_allclose(x, x_ref, rtol=1e-9)


def test_continuous_parameters_of_slow_zero_and_real_axis_poles():
    from armaxmodal.modal import continuous_modal_parameters, discrete_to_continuous

    f, x, fd = continuous_modal_parameters(np.array([-0.1 + 0.5j, 0j]))  # |lambda| < 1 rad/s, and 0
    assert x[0] == pytest.approx(0.1 / np.hypot(0.1, 0.5)) and f[0] == pytest.approx(np.hypot(0.1, 0.5) / (2 * np.pi))
    assert np.isnan(x[1]) and f[1] == 0.0 and fd[0] == pytest.approx(0.5 / (2 * np.pi))
    # a real negative discrete pole given as a float is still the Nyquist-frequency pole
    lam = discrete_to_continuous(np.array([-0.5]), 100.0)
    assert lam[0] == pytest.approx(100.0 * (np.log(0.5) + 1j * np.pi))


def _shared_problem(fixtures_dir, oe=False):
    """Three sensors of the supine ride at (4, 5, 3, 1) with shared poles, at a start point."""
    rec = am.read_recording(fixtures_dir / "supine_random.csv")
    ys = [np.ascontiguousarray(rec.response[:1200, k]) for k in range(3)]
    u_t = np.ascontiguousarray(rec.base[None, :1200])
    na, nb, nc, nk = 4, 5, 0 if oe else 3, 1
    t0, t1 = max(na, nc, nk + nb - 1), 1200
    p_k = nb + nc
    cols = gn.columns(na, nb, nc, nk, 1)
    parts = [starts_mod.hannan_rissanen(y, u_t, na, nb, 3, nk, t0, t1)[: na + p_k] for y in ys]
    start = np.concatenate([parts[0][:na]] + [p[na:] for p in parts])
    theta = parameters_mod.project_shared_stable(start, na, nb, nc, 1, 3, oe)

    def residuals(th):
        return [
            pem_mod.residual_and_loss(
                ys[k], u_t, parameters_mod.local_parameters(th, k, na, p_k), na, nb, nc, nk, t0, t1, oe
            )
            for k in range(3)
        ]

    variances = np.array([0.7, 1.3, 2.1]) * np.mean([np.var(y) for y in ys])
    normal = gn.shared_normal_equations(ys, u_t, residuals(theta), variances, cols, na, p_k, t0, t1, oe)
    return theta, residuals, variances, normal, (t0, t1)


@pytest.mark.parametrize("oe", [False, True])
def test_shared_pole_gradient_and_gauss_newton_matrix_are_exact(fixtures_dir, oe):
    """The block-arrow normal equations of the shared-pole fit against finite differences:
    the gradient of sum_k V_k / lambda_k, and J'WJ from the numerical Jacobian of the
    prediction errors (a wrong Gram block, weight or sign fails this)."""
    theta, residuals, variances, normal, (t0, t1) = _shared_problem(fixtures_dir, oe)
    h = 1e-6
    grad = np.zeros_like(theta)
    jac = [np.zeros((t1 - t0, theta.size)) for _ in variances]
    for i in range(theta.size):
        step = np.zeros_like(theta)
        step[i] = h
        up, down = residuals(theta + step), residuals(theta - step)
        grad[i] = sum((u[1] - d[1]) / (2 * h) / v for u, d, v in zip(up, down, variances, strict=True))
        for k in range(len(variances)):
            jac[k][:, i] = (up[k][0][t0:t1] - down[k][0][t0:t1]) / (2 * h)
    np.testing.assert_allclose(-2 * normal.gradient, grad, rtol=0, atol=1e-5 * np.abs(grad).max())
    gauss_newton = sum(j.T @ j / v for j, v in zip(jac, variances, strict=True))
    np.testing.assert_allclose(normal.full(), gauss_newton, rtol=0, atol=1e-5 * np.abs(gauss_newton).max())


def test_the_schur_solve_equals_the_dense_damped_solve(fixtures_dir):
    """The block-arrow LM step (Schur complement on the shared A block) and its curvature
    against the dense system with the same diagonal damping."""
    _, _, _, normal, _ = _shared_problem(fixtures_dir)
    dense = normal.full()
    for damping in (0.0, 1e-3, 10.0):
        expected = np.linalg.solve(gn._damped(dense, damping), normal.gradient)
        np.testing.assert_allclose(normal.solve(damping), expected, rtol=1e-7, atol=1e-12 * np.abs(expected).max())
    step = np.random.default_rng(2).standard_normal(dense.shape[0])
    assert normal.curvature(step) == pytest.approx(step @ dense @ step, rel=1e-10)


def test_pole_rows_of_a_shared_and_a_single_sensor_fit(fixtures_dir):
    """The diagram's pole rows (``pole_rows``) against the fit's own mode table: every column
    carried over, the shared shape from each sensor's residue, the energies as defined."""
    from armaxmodal.modes.poles import POLE_COLUMNS, pole_rows

    rec = am.read_recording(fixtures_dir / "supine_random.csv")
    rec = am.Recording(rec.fs, rec.base[:2400], rec.response[:2400, :2], rec.sensors[:2])
    shared = fitmod.fit_armax(rec, 4, 5, 4, 0, shared_poles=True)
    table = shared.modes()
    first = table[table.sensor == rec.sensors[0]].reset_index(drop=True)
    rows = pole_rows(shared, "shared")
    assert len(rows) == len(first) == 2
    for row, (_, ref) in zip(rows, first.iterrows(), strict=True):
        assert list(row) == POLE_COLUMNS and row["source"] == "shared" and row["na"] == 4
        for col in POLE_COLUMNS[2:-3]:  # freq_hz .. damping_ci95_hi
            assert row[col] == ref[col], col
        assert row["pole"] == ref["pole"]
        lam = np.log(ref.pole) * rec.fs  # Eq. 3.24 from the discrete residue R: M = -R fs / lambda^2
        residues = [table[(table.sensor == s) & (table.pole == ref.pole)].residue.item() for s in rec.sensors]
        own = [-r * rec.fs / lam**2 for r in residues]
        np.testing.assert_allclose(row["vector"], own, rtol=1e-10)
        assert row["energy"] == pytest.approx(np.linalg.norm(np.asarray(own) * ref.freq_hz), rel=1e-10)
    single = fitmod.fit_armax(rec.select([rec.sensors[1]]), 4, 5, 4, 0)
    ref = single.modes()
    rows = pole_rows(single, rec.sensors[1])
    assert len(rows) == len(ref) >= 1
    for row, (_, r) in zip(rows, ref.iterrows(), strict=True):
        assert row["source"] == rec.sensors[1] and row["freq_hz"] == r.freq_hz and row["damping_sd"] == r.damping_sd
        const = -r.residue * rec.fs / (np.log(r.pole) * rec.fs) ** 2
        np.testing.assert_allclose(row["vector"], [const], rtol=1e-10)
        assert row["energy"] == pytest.approx(abs(const) * r.freq_hz, rel=1e-10)


def test_solves_fall_back_to_least_squares_where_cholesky_fails():
    """An indefinite or singular system (a fit broken down numerically) takes the
    least-squares / pseudo-inverse path, and that path solves the same damped system."""
    a = np.array([[2.0, 0.0, 1.0], [0.0, -1.0, 0.5], [1.0, 0.5, 3.0]])  # indefinite
    g = np.array([1.0, -2.0, 0.5])
    for damping in (0.0, 0.1):
        expected = np.linalg.lstsq(gn._damped(a, damping), g, rcond=None)[0]
        np.testing.assert_allclose(gn.solve(a, g, damping), expected, rtol=1e-12)
    singular = np.array([[1.0, 1.0], [1.0, 1.0]])
    np.testing.assert_allclose(gn.inverse(singular), np.linalg.pinv(singular), rtol=1e-12)
    spd = np.array([[4.0, 1.0], [1.0, 3.0]])
    np.testing.assert_allclose(gn.inverse(spd), np.linalg.inv(spd), rtol=1e-12)
    # the block-arrow step with an indefinite sensor block equals the dense damped solve
    arrow = gn._Arrow(
        aa=np.array([[5.0, 0.3], [0.3, 4.0]]),
        ab=[np.array([[0.2, 0.1, 0.0], [0.0, 0.3, 0.1]])] * 2,
        bb=[a, np.eye(3) * 2.0],
        ga=np.array([1.0, 0.5]),
        gb=[g, -g],
    )
    for damping in (0.0, 0.1):
        expected = np.linalg.lstsq(gn._damped(arrow.full(), damping), arrow.gradient, rcond=None)[0]
        np.testing.assert_allclose(arrow.solve(damping), expected, rtol=1e-9, atol=1e-12)


def test_damping_scales_by_the_diagonal_and_non_finite_systems_are_an_order_error():
    from armaxmodal.exceptions import OrderError

    g = np.array([[4.0, 1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, -2.0]])
    damped = gn._damped(g, 0.5)
    # 0.5 x the diagonal where it is positive, 0.5 x 1 where it is not, plus a 1e-13 ridge
    np.testing.assert_allclose(np.diag(damped), [4.0 + 2.0 + 4e-13, 0.5 + 1e-13, -2.0 + 0.5 + 1e-13], rtol=1e-15)
    np.testing.assert_array_equal(damped - np.diag(np.diag(damped)), g - np.diag(np.diag(g)))
    with pytest.raises(OrderError, match=r"normal equations became non-finite.*Lower the orders\.$"):
        gn._damped(np.array([[np.nan, 0.0], [0.0, 1.0]]), 0.1)
