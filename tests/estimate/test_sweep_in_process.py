"""The sweep and the selection run in this process (``n_jobs=1``) on a short two-mode ride.

Fast (about a second each), and one thread, so a mutation tool can tell which test reaches
the delay choice, the sweep's jobs, the finishing fits and the segment refits. Each test
runs its own sweep (a shared fixture would credit only the first test with reaching the
sweep). Every check is against the structure's exact modes, a slow reference
written out here with :func:`fit_armax`, or the same sweep over worker threads.
"""

import numpy as np
import pandas as pd
import pytest

import armaxmodal as am
from armaxmodal.estimate.orders import default_nb, default_nc, information_criterion
from armaxmodal.modes.diagram import (
    DELAY_CHOICE_ORDERS,
    NK_EXTENSION,
    NK_SEARCH,
    SAMPLES_PER_PARAMETER,
    SWEEP_TOL,
    _choose_nk,
    _job_cost,
    choose_nk,
    deepest_delay,
    stabilisation_diagram,
    sweep_fit,
)
from armaxmodal.modes.intervals import N_SEGMENTS
from armaxmodal.modes.pipeline import select_modes
from armaxmodal.modes.poles import SHARED
from armaxmodal.recording import Recording

ORDERS = range(2, 11, 2)
PER_SENSOR_MAX = 6


def _two_mode_ride(seconds: float = 60.0, seed: int = 3) -> tuple[am.Structure, Recording]:
    """Two modes, 3.53 and 9.95 Hz at 5-6 % damping, a held input at 50 Hz."""
    s = am.Structure.from_chain([10.0, 5.0], [8000.0, 0.0], [40.0, 0.0], [12000.0], [20.0], ("m1", "m2"))
    u = am.random_vibration(50.0, seconds, (0.5, 24.0), seed=seed)
    return s, am.simulate_recording(s, u, 50.0, noise=0.05, seed=seed + 1)


def _late_input(rec: Recording, lag: int) -> Recording:
    """The same ride with the input channel recorded ``lag`` samples late (outputs lead)."""
    return Recording(rec.fs, rec.base[:-lag], rec.response[lag:], rec.sensors, rec.input_name)


@pytest.fixture(scope="module")
def ride():
    return _two_mode_ride()


def _diagram(rec: Recording, **options):
    return stabilisation_diagram(rec, ORDERS, per_sensor_max_order=PER_SENSOR_MAX, n_jobs=1, **options)


@pytest.fixture
def diagram(ride):
    return _diagram(ride[1])


def _reference_nk(rec: Recording, nk_values, na_values=(8, 10, 12)) -> int:
    """The delay choice written out: the lowest BIC over every (na, nk) candidate."""
    best = None
    for na in na_values:
        for nk in nk_values:
            fit = am.fit_armax(
                rec, na, default_nb(na, nk), default_nc(na), nk,
                shared_poles=True, max_iter=8, tol=SWEEP_TOL, stop="decrease", warn=False,
            )  # fmt: skip
            score = information_criterion(fit)
            if best is None or score < best[0]:
                best = (score, nk)
    return best[1]


def test_the_delay_is_the_lowest_bic_one(ride, diagram):
    rec = diagram.recording
    nk = diagram.orders[0][3]
    # the true delay is 1 (no feed-through, see below); the search starts at 0, one tap early
    assert nk == _reference_nk(rec, NK_SEARCH) == 0
    assert choose_nk(rec, n_jobs=1) == nk
    assert [o for o in diagram.orders] == [(na, default_nb(na, nk), default_nc(na), nk) for na in ORDERS]


def test_the_delay_choice_fits_stop_at_their_cap(ride):
    """``choose_delay``'s fits run ``max_iter`` iterations and no more: continued to 2 in all, the
    checkpoint of a 1-iteration choice is the fresh 2-iteration fit, not a converged one."""
    from armaxmodal._threads import one_blas_thread
    from armaxmodal.estimate.orders import choose_delay

    rec = ride[1]
    with one_blas_thread():
        nk, checkpoints = choose_delay(rec, (0, -1), (4,), max_iter=1, tol=SWEEP_TOL, n_jobs=1)
        ((orders, checkpoint),) = checkpoints.items()
        assert orders == (4, default_nb(4, nk), default_nc(4), nk)
        continued = sweep_fit(rec, (SHARED, orders, checkpoint), 2, SWEEP_TOL)[0]
        options = {"shared_poles": True, "tol": SWEEP_TOL, "stop": "decrease", "warn": False}
        fresh, converged = (am.fit_armax(rec, *orders, max_iter=n, **options) for n in (2, 30))
    assert _same_fit(continued, fresh) and not _same_fit(fresh, converged)


