"""Frequency-domain refit of selected modes under the inter-sample behaviour."""

import json

import numpy as np
import pytest

import armaxmodal as am
from armaxmodal.modes.state import refine_modes
from armaxmodal.spectra import excited_band


def _start(fixtures_dir, name):
    """Truth perturbed by 3 % in frequency and 15 % in damping: a start the selection could give."""
    truth = json.loads((fixtures_dir / f"{name}.truth.json").read_text())["modes"]
    f = np.array([m["freq_hz"] for m in truth])
    x = np.array([m["damping"] for m in truth])
    signs = np.array([1, -1, 1, -1])
    return f, x, f * (1 + 0.03 * signs), x * (1 - 0.15 * signs)


@pytest.mark.parametrize(
    "name, hold", [("supine_sweep", "bandlimited"), ("supine_random", "bandlimited"), ("supine_random_zoh", "zoh")]
)
def test_the_data_choose_the_hold_and_the_refit_finds_the_modes(fixtures_dir, name, hold):
    rec = am.read_recording(fixtures_dir / f"{name}.csv")
    f, x, f0, x0 = _start(fixtures_dir, name)
    ref = refine_modes(rec, f0, x0, band_hz=excited_band(rec))
    assert ref.hold == hold
    assert ref.hold_cost[hold] < ref.hold_cost[{"zoh": "bandlimited", "bandlimited": "zoh"}[hold]]
    # within the targets, and the errors consistent with the reported uncertainty
    assert np.all(np.abs(ref.freq_hz / f - 1) < 0.02) and np.all(np.abs(ref.damping / x - 1) < 0.10)
    assert np.all(np.abs(ref.freq_hz - f) < 4 * ref.freq_sd) and np.all(np.abs(ref.damping - x) < 4 * ref.damping_sd)


def test_the_refit_reports_the_modes_in_the_order_they_were_given(fixtures_dir):
    """The selection's rows and shapes are matched to the refit by position: a start from the
    highest mode down comes back from the highest mode down, each mode where it belongs."""
    rec = am.read_recording(fixtures_dir / "supine_random.csv")
    f, x, f0, x0 = _start(fixtures_dir, "supine_random")
    ref = refine_modes(rec, f0[::-1], x0[::-1], band_hz=excited_band(rec), hold="bandlimited")
    np.testing.assert_allclose(ref.freq_hz, f[::-1], rtol=0.02)
    np.testing.assert_allclose(ref.damping, x[::-1], rtol=0.10)


def test_where_a_few_steps_do_not_decide_the_hold_both_are_converged():
    """A held ride of the five-segment body with feet, started from dampings 50 % high: after four
    steps the band-limited form leads by 8.9, less than the count's decisive 10, so both forms are
    converged, and there the held one is lower by far and finds the exact dampings. Decided on the
    four steps alone (``decisive=0``), the band-limited form is taken and its dampings are biased."""
    body = am.supine_with_feet()
    exact = body.modes()
    ride = am.simulate_recording(body, am.random_vibration(60.0, 120.0, (0.5, 24.0), seed=1), 60.0, noise=0.03, seed=2)
    start = (exact.freq_hz, 1.5 * exact.damping)
    ref = refine_modes(ride, *start, band_hz=(0.5, 24.0))
    assert ref.hold == "zoh" and ref.hold_cost["bandlimited"] - ref.hold_cost["zoh"] > 10.0  # converged costs
    assert np.all(np.abs(ref.damping - exact.damping) < 4 * ref.damping_sd)
    assert np.all(np.abs(ref.freq_hz - exact.freq_hz) < 4 * ref.freq_sd)
    hasty = refine_modes(ride, *start, band_hz=(0.5, 24.0), decisive=0.0)
    assert hasty.hold == "bandlimited" and abs(hasty.hold_cost["zoh"] - hasty.hold_cost["bandlimited"]) < 10.0
    assert np.any(np.abs(hasty.damping - exact.damping) > 4 * hasty.damping_sd)  # what the rule prevents
    # from the exact modes four steps decide (by hundreds): only the chosen form is converged
    f, x = exact.freq_hz, exact.damping
    near, steps = (refine_modes(ride, f, x, band_hz=(0.5, 24.0), decisive=d) for d in (10.0, 0.0))
    assert near.hold_cost == steps.hold_cost
    assert near.hold == "zoh" and near.hold_cost["bandlimited"] - near.hold_cost["zoh"] > 100.0


