"""A resonance the input does not drive: a column of the diagram's poles with negative damping at a
clear, coherent H1 peak no reported mode is near (``undriven_resonance``)."""

from __future__ import annotations

from dataclasses import replace

import matplotlib.pyplot as plt
import numpy as np
import pandas as pd
import pytest

import armaxmodal as am
from armaxmodal.modes.frf import undriven_resonances
from armaxmodal.modes.settings import DEFAULTS


@pytest.fixture(scope="module")
def light():
    """The two lightly damped modes of ``light_ride`` (3.53 and 9.95 Hz) and a small diagram of them."""
    s = am.Structure.from_chain([10.0, 5.0], [8000.0, 0.0], [8.0, 0.0], [12000.0], [5.0], ("m1", "m2"))
    u = am.random_vibration(50.0, 240.0, (0.5, 24.0), seed=3)
    rec = am.simulate_recording(s, u, 50.0, noise=0.02, seed=4, hold="bandlimited")
    return s.modes(), am.stabilisation_diagram(rec, range(2, 9, 2), per_sensor=False, n_jobs=1)


def _with_growing_column(diagram, freq_hz: float, orders) -> am.StabilisationDiagram:
    """The diagram with one shared pole of negative damping (beyond its interval, as the sweep rejects it)
    added at each of ``orders``, near ``freq_hz``."""
    rows = [
        {
            "source": "shared",
            "na": na,
            "freq_hz": freq_hz * (1 + 0.002 * k),
            "damping": -0.01 - 0.002 * k,
            "rejected": "negative damping",
        }
        for k, na in enumerate(orders)
    ]
    return replace(diagram, poles=pd.concat([diagram.poles, pd.DataFrame(rows)], ignore_index=True))


def _notes(diagram, reported_hz):
    nas = sorted({o.na for o in diagram.orders})
    return undriven_resonances(diagram, reported_hz, None, nas, DEFAULTS.cluster)


def test_a_growing_column_at_a_peak_no_mode_is_near_is_named_with_its_frequency(light):
    modes, diagram = light
    grown = _with_growing_column(diagram, 9.95, [4, 6, 8])
    (note,) = _notes(grown, [modes.freq_hz[0]])  # 9.95 Hz not reported
    assert note.code == "undriven_resonance" and note.freq_hz == (pytest.approx(9.97, abs=0.01),)
    assert "negative damping (-0.014 to -0.010) at 3 orders" in note.message
    assert note.message.startswith("the measured FRF peaks at 9.9")  # the H1's own peak, near 9.95 Hz


@pytest.mark.parametrize(
    ("column_hz", "orders", "reported"),
    [
        (9.95, [4, 6, 8], [3.53, 9.95]),  # a reported mode is near: the column is that mode's business
        (9.95, [6, 8], [3.53]),  # two orders: no column
        (6.5, [4, 6, 8], [3.53]),  # no coherent H1 peak within the clustering's reach
    ],
)
def test_no_note_without_a_column_a_peak_and_no_mode_near(light, column_hz, orders, reported):
    assert _notes(_with_growing_column(light[1], column_hz, orders), reported) == []


@pytest.mark.parametrize(("event", "h1_peak_hz"), [("painter_nc73666231", 4.25)])
def test_painter_street_2021_names_the_fundamental_the_h1_shows(realdata_dir, event, h1_peak_hz):
    """The bridge's deck resonates at the H1's coherent peak (4.25 Hz, coherence 0.99: the data's
    README), which no reported mode is near: the note names a frequency within 3 % of it."""
    rec = am.read_recording(realdata_dir / "bridge_painter" / f"{event}.csv.gz", input="base")
    selection = am.select_modes(am.stabilisation_diagram(rec, n_jobs=1), n_jobs=1)
    (note,) = [w for w in selection.warnings if w.code == "undriven_resonance"]
    assert abs(note.value / h1_peak_hz - 1) <= 0.03
    assert not np.any(np.abs(selection.modes.freq_hz / h1_peak_hz - 1) <= 0.03) and selection.quality == "poor"
    # the diagram draws it where it is named, once in the legend
    ax, _ = selection.diagram.plot(selection)
    drawn = [line for line in ax.lines if line.get_label() == "resonance the input does not drive"]
    assert len(drawn) == 1 and drawn[0].get_xdata()[0] == pytest.approx(note.value)
    plt.close(ax.figure)