def test_the_diagram_computes_each_orders_criterion_once(diagram):
    """The clustering and the FRF screen read one ``{na: BIC}`` of the shared fits, in each output's
    mean square, made on first use: the criterion the delay choice ranks fits by."""
    from armaxmodal.estimate.orders import output_mean_squares

    unit = output_mean_squares(diagram.recording)
    expected = {na: information_criterion(diagram.fits[(SHARED, na)], unit=unit) for na in ORDERS}
    assert diagram.order_bic == expected and diagram.order_bic is diagram.order_bic
    assert min(expected, key=expected.get) == 4  # two modes: the lowest order that holds them


def _same_fit(a, b) -> bool:
    """The same fit up to rounding: the same iteration count and stop, every coefficient and
    loss to 1e-7 and the joint covariance to 1e-4 of its largest entry. Not bit for bit: a
    continued fit computes on arrays allocated elsewhere, and on some CPUs the BLAS and SIMD
    reductions round differently with alignment (seen in CI: coefficients 1e-8 apart, a
    covariance the ill-conditioned inverse moved by 1e-5). A continuation that loses any of
    its state (the damping, its growth, the crawl count, the variances) lands 1e-4 or more
    away or stops at another iteration."""
    if not all(np.array_equal(getattr(a, k), getattr(b, k)) for k in ("iterations", "converged")):
        return False
    for ma, mb in zip(a.models, b.models, strict=True):
        for k in "abc":
            x, y = getattr(ma, k), getattr(mb, k)
            if not np.allclose(x, y, rtol=1e-7, atol=1e-7 * np.max(np.abs(y))):
                return False
    if not np.allclose(a.loss, b.loss, rtol=1e-7, atol=0):
        return False
    ca, cb = np.asarray(a.joint_covariance), np.asarray(b.joint_covariance)
    return ca.shape == cb.shape and np.allclose(ca, cb, rtol=0, atol=1e-4 * max(np.max(np.abs(cb), initial=0), 1e-300))


def test_the_sweep_continues_the_delay_choice_fits_exactly(ride):
    """The delay choice hands the sweep where each of its fits at the chosen delay stopped
    (after at most 8 iterations); continued in the sweep, each is the fit the sweep would
    have made from the start (to rounding, :func:`_same_fit`)."""
    from armaxmodal._threads import one_blas_thread
    from armaxmodal.modes.diagram import _choose_nk

    rec = ride[1]
    with one_blas_thread():
        nk, checkpoints = _choose_nk(rec, NK_SEARCH, (4, 6), 1, deepest=deepest_delay(rec, 6))
        assert nk == 0
        assert sorted(checkpoints) == [(SHARED, (na, default_nb(na, nk), default_nc(na), nk)) for na in (4, 6)]
        for job, checkpoint in checkpoints.items():
            continued = sweep_fit(rec, job + (checkpoint,), 30, SWEEP_TOL)[0]
            fresh = am.fit_armax(
                rec, *job[1], shared_poles=True, max_iter=30, tol=SWEEP_TOL, stop="decrease", warn=False
            )
            assert _same_fit(continued, fresh)


@pytest.mark.parametrize(
    ("na", "cap", "stop", "where"),
    [
        (6, 3, "decrease", "mid-run"),
        (8, 8, "decrease", "mid-run"),
        (4, 5, "decrease", "between runs"),
        (4, 8, "decrease", "converged"),
        (10, 25, "expected", "crawling"),  # two floor-damped small steps counted, of the three that stop it
    ],
)
def test_a_fit_stopped_by_its_cap_continues_exactly(ride, na, cap, stop, where):
    """Stopped after ``cap`` iterations -- mid-way through a Levenberg-Marquardt run, while
    crawling, between two runs of the noise-variance alternation, or converged -- and
    continued to 30, a shared-pole fit equals the fit capped at 30 from the start
    (:func:`_same_fit`): the damping, the crawl count and the variances weighting the run
    are all carried over."""
    from armaxmodal._threads import one_blas_thread
    from armaxmodal.estimate.fit import fit_resumable

    rec = ride[1]
    options = {"shared_poles": True, "tol": SWEEP_TOL if stop == "decrease" else 1e-9, "stop": stop, "warn": False}
    orders = (na, default_nb(na, -1), default_nc(na), -1)
    with one_blas_thread():
        short, checkpoint = fit_resumable(rec, orders, max_iter=cap, covariance=False, **options)
        fresh = fit_resumable(rec, orders, max_iter=30, **options)[0]
        continued = fit_resumable(rec, orders, max_iter=30, resume=checkpoint, **options)[0]
    progress = checkpoint.progress
    kind = "converged" if checkpoint.converged else "between runs" if progress is None else "mid-run"
    if progress is not None and progress.crawling:
        kind = "crawling"
    assert kind == where and short.covariance == ()
    assert fresh.iterations[0] > cap or kind == "converged"
    assert _same_fit(continued, fresh)