def test_refit_shapes_match_the_exact_modal_constants(fixtures_dir):
    rec = am.read_recording(fixtures_dir / "supine_random.csv")
    f, x, f0, x0 = _start(fixtures_dir, "supine_random")
    ref = refine_modes(rec, f0, x0, band_hz=excited_band(rec), hold="bandlimited")
    # EPFRF modal constants -r / lambda^2, compared with magnitude and phase (unit largest component)
    truth = json.loads((fixtures_dir / "supine_random.truth.json").read_text())["modes"]
    want = np.array(
        [
            [m["shape"][s]["mag"] * np.exp(1j * np.radians(m["shape"][s]["phase_deg"])) for m in truth]
            for s in rec.sensors
        ]
    )
    got = ref.shapes / ref.shapes[np.argmax(np.abs(ref.shapes), axis=0), np.arange(4)]
    want = want / want[np.argmax(np.abs(want), axis=0), np.arange(4)]
    assert np.max(np.abs(got - want)) < 0.06


def test_bad_hold_is_refused(fixtures_dir):
    rec = am.read_recording(fixtures_dir / "supine_random.csv")
    with pytest.raises(ValueError, match="hold"):
        refine_modes(rec, [5.8], [0.25], band_hz=(0.5, 28.0), hold="foh")


def test_too_few_lines_for_the_modes_is_a_clear_error(fixtures_dir):
    from armaxmodal.exceptions import OrderError

    rec = am.read_recording(fixtures_dir / "supine_random.csv")
    with pytest.raises(OrderError, match=r"DFT lines in 5(\.0\d*)?-5\.1\d* Hz cannot fit 4 modes"):
        refine_modes(rec, [5.8, 8.3, 13.5, 16.2], [0.25, 0.35, 0.3, 0.27], band_hz=(5.0, 5.1))


@pytest.mark.parametrize("hold", ["bandlimited", "zoh"])
def test_variable_projection_jacobian_matches_finite_differences(fixtures_dir, hold):
    from scipy.optimize._numdiff import approx_derivative

    model = _supine_model(fixtures_dir, hold)
    x = np.ravel(np.column_stack([np.log(2 * np.pi * np.array([5.8, 8.3, 13.5, 16.2])), [0.25, 0.33, 0.3, 0.27]]))
    analytic = model.jacobian(x)
    numeric = approx_derivative(model.residual, x, method="3-point")
    assert np.max(np.abs(analytic - numeric)) < 1e-6 * np.max(np.abs(numeric))


def _supine_model(fixtures_dir, hold):
    from armaxmodal._separable import SeparableModel as _SeparableModel

    rec = am.read_recording(fixtures_dir / "supine_random.csv")
    dt = 1 / rec.fs
    freq = np.fft.rfftfreq(rec.n_samples, dt)
    lines = (freq >= 0.5) & (freq <= 28)
    w = 2 * np.pi * freq[lines]
    y = np.fft.rfft(rec.response, axis=0)[lines]
    return _SeparableModel(1j * w, np.exp(-1j * w * dt), np.fft.rfft(rec.base)[lines], y / np.abs(y).mean(0), dt, hold)


