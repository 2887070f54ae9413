import numpy as np
import pytest

import armaxmodal as am
from armaxmodal.exceptions import StructureError
from armaxmodal.systems import datasets

# Table 2.1 prints two decimals: agreement after rounding is exact.
TABLE_2_1_DECIMALS = 2
# Table 4.3 prints four decimals (+-0.5e-4) computed from unrounded parameters. The matrices
# printed in Section 4.4 are rounded too: moving every printed element by half its last digit
# moves the frequencies by at most 1.6e-4 Hz and the damping ratios by 1.6e-5 (worst case,
# summed first-order sensitivities), hence these bounds.
TABLE_4_3_FREQ_ATOL = 2.1e-4
TABLE_4_3_DAMPING_ATOL = 0.7e-4
# Table 4.4 rounds springs to 1 N/m and dampers to 0.1 N s/m; the matrices round separately.
TABLE_4_4_K_ATOL = 1.5
TABLE_4_4_C_ATOL = 0.06


def test_chapter2_reproduces_table_2_1():
    modes = am.chapter2_system().modes()
    np.testing.assert_array_equal(np.round(modes.freq_hz, TABLE_2_1_DECIMALS), datasets.TABLE_2_1["freq_hz"])
    np.testing.assert_array_equal(np.round(modes.damping, TABLE_2_1_DECIMALS), datasets.TABLE_2_1["damping"])


def test_supine_reproduces_table_4_3():
    modes = am.supine_human().modes()
    for key in ("freq_hz", "damped_freq_hz"):
        np.testing.assert_allclose(getattr(modes, key), datasets.TABLE_4_3[key], atol=TABLE_4_3_FREQ_ATOL)
    np.testing.assert_allclose(modes.damping, datasets.TABLE_4_3["damping"], atol=TABLE_4_3_DAMPING_ATOL)


def test_supine_components_match_table_4_4():
    comps = am.supine_human().chain_components()
    t = datasets.TABLE_4_4
    np.testing.assert_allclose(comps.k, t["k"], atol=TABLE_4_4_K_ATOL)
    np.testing.assert_allclose(comps.k_s, t["k_s"], atol=TABLE_4_4_K_ATOL)
    np.testing.assert_allclose(comps.c, t["c"], atol=TABLE_4_4_C_ATOL)
    np.testing.assert_allclose(comps.c_s, t["c_s"], atol=TABLE_4_4_C_ATOL)
    frame = comps.to_frame()
    assert set(frame["component"]) == {"mass", "k", "c", "k_s", "c_s"}
    assert len(frame) == 4 * 3 + 3 * 2


def test_table_4_4_chain_gives_table_4_3():
    t = datasets.TABLE_4_4
    s = am.Structure.from_chain(np.diag(am.supine_human().M), t["k"], t["c"], t["k_s"], t["c_s"])
    np.testing.assert_allclose(s.modes().freq_hz, datasets.TABLE_4_3["freq_hz"], atol=TABLE_4_3_FREQ_ATOL)


def test_chain_round_trip():
    s = am.chapter2_system()
    c = s.chain_components()
    back = am.Structure.from_chain(c.masses, c.k, c.c, c.k_s, c.c_s, s.names)
    np.testing.assert_allclose(back.K, s.K, rtol=0, atol=1e-9)
    np.testing.assert_allclose(back.C, s.C, rtol=0, atol=1e-9)
    np.testing.assert_array_equal(c.k, [74000, 28000, 120800, 2400])


def test_non_chain_is_refused():
    s = am.chapter2_system()
    k = np.array(s.K)
    k[0, 2] = k[2, 0] = -1000.0
    k[0, 0] += 1000.0
    k[2, 2] += 1000.0
    with pytest.raises(StructureError, match="not a chain"):
        am.Structure(s.M, s.C, k).chain_components()