def test_a_late_input_past_the_search_range_is_found_by_the_extension(ride):
    """Outputs 8 samples ahead of the input: the best delay lies beyond the searched 0..-6,
    so the search looks further. An absolute acceleration has no direct feed-through
    of the base acceleration (the springs and dampers pass it on), so a held input's true
    delay is one sample, and with the input 8 samples late it is -7."""
    late = _late_input(ride[1], 8)
    assert min(NK_SEARCH) > -8
    nk = choose_nk(late, n_jobs=1)
    assert nk == _reference_nk(late, range(min(NK_SEARCH), min(NK_SEARCH) - 4, -1)) == 1 - 8
    # the extension goes NK_EXTENSION = 3 further while its choice sits at its end: 11 samples late,
    # twice (to -9, then -12), and holds the lead at -10
    late = _late_input(ride[1], 11)
    assert choose_nk(late, n_jobs=1) == 1 - 11
    # ... down to the most non-causal delay the record supports at the sweep's top order, where it stops
    assert _choose_nk(late, NK_SEARCH, DELAY_CHOICE_ORDERS, 1, deepest=-9)[0] == -9
    assert deepest_delay(late, 12) == 37 - late.n_samples // SAMPLES_PER_PARAMETER
    # a narrower search that does not reach the edge is not extended
    assert choose_nk(_late_input(ride[1], 2), nk_values=range(0, -5, -1), n_jobs=1) == 1 - 2


def test_the_delay_choice_and_the_selection_show_their_progress(ride, capsys):
    """On a long ride the delay choice and the selection take as long as the sweep: each
    shows its own bar. The delay choice's extension has a bar of its own (the input 8 samples
    late sends it past the searched edge, left unaligned: 21 fits, then 12 more), so that no
    bar's total grows under the user's eyes."""
    late = _late_input(ride[1], 8)
    d = stabilisation_diagram(late, ORDERS, per_sensor=False, align=False, n_jobs=1, progress=True)
    searched = len(NK_SEARCH) * len(DELAY_CHOICE_ORDERS)
    extended = (NK_EXTENSION + 1) * len(DELAY_CHOICE_ORDERS)
    bars = capsys.readouterr().err
    assert "input delay choice: 100%" in bars and f"{searched}/{searched}" in bars
    assert f"input delay choice beyond nk = {min(NK_SEARCH)}: 100%" in bars and f"{extended}/{extended}" in bars
    totals = {int(line.split("/")[1].split()[0]) for line in bars_of(bars) if line.startswith("input delay choice:")}
    assert totals == {searched}  # no total grew
    select_modes(d, n_jobs=1, progress=True)
    counts = [line for line in bars_of(capsys.readouterr().err) if line.startswith("mode selection:")]
    # at least one finishing fit, the refit and a representative order's segment refits
    assert counts and int(counts[-1].split(":")[1].split("fit")[0]) >= 2 + N_SEGMENTS


def bars_of(err: str) -> list[str]:
    """The lines a tqdm bar drew (it redraws in place with carriage returns)."""
    return [line.strip() for line in err.replace("\r", "\n").splitlines() if line.strip()]