@pytest.mark.parametrize("hold", ["bandlimited", "zoh"])
def test_the_compressed_fit_takes_the_full_problems_steps(fixtures_dir, hold):
    """The fitter hands scipy ``n + 1`` rows built from the normal equations instead of one row
    per line (memory and time): the normal equations, the gradient and the cost are the full
    problem's at every point, so the solver lands where the full problem's does, from a start
    3 % off."""
    import scipy.optimize

    from armaxmodal._separable import GramCompressed

    model = _supine_model(fixtures_dir, hold)
    small = GramCompressed(model)
    log_wn = np.log(2 * np.pi * np.array([5.83, 8.31, 13.50, 16.25]))
    truth = np.ravel(np.column_stack([log_wn, [0.26, 0.35, 0.3, 0.27]]))
    start = truth * np.array([1.005, 0.9, 0.995, 1.1, 1.005, 0.9, 0.995, 1.1])
    j, r = model.jacobian(start), model.residual(start).copy()
    jc, rc = small.jacobian(start), small.residual(start)
    assert jc.shape == (start.size + 1, start.size) and rc.shape == (start.size + 1,)
    assert np.allclose(jc.T @ jc, j.T @ j, rtol=1e-10, atol=1e-10 * np.abs(j.T @ j).max())
    assert np.allclose(jc.T @ rc, j.T @ r, rtol=1e-9, atol=1e-9 * np.abs(j.T @ r).max())
    assert rc @ rc == pytest.approx(r @ r, rel=1e-12)
    # the rows a sensor at a time (the sandwich's blocks), interleaved, are the full Jacobian's
    rows = list(model.sensor_rows(start))
    interleaved = np.stack([jk for jk, _ in rows], axis=1).reshape(j.shape)
    assert np.allclose(interleaved, j, rtol=0, atol=1e-12 * np.abs(j).max())
    assert np.array_equal(np.column_stack([rk for _, rk in rows]).ravel(), r)
    bounds = (np.tile([np.log(2 * np.pi * 0.5), 1e-4], 4), np.tile([np.log(2 * np.pi * 30.0), 0.95], 4))
    options = {"x_scale": "jac", "max_nfev": 60, "xtol": 1e-12, "ftol": 1e-12, "bounds": bounds}
    full = scipy.optimize.least_squares(model.residual, start, jac=model.jacobian, **options)
    compressed = scipy.optimize.least_squares(small.residual, start, jac=small.jacobian, **options)
    # (to 1e-5 in log frequency and damping: on the zoh assumption one damping sits at its
    # bound and its mode's frequency is flat to 1e-5 there, where rounding decides)
    assert np.allclose(compressed.x, full.x, rtol=0, atol=1e-5)
    assert compressed.cost == pytest.approx(full.cost, rel=1e-9)


def test_sandwich_errors_equal_statsmodels_hc1_on_a_linear_regression():
    """White's HC1 covariance of a heteroscedastic linear regression, against statsmodels."""
    import statsmodels.api as sm

    from armaxmodal.stats import sandwich_sd as _sandwich_sd

    rng = np.random.default_rng(3)
    x = np.column_stack([np.ones(400), rng.standard_normal(400), rng.uniform(0, 3, 400)])
    y = x @ [0.5, -1.0, 2.0] + rng.standard_normal(400) * (0.1 + x[:, 2])  # noise grows with x3
    fit = sm.OLS(y, x).fit(cov_type="HC1")
    got = _sandwich_sd([(x[:20], fit.resid[:20]), (x[20:], fit.resid[20:])], 3)
    np.testing.assert_allclose(got, fit.bse, rtol=1e-10)
    # the pooled-variance errors differ here: the test can tell the two apart
    assert np.max(np.abs(sm.OLS(y, x).fit().bse / fit.bse - 1)) > 0.1


def test_refit_errors_agree_with_the_armax_bound_on_held_data():
    """On a held (zoh) ride both estimators are efficient: the refit's standard errors sit
    near the shared-pole ARMAX fit's delta-method errors at the true orders (lightly damped
    modes, 1-2 %). Both ratios within a factor of two: a pooled variance, a dropped square
    or a divided scale in the sandwich fall outside it."""
    s = am.Structure.from_chain([10.0, 5.0], [8000.0, 0.0], [8.0, 0.0], [12000.0], [5.0], ("m1", "m2"))
    u = am.random_vibration(50.0, 120.0, (0.5, 24.0), seed=3)
    rec = am.simulate_recording(s, u, 50.0, noise=0.05, seed=4, hold="zoh")
    m = s.modes()
    ref = refine_modes(rec, m.freq_hz, m.damping, band_hz=excited_band(rec), hold="zoh")
    armax = am.fit_armax(rec, 4, 5, 4, 0, shared_poles=True, warn=False).modes()
    armax = armax[armax.sensor == rec.sensors[0]].sort_values("freq_hz")
    ratio_f = ref.freq_sd / armax.freq_sd.to_numpy()
    ratio_x = ref.damping_sd / armax.damping_sd.to_numpy()
    assert np.all((ratio_f > 0.5) & (ratio_f < 2.0)), ratio_f
    assert np.all((ratio_x > 0.5) & (ratio_x < 2.0)), ratio_x