@pytest.mark.parametrize(
    "change, message",
    [
        (lambda m, c, k: (m, np.array(c) + np.triu(np.ones((4, 4)), 1) * 5, k), "symmetric"),
        (lambda m, c, k: (m, c, np.array(k) - 2e5 * np.eye(4)), "positive definite"),
        (lambda m, c, k: (m, -np.array(c), k), "semi-definite"),
        (lambda m, c, k: (np.array(m) + 0.1, c, k), "diagonal"),
        (lambda m, c, k: (-np.array(m), c, k), "positive masses"),
        (lambda m, c, k: (m, np.array(c)[:3, :3], k), r"shape \(4, 4\)"),
        (lambda m, c, k: (m, c, np.where(np.eye(4) > 0, np.nan, k)), "NaN"),
    ],
)
def test_bad_matrices_are_refused(change, message):
    s = am.chapter2_system()
    with pytest.raises(StructureError, match=message):
        am.Structure(*change(s.M, s.C, s.K))


def test_printed_asymmetric_c_is_refused():
    s = am.supine_human()
    c = np.array(s.C)
    c[1, 0] = 0.0  # as printed in Section 4.4
    with pytest.raises(StructureError, match="symmetric"):
        am.Structure(s.M, c, s.K)


def test_modes_solve_the_quadratic_eigenproblem():
    s = am.supine_human()
    m = s.modes()
    for lam, psi in zip(m.eigenvalues, m.shapes.T, strict=True):
        residual = (lam**2 * s.M + lam * s.C + s.K) @ psi
        assert np.linalg.norm(residual) < 1e-9 * np.linalg.norm(s.K)
    np.testing.assert_allclose(np.linalg.norm(m.shapes, axis=0), 1.0)
    assert np.all(np.abs(m.shapes.imag[np.argmax(np.abs(m.shapes), axis=0), range(4)]) < 1e-12)


def test_modal_sum_equals_direct_epfrf():
    """Eqs. 3.23-3.26: the modal constants rebuild -w^2 H M e exactly."""
    s = am.chapter2_system()
    m = s.modes()
    f = np.linspace(0.2, 40, 300)
    s_ = 2j * np.pi * f[:, None, None]
    lam = m.eigenvalues[None, None, :]
    consts = m.modal_constants[None]
    hme = np.sum(consts / (s_ - lam) + consts.conj() / (s_ - lam.conj()), axis=2)
    modal_epfrf = -((2 * np.pi * f[:, None]) ** 2) * hme
    np.testing.assert_allclose(modal_epfrf, s.epfrf(f), rtol=1e-9, atol=1e-12)
    direct = -((2 * np.pi * f[:, None]) ** 2) * np.einsum("fij,j->fi", s.frf(f), s.masses)
    np.testing.assert_allclose(direct, s.epfrf(f), rtol=1e-9)


def test_transmissibility_limits():
    s = am.supine_human()
    t = s.transmissibility([1e-4, 1e4])
    np.testing.assert_allclose(t[0], 1.0, atol=1e-6)  # rigid motion at low frequency
    assert np.all(np.abs(t[1]) < 1e-2)  # isolation far above the modes
    np.testing.assert_allclose(s.epfrf([1e-4])[0], 0.0, atol=1e-6)
    np.testing.assert_allclose(s.transmissibility([3.0], "chest")[0, 1], 1.0)


def test_transmissibility_between_outputs_tends_to_mode_shape_ratio():
    """Eqs. 3.32-3.33 on a lightly damped chain with separated modes."""
    s = am.Structure.from_chain([2.0, 1.0, 1.5], [4e4, 1e3, 2e4], [1.0, 0.3, 0.5], [1e4, 3e4], [0.3, 1.0])
    m = s.modes()
    assert m.damping.max() < 0.01
    for r in range(3):
        t = s.transmissibility([m.damped_freq_hz[r]], reference=0)[0]
        ratio = m.shapes[:, r] / m.shapes[0, r]
        np.testing.assert_allclose(np.abs(t), np.abs(ratio), rtol=0.05)


def test_from_chain_checks_sizes_and_signs():
    with pytest.raises(StructureError, match="k_s"):
        am.Structure.from_chain([1, 1], [1, 1], [1, 1], [1, 1], [1])
    with pytest.raises(StructureError, match="non-negative"):
        am.Structure.from_chain([1, 1], [1, -1], [1, 1], [1], [1])