def test_the_sweep_fits_every_source_and_order_it_should(ride, diagram):
    rec = diagram.recording
    expected = {(SHARED, na) for na in ORDERS} | {(s, na) for s in rec.sensors for na in ORDERS if na <= PER_SENSOR_MAX}
    assert set(diagram.fits) == expected
    for (source, na), fit in diagram.fits.items():
        assert fit.orders == diagram.orders[list(ORDERS).index(na)]
        assert fit.shared_poles == (source == SHARED)
        assert fit.n_samples > 0 and len(fit.models) == (len(rec.sensors) if source == SHARED else 1)
        # a fit the delay choice stopped at its 8-iteration cap must not stand in the sweep
        assert fit.converged.all() or (fit.iterations >= 30).any(), (source, na, fit.iterations)
    # every pole row belongs to a fit of the sweep, and every fit's poles are in the table
    by_fit = diagram.poles.groupby(["source", "na"]).size()
    assert set(by_fit.index) == expected
    for (source, na), count in by_fit.items():
        pairs = np.sum(np.imag(diagram.fits[(source, na)].models[0].poles()) > 0)
        assert count == pairs, (source, na)
    # the shared poles of the true modes are stable in all three and kept, from the second
    # order that holds both modes on
    shared = diagram.poles[(diagram.poles.source == SHARED) & (diagram.poles.na >= 6)]
    for f in ride[0].modes().freq_hz:
        near = shared[np.abs(shared.freq_hz / f - 1) < 0.01]
        assert len(near) == len([na for na in ORDERS if na >= 6]), f
        assert set(near.cls) == {"f+d+v"} and set(near.rejected) == {""}, near[["na", "cls", "rejected"]]


def test_workers_and_this_process_give_the_same_diagram(ride, diagram):
    threaded = stabilisation_diagram(ride[1], ORDERS, per_sensor_max_order=PER_SENSOR_MAX, n_jobs=2)
    cols = ["source", "na", "freq_hz", "damping", "cls", "rejected"]
    pd.testing.assert_frame_equal(threaded.poles[cols], diagram.poles[cols])


def test_the_in_process_selection_gives_the_exact_modes(ride, diagram):
    s, _ = ride
    truth = s.modes()
    sel = select_modes(diagram, n_jobs=1)
    f, x = sel.modes.freq_hz.to_numpy(), sel.modes.damping.to_numpy()
    assert len(f) == 2
    assert np.all(np.abs(f / truth.freq_hz - 1) < 0.005), f
    assert np.all(np.abs(x / truth.damping - 1) < 0.15), x
    # the reported values are a converged fit's at the representative order, not the
    # sweep's early-stopped one: a fit from scratch agrees within a tenth of an SE
    rec = diagram.recording
    for m in sel.modes.itertuples():
        full = am.fit_armax(rec, *diagram.fits[(SHARED, m.na)].orders, shared_poles=True).modes()
        full = full[full.sensor == rec.sensors[0]]
        j = int(np.argmin(np.abs(full.freq_hz.to_numpy() - m.freq_hz)))
        assert abs(full.freq_hz.iloc[j] - m.freq_hz) < 0.1 * full.freq_sd.iloc[j]
        assert abs(full.damping.iloc[j] - m.damping) < 0.1 * full.damping_sd.iloc[j]


def test_the_segment_spread_is_that_of_refits_on_thirds(diagram):
    sel = select_modes(diagram, n_jobs=1, refine=False)
    rec = diagram.recording
    n = rec.n_samples // 3
    for m in sel.modes.itertuples():
        orders = diagram.fits[(SHARED, m.na)].orders
        found = []
        for k in range(3):
            part = Recording(rec.fs, rec.base[k * n : (k + 1) * n], rec.response[k * n : (k + 1) * n], rec.sensors)
            modes = am.fit_armax(part, *orders, shared_poles=True, max_iter=30, warn=False).modes()
            modes = modes[(modes.sensor == rec.sensors[0]) & (modes.damping > 0)]
            found.append(modes.iloc[int(np.argmin(np.abs(modes.freq_hz - m.freq_hz)))])
        assert m.segments_found == 3
        assert m.freq_segment_sd == pytest.approx(np.std([p.freq_hz for p in found], ddof=1), rel=0.02)
        assert m.damping_segment_sd == pytest.approx(np.std([p.damping for p in found], ddof=1), rel=0.05)
        # the model is right here: the spread does not dominate the statistical interval
        assert not m.model_error_dominates