@pytest.mark.parametrize("hold", ["bandlimited", "zoh"])
def test_the_modal_kernels_equal_their_column_by_column_references(hold):
    """The basis, the pole slopes and ``-dA/dx coef`` from the kernels, against numpy built a
    column at a time (tests/naive.py), on random lines, poles and coefficients."""
    from armaxmodal._kernels import modal_basis, modal_moved
    from armaxmodal._separable import pole_derivatives as _pole_derivatives
    from tests import naive

    rng = np.random.default_rng(7)
    dt, lines, n, sensors = 0.01, 300, 3, 4
    w = np.sort(rng.uniform(1, 150, lines))
    s, z_inv, u = 1j * w, np.exp(-1j * w * dt), rng.standard_normal(lines) + 1j * rng.standard_normal(lines)
    x = np.ravel(np.column_stack([np.log(rng.uniform(10, 120, n)), rng.uniform(0.01, 0.3, n)]))
    lam = -x[1::2] * np.exp(x[0::2]) + 1j * np.exp(x[0::2]) * np.sqrt(1 - x[1::2] ** 2)
    basis, slopes = np.empty((2 * lines, 4 * n + 2), order="F"), np.empty((4, n, lines), complex)
    modal_basis(s, z_inv, u, lam, dt, hold == "bandlimited", basis, slopes)
    want_basis, want_slopes = naive.modal_basis(s, z_inv, u, lam, dt, hold == "bandlimited")
    np.testing.assert_allclose(basis, want_basis, rtol=1e-12, atol=1e-12 * np.abs(want_basis).max())
    np.testing.assert_allclose(slopes, want_slopes, rtol=1e-12)
    alpha, beta = (rng.standard_normal((n, sensors)) + 1j * rng.standard_normal((n, sensors)) for _ in range(2))
    moved = np.empty((2 * lines, sensors, 2 * n))
    modal_moved(slopes, alpha, beta, _pole_derivatives(x), moved)
    want = naive.modal_moved(want_slopes, alpha, beta, _pole_derivatives(x))
    np.testing.assert_allclose(moved, want, rtol=1e-12, atol=1e-12 * np.abs(want).max())


@pytest.mark.parametrize(("case", "formed"), [("plain", False), ("at_nyquist", False), ("close pair", True)])
def test_the_normal_equations_equal_those_of_the_jacobians_rows(fixtures_dir, case, formed):
    """``J'J``, ``J'r`` and ``|r|^2`` without the rows equal those of the formed Jacobian, with the
    basis left implicit (``Q = basis R^-1``) and, where two poles 2 % apart condition it past one
    pass of its Gram matrix, with ``Q`` formed; also where a fit has put an undamped pole at the
    Nyquist frequency (30 Hz for this 60 Hz ride, as a count's fit did): its slope lies almost in
    the basis and the difference of squares alone kept no digit of its diagonal, so the rows are
    formed there, and only there."""
    model = _supine_model(fixtures_dir, "bandlimited")
    freq, damping = {"plain": ([5.8, 8.3, 13.5, 16.2], [0.26, 0.35, 0.3, 0.27]),
                     "at_nyquist": ([5.8, 8.3, 13.5, 16.2, 30.0], [0.26, 0.35, 0.3, 0.27, 1e-4]),
                     "close pair": ([5.8, 5.9, 13.5], [0.26, 0.26, 0.3])}[case]  # fmt: skip
    x = np.ravel(np.column_stack([np.log(2 * np.pi * np.array(freq)), damping]))
    j, r = model.jacobian(x), model.residual(x).copy()
    rows, sensor_rows = [], model.sensor_rows
    model.sensor_rows = lambda at: rows.append(at) or sensor_rows(at)
    gram, grad, power = model.normal_equations(x)
    assert model.formed == formed and bool(rows) == (case == "at_nyquist")
    np.testing.assert_allclose(gram, j.T @ j, rtol=1e-8, atol=1e-10 * np.abs(j.T @ j).max())
    np.testing.assert_allclose(grad, j.T @ r, rtol=1e-6, atol=1e-9 * np.abs(j.T @ r).max())
    assert power == pytest.approx(r @ r, rel=1e-12)


#: orthonormal to rounding: LAPACK's Householder QR of a 2,000 x 12 matrix is within a few 1e-15
ORTHONORMAL = 1e-13


