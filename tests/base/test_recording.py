"""``Recording.split``: the parts the halves test and the segment spread are fitted on."""

import numpy as np
import pytest

import armaxmodal as am


def _record(n=10):
    t = np.arange(n, dtype=float)
    return am.Recording(10.0, np.sin(t), np.column_stack([t, -2 * t]), ("a", "b"), "base", mass_kg=70.0)


def test_the_parts_are_the_records_consecutive_equal_slices_without_the_remainder():
    rec = _record(10)
    parts = rec.split(3)  # 3 samples each, the tenth dropped
    assert [p.n_samples for p in parts] == [3, 3, 3]
    for i, part in enumerate(parts):
        np.testing.assert_array_equal(part.base, rec.base[3 * i : 3 * i + 3])
        np.testing.assert_array_equal(part.response, rec.response[3 * i : 3 * i + 3])
        assert (part.fs, part.sensors, part.input_name) == (10.0, ("a", "b"), "base")
    (whole,) = rec.split(1)
    np.testing.assert_array_equal(whole.response, rec.response)


@pytest.mark.parametrize("k", [0, -2, 11, 2.0, True, "2"])
def test_a_number_of_parts_no_record_can_be_cut_into_is_refused_by_name(k):
    with pytest.raises(am.DataError, match="k: expected a whole number of parts from 1 to 10"):
        _record(10).split(k)