def test_one_sweep_job_fits_its_own_source(diagram):
    rec = diagram.recording
    orders = diagram.orders[1]
    single, no_checkpoint = sweep_fit(rec, (rec.sensors[1], orders), 30, SWEEP_TOL)
    assert no_checkpoint is None  # only shared-pole fits are continued
    alone = am.fit_armax(rec.select([rec.sensors[1]]), *orders, max_iter=30, tol=SWEEP_TOL, stop="decrease")
    assert not single.shared_poles and len(single.models) == 1
    np.testing.assert_allclose(single.models[0].a, alone.models[0].a, rtol=1e-9, atol=1e-12)
    shared, checkpoint = sweep_fit(rec, (SHARED, orders), 30, SWEEP_TOL)
    assert shared.shared_poles and len(shared.models) == len(rec.sensors)
    assert checkpoint.iterations <= shared.iterations[0]
    assert np.array_equal(checkpoint.theta[: orders[0]], shared.models[0].a[1:])
    # orders the record cannot carry are skipped, not raised
    assert sweep_fit(rec, (SHARED, (400, 401, 400, 0)), 30, SWEEP_TOL) == (None, None)


def test_job_cost_scales_with_order_and_sensors():
    assert _job_cost((SHARED, (10, 11, 10, 0)), 4) == 40
    assert _job_cost(("head", (10, 11, 10, 0)), 4) == 10
    assert _job_cost(("head", (6, 7, 6, -2)), 4) == 6
    assert _job_cost((SHARED, (10, 11, 10, 0), None), 4) == 40  # a continued fit


def _late_channel(rec: Recording, k: int, lag: int) -> Recording:
    """Output ``k`` recorded ``lag`` samples late."""
    y = rec.response[lag:].copy()
    y[:, k] = rec.response[:-lag, k]
    return Recording(rec.fs, rec.base[lag:], y, rec.sensors, rec.input_name)


def test_by_default_a_late_sensor_is_aligned_and_sensors_stop_at_order_20(ride, capsys):
    late = _late_channel(ride[1], 1, 3)
    d = stabilisation_diagram(late, (2, 4, 20, 21, 22), n_jobs=1, progress=True)
    assert d.preparation.shifts == {"m2": 3}
    aligned, want = d.recording.response[:, 1], late.response[3 : 3 + d.recording.n_samples, 1]
    np.testing.assert_allclose(aligned - aligned.mean(), want - want.mean(), atol=1e-9)
    assert {na for (src, na) in d.fits if src != SHARED} == {2, 4, 20}
    assert {na for (src, na) in d.fits if src == SHARED} == {2, 4, 20, 21, 22}
    assert max(int(f.iterations.max()) for f in d.fits.values()) <= 30
    bar = capsys.readouterr().err
    assert "stabilisation sweep: 100%" in bar and "11/11" in bar and "fit/s" in bar  # 5 shared + 2 x 3


def test_a_record_sampled_far_above_its_band_is_resampled_by_default():
    s, rec50 = _two_mode_ride(40.0)
    u = am.random_vibration(400.0, 40.0, (0.5, 24.0), seed=3)
    rec = am.simulate_recording(s, u, 400.0, noise=0.05, seed=4)
    d = stabilisation_diagram(rec, ORDERS, per_sensor=False, n_jobs=1)
    assert d.preparation.original_fs == 400.0 and d.recording.fs < 100.0
    assert d.recording.fs == d.preparation.analysis_fs and "resampled" in {w.code for w in d.warnings}


def test_the_band_and_the_detrend_reach_the_preparation_and_the_selection(ride):
    s, rec = ride
    offset = Recording(rec.fs, rec.base, rec.response + [0.5, -0.2], rec.sensors, rec.input_name)
    d = _diagram(offset, band=(1.0, 6.0), detrend="linear")
    assert d.preparation.band == (1.0, 6.0) and d.preparation.detrend == "linear"
    assert "trend_removed" in {w.code for w in d.warnings}
    sel = select_modes(d, n_jobs=1)  # the diagram's band: only the first mode, nothing unexplained
    assert sel.modes.freq_hz.to_numpy() == pytest.approx(s.modes().freq_hz[:1], rel=0.005)
    assert not [n for n in sel.own_warnings if n.code == "unexplained_peak"]
    # a band the rate need not change for: the selection still keeps to it
    upper = _diagram(rec, band=(6.0, 20.0))
    assert upper.recording.fs == rec.fs
    sel = select_modes(upper, n_jobs=1)
    assert sel.modes.freq_hz.to_numpy() == pytest.approx(s.modes().freq_hz[1:], rel=0.005)


def test_a_given_delay_sweeps_as_the_chosen_one(ride, diagram):
    given = _diagram(ride[1], nk=diagram.orders[0][3])
    assert given.orders == diagram.orders and set(given.fits) == set(diagram.fits)
    pd.testing.assert_frame_equal(
        given.poles[["source", "na", "cls"]], diagram.poles[["source", "na", "cls"]], check_exact=True
    )
    np.testing.assert_allclose(given.poles.freq_hz, diagram.poles.freq_hz, rtol=1e-3)