@pytest.mark.parametrize("condition", [1.0, 30.0, 90.0, 1e3, 1e5, 1e7])
def test_the_modal_bases_orthonormal_factor_is_a_qr_at_every_conditioning(condition):
    """``orthonormal_basis`` against the definition of a QR factorisation, on columns of very
    unequal norms (as the plant and transient columns are): a well conditioned basis through one
    pass of its Gram matrix (orthonormal to about condition^2 x eps), a less well conditioned one
    through two, and one conditioned beyond ``CHOLESKY_QR_MAX_CONDITION`` still orthonormal to
    rounding (the Gram route alone would lose 2 log10(1e7) = 14 digits of it, and one pass of it 10
    at 1e5: a one-pass limit set too high fails here)."""
    from armaxmodal._linalg import CHOLESKY_QR_MAX_CONDITION, orthonormal_basis

    rng = np.random.default_rng(3)
    left, _ = np.linalg.qr(rng.standard_normal((2000, 12)))
    right, _ = np.linalg.qr(rng.standard_normal((12, 12)))
    a = left @ np.diag(np.geomspace(1.0, 1.0 / condition, 12)) @ right * np.geomspace(1e-3, 1e4, 12)
    q, r = orthonormal_basis(np.asfortranarray(a))
    assert (condition > CHOLESKY_QR_MAX_CONDITION) == (condition == 1e7)  # both routes are tried
    # one pass is allowed to 100 only (``ONE_PASS_MAX_CONDITION``): beyond, rounding's orthonormality
    one_pass = 10 * condition**2 * np.finfo(float).eps if condition <= 100.0 else 0.0
    np.testing.assert_allclose(q.T @ q, np.eye(12), atol=max(ORTHONORMAL, one_pass))
    np.testing.assert_allclose(q @ r, a, rtol=0, atol=1e-13 * np.abs(a).max())
    assert np.allclose(r, np.triu(r))
    if condition <= CHOLESKY_QR_MAX_CONDITION:  # the Gram route's R (Householder's has diagonal signs of its own)
        assert np.all(np.diag(r) > 0)


def test_normal_equations_that_lost_their_definiteness_are_formed_from_the_rows():
    """Where the difference of squares leaves ``J'J`` indefinite (two poles nearly one: a count's
    split screening stopped on it), the compressed problem asks for the rows' normal equations
    instead of failing; where those are indefinite too, the error stands."""
    from types import SimpleNamespace

    from armaxmodal._separable import GramCompressed

    lost, formed = np.array([[1.0, 1.0 + 1e-6], [1.0 + 1e-6, 1.0]]), np.array([[1.0, 0.5], [0.5, 1.0]])
    asked = []

    def normal_equations(x, rows=False):
        asked.append((tuple(x), rows))
        return (formed if rows else lost), np.array([0.3, 0.4]), 1.0

    compressed = GramCompressed(SimpleNamespace(normal_equations=normal_equations))
    jac, res = compressed.jacobian(np.array([0.5, 0.1])), compressed.residual(np.array([0.5, 0.1]))
    assert asked == [((0.5, 0.1), False), ((0.5, 0.1), True)]  # once each, at the point asked
    np.testing.assert_allclose(jac[:2].T @ jac[:2], formed, rtol=1e-10)
    np.testing.assert_allclose(jac[:2].T @ res[:2], [0.3, 0.4], rtol=1e-10)
    assert res @ res == pytest.approx(1.0)
    with pytest.raises(np.linalg.LinAlgError):
        GramCompressed(SimpleNamespace(normal_equations=lambda x, rows=False: (lost, np.ones(2), 1.0))).residual(
            np.zeros(2))


def test_a_null_direction_of_the_normal_equations_stays_solvable_at_any_scale():
    """The compressed problem's Cholesky factor takes a ridge of 1e-12 of the mean diagonal: two
    parameters that move the residual alike (rank one, ``J'J`` only semi-definite) are still
    factored, whatever the units make of the scale."""
    from armaxmodal._linalg import ridged_cholesky

    for scale in (1.0, 1e8):
        gram = scale * np.ones((2, 2))
        r = ridged_cholesky(gram)
        np.testing.assert_allclose(r.T @ r, gram, rtol=1e-9)
        assert np.all(np.diag(r) > 0)