def test_the_selection_reports_what_it_should(ride, diagram):
    s, _ = ride
    sel = select_modes(diagram, n_jobs=1, segments=2)
    assert "index" not in sel.modes.columns and list(sel.modes.index) == [0, 1]
    assert set(sel.modes.estimator) == {"ml-zoh"} and sel.refinement.hold == "zoh"  # a held input: its exact class
    assert (sel.modes.segments_found == 2).all() and sel.modes.freq_segment_sd.notna().all()
    # the ARMAX standard deviations are the converged fit's, taken from its 95 % intervals
    rec = diagram.recording
    for m in sel.modes.itertuples():
        full = am.fit_armax(rec, *diagram.fits[(SHARED, m.na)].orders, shared_poles=True).modes()
        full = full[full.sensor == rec.sensors[0]]
        j = int(np.argmin(np.abs(full.freq_hz.to_numpy() - m.freq_hz)))
        assert m.freq_sd_armax == pytest.approx(full.freq_sd.iloc[j], rel=0.1)
        assert m.damping_sd_armax == pytest.approx(full.damping_sd.iloc[j], rel=0.1)
    # Table 3.2's weighted means come with the selection (a per-sensor sweep was run)
    assert sel.weighted is not None and len(sel.weighted) == 2
    # the best-supported mode when only one is asked for
    (one,) = select_modes(diagram, n_modes=1, n_jobs=1, segments=0).modes.freq_hz
    assert one == pytest.approx(s.modes().freq_hz[0], rel=0.005)


def test_no_mode_in_the_band_says_why_and_what_to_do(diagram):
    """Nothing stable in 15-20 Hz: the selection is empty, says so with the diagram's own counts
    of the shared poles there and of those rejected, and says what to do."""
    sel = select_modes(diagram, band=(15.0, 20.0), n_jobs=1)
    shared = diagram.poles[(diagram.poles.source == "shared") & diagram.poles.freq_hz.between(15.0, 20.0)]
    rejected = int((shared.rejected != "").sum())
    (note,) = [w for w in sel.warnings if w.code == "no_modes"]
    assert sel.modes.empty and sel.quality == "poor"
    assert note.message.startswith(f"no stable mode found in 15-20 Hz: of {len(shared)} shared poles in 15-20 Hz, "
                                   f"{rejected} were rejected")  # fmt: skip
    assert note.message.endswith(
        "Widen the band, extend the order range, or check that the input excites the structure."
    )


def test_a_record_of_noise_is_flagged_before_its_poles_are_read(ride):
    """Outputs that are independent noise still give poles a selection may keep; the diagram
    says first that no output responds to the input."""
    rec = ride[1]
    noise = np.random.default_rng(5).standard_normal(rec.response.shape)
    d = _diagram(Recording(rec.fs, rec.base, noise, rec.sensors, rec.input_name))
    (w,) = [w for w in d.warnings if w.code == "incoherent_output"]
    assert w.channels == rec.sensors and "not the structure's" in w.message


def test_the_diagram_plots_the_selection(diagram):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    sel = select_modes(diagram, n_jobs=1, segments=0)
    top, damping = diagram.plot(sel)
    labels = " ".join(t.get_text() for t in top.texts)
    for f in sel.modes.freq_hz:
        assert f"{f:.2f} Hz" in labels
    legend = [t.get_text() for t in top.figure.legends[0].get_texts()]
    assert ("coherence < 0.8" in legend) == bool(top.patches)  # the shading is explained
    fig, ax = plt.subplots()
    top2, _ = diagram.plot(ax=ax)
    assert top2 is ax and not top2.texts  # no selection: no mode labels
    plt.close("all")


def test_the_figure_draws_the_h1_and_coherence_the_check_judged(diagram, monkeypatch):
    """The figure's H1 curves and its low-coherence shading use the check's Welch segments:
    with the default ones, a short bridge record was shaded below 0.8 everywhere while the
    check's caption said it used lines of coherence 0.8 or more. Without a check, the default."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    import armaxmodal.io.report.diagram_plot as plot
    from armaxmodal.spectra import measured_frf

    asked = []

    def spy(rec, nperseg=None):
        asked.append(nperseg)
        return measured_frf(rec, nperseg)

    monkeypatch.setattr(plot, "measured_frf", spy)
    selection = select_modes(diagram, n_jobs=1, segments=0)
    diagram.plot(selection)
    diagram.plot()
    assert asked == [selection.check.nperseg, None]
    plt.close("all")


def test_the_fitted_frf_is_drawn_over_the_lines_each_output_was_checked_on(bundled_diagram):
    """The check's LSFD curve of an output is drawn from its lowest to its highest coherent line
    only: beyond them it is its residual terms extrapolated (the Inglewood bridge's rose tenfold
    over its H1 below 1.5 Hz). On the bundled ride the legs' coherence ends near 17 Hz, the
    other outputs' reach the top of the band."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from armaxmodal.spectra import coherent_lines

    selection = select_modes(bundled_diagram, n_jobs=1, segments=0)
    check = selection.check
    lines = coherent_lines(bundled_diagram.recording, check.nperseg)
    assert check.checked_hz == tuple((ln.freq_hz[0], ln.freq_hz[-1]) for ln in lines)
    top, _ = bundled_diagram.plot(selection)
    dashed = [line for a in top.figure.axes for line in a.get_lines() if line.get_linestyle() == "--"]
    assert len(dashed) == len(lines)  # one curve per output, in the sensors' order
    for line, (lo, hi) in zip(dashed, check.checked_hz, strict=True):
        assert line.get_xdata().min() >= lo and line.get_xdata().max() <= hi
        assert line.get_xdata().max() == pytest.approx(hi, abs=1e-9)
    legs = bundled_diagram.recording.sensors.index("legs")
    assert check.checked_hz[legs][1] < 0.8 * min(hi for k, (_, hi) in enumerate(check.checked_hz) if k != legs)
    plt.close("all")


def test_the_frf_axis_spans_the_curves_inside_the_input_band():
    """Beyond the input's excited band an H1 is noise over noise and may rise far above the
    structure's response: the axis is set by the curves inside the band (twice their peak),
    and a near-zero channel stretches it at most four decades down."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from armaxmodal.io.report.diagram_plot import _limit_frf_axis
    from armaxmodal.spectra import excited_band, measured_frf

    s, _ = _two_mode_ride(30.0)
    ride = am.simulate_recording(s, am.random_vibration(50.0, 30.0, (0.5, 16.0), seed=3), 50.0, noise=0.05, seed=4)
    diagram = _diagram(ride)
    rec = diagram.recording
    selection = select_modes(diagram, n_jobs=1, segments=0)
    f, h, _ = measured_frf(rec, selection.check.nperseg)  # the curves the check judged
    top, _ = diagram.plot(selection)
    (frf_axis,) = [a for a in top.figure.axes if a.get_yscale() == "log"]
    inside = (f > 0) & (f <= excited_band(rec)[1])
    assert top.get_xlim()[1] > excited_band(rec)[1]  # the span reaches past the band ...
    assert frf_axis.get_ylim()[1] == pytest.approx(2 * np.abs(h[inside]).max())  # ... its curves do not count
    _, ax = plt.subplots()
    _limit_frf_axis(ax, f, np.column_stack([np.abs(h[:, 0]), np.full(f.size, 1e-12)]), 0.0, 50.0)
    assert ax.get_ylim()[0] == pytest.approx(ax.get_ylim()[1] * 1e-4)
    plt.close("all")


def test_a_sweep_capped_below_the_delay_choice_fits_its_orders_afresh(ride):
    """The delay choice's fits ran DELAY_CHOICE_ITERATIONS iterations; a sweep capped lower
    must not take them over (they would exceed its cap): every fit respects the sweep's cap."""
    from armaxmodal.modes.diagram import DELAY_CHOICE_ITERATIONS

    cap = 2
    assert cap < DELAY_CHOICE_ITERATIONS
    diagram = stabilisation_diagram(ride[1], range(4, 9, 2), per_sensor=False, max_iter=cap, n_jobs=1)
    assert max(int(fit.iterations.max()) for fit in diagram.fits.values()) == cap


def _with_line(rec: Recording, channels: list[str], freq_hz: float, amp: float, on_input: bool = False) -> Recording:
    """A sinusoid added to some outputs (and to the input)."""
    line = amp * np.sin(2 * np.pi * freq_hz * rec.time)
    y = rec.response.copy()
    for name in channels:
        y[:, rec.sensors.index(name)] += line
    return Recording(rec.fs, rec.base + line if on_input else rec.base, y, rec.sensors, rec.input_name)


def test_a_line_the_input_does_not_drive_is_named_as_a_periodic_disturbance(ride, diagram):
    """A hum the base does not cause is an undamped pole of negligible residue at every order:
    named with its frequency and the sensor whose own sweep shows it, never on the clean ride;
    picked up on every channel, the input's own line is stated with its prominence."""
    assert not [w for w in diagram.warnings if w.code == "periodic_disturbance"]
    name = ride[1].sensors[1]
    (w,) = [w for w in _diagram(_with_line(ride[1], [name], 7.3, 0.2)).warnings if w.code == "periodic_disturbance"]
    assert w.value == pytest.approx(7.3, abs=0.005) and w.channels == (name,)
    assert "in the outputs" in w.message and "armaxmodal diagnose" in w.message
    everywhere = _with_line(ride[1], list(ride[1].sensors), 7.3, 0.6, on_input=True)
    (w,) = [w for w in _diagram(everywhere).warnings if w.code == "periodic_disturbance"]
    assert w.value == pytest.approx(7.3, abs=0.005) and "the input carries the line too (" in w.message


def test_a_structure_damped_below_the_line_threshold_is_not_a_disturbance():
    """Modes at 0.066 % and 0.089 % damping are as undamped as a hum, but the input drives
    them (residues 11 % and 100 % of the strongest): modes, never a periodic disturbance."""
    from armaxmodal.modes.settings import DEFAULTS

    UNDAMPED_LINE = DEFAULTS.lines.undamped

    s = am.Structure.from_chain([10.0, 5.0], [8000.0, 0.0], [0.5, 0.0], [12000.0], [0.3], ("m1", "m2"))
    assert max(s.modes().damping) < UNDAMPED_LINE
    rec = am.simulate_recording(s, am.random_vibration(50.0, 60.0, (0.5, 24.0), seed=3), 50.0, noise=0.05, seed=4)
    diagram = _diagram(rec)
    assert (diagram.poles.damping.abs() < UNDAMPED_LINE).sum() >= 8  # the sweep does see them undamped
    assert not [w for w in diagram.warnings if w.code == "periodic_disturbance"]


def test_identify_names_the_peak_its_order_leaves_out(ride):
    """``identify`` at one order reports what that order holds: at na = 2 only the 3.53 Hz
    mode, and the 9.95 Hz mode's clear, coherent FRF peak is named (``unexplained_peak``, on
    both sensors, as :func:`select_modes` names it); at na = 4 both modes are found and
    nothing is left unexplained."""
    s, rec = ride
    exact = s.modes().freq_hz
    short = am.identify(rec, (2, 3, 2, 0))
    assert short.modes.freq_hz.to_numpy() == pytest.approx(exact[:1], rel=0.005)
    (w,) = [w for w in short.warnings if w.code == "unexplained_peak"]
    assert w.channels == ("m1", "m2") and w.value == pytest.approx(exact[1], rel=0.05)
    assert [d["code"] for d in short.to_dict()["warnings"]].count("unexplained_peak") == 1
    full = am.identify(rec, (4, 5, 4, 0))
    assert full.modes.freq_hz.to_numpy() == pytest.approx(exact, rel=0.005)
    assert not [w for w in full.warnings if w.code == "unexplained_peak"]


def test_each_sensor_fit_starts_from_the_shared_fit_of_its_order(monkeypatch, fixtures_dir):
    """Issue 29: the per-sensor sweep starts every sensor's fit from the shared fit of the same
    order (its A, the sensor's B and C), not from scratch; the shared fits are unchanged."""
    import armaxmodal.modes.diagram as diagram_module

    seen = []
    real = diagram_module.fit_resumable

    def recording_start(rec, orders, **kwargs):
        seen.append((rec.sensors, tuple(orders), kwargs.get("start")))
        return real(rec, orders, **kwargs)

    monkeypatch.setattr(diagram_module, "fit_resumable", recording_start)
    rec = am.read_recording(fixtures_dir / "supine_random.csv")
    diagram = stabilisation_diagram(rec, range(4, 9, 2), nk=-3, n_jobs=1)
    singles = [(sensors, orders, start) for sensors, orders, start in seen if len(sensors) == 1]
    assert len(singles) == 3 * len(rec.sensors)
    for sensors, orders, start in singles:
        assert start is diagram.fits[(SHARED, orders[0])], (sensors, orders)
        assert start.shared_poles and tuple(start.orders) == orders
    assert all(start is None for sensors, _, start in seen if len(sensors) > 1)
