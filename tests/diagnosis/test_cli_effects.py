"""The loop tried from the command line, one effect at a time: ``simulate --effect`` plants each
effect ``diagnose`` names, and ``diagnose`` names it, on its channel or joint, in its verdict, the
first lines it prints, on one screen (at most 25 lines of at most 100 characters). Sizes are the
diagnosis battery's (``scripts/diagnose_battery.py``)."""

import pytest

from armaxmodal.cli import main
from armaxmodal.diagnosis.effects import REGISTRY

#: (the --effect planted, the diagnose options, the effect named, where the verdict puts it)
CASES = [
    ("input_delay:legs:samples=2.4", [], "input_delay", "on legs"),
    ("offset_drift:chest:offset=0.3,drift_per_s=0.004", [], "offset_drift", "on chest"),
    ("level_shift:pelvis:time_s=70,size=0.3", [], "level_shift", "on pelvis"),
    ("gain_change:chest:time_s=50,factor=1.2", [], "gain_change", "on chest"),
    ("clock_drift:legs:rate_ppm=278", [], "clock_drift", "on legs"),
    ("periodic_disturbance:head:freq_hz=11.3,amp=0.1", [], "periodic_disturbance", "on head"),
    # the default model's noise part (nc 12) holds coloured noise, as an ARMAX model should: the loop
    # names it where the model's noise part is too short for it
    ("coloured_noise:pelvis:level=0.3", ["--model", "12,17,2,-4"], "coloured_noise", "pelvis"),
    ("clipping:chest:fraction=0.6", [], "clipping", "on chest"),
    ("sensor_fault:head:stuck_s=1", [], "sensor_fault", "on head"),
    ("second_input:legs:level=0.3", [], "second_input", ""),
    ("stiffness_nonlinearity:chest+pelvis:ratio=0.3", [], "stiffness_nonlinearity", "between chest and pelvis"),
    ("damping_nonlinearity:chest+pelvis:ratio=2", [], "damping_nonlinearity", "between chest and pelvis"),
    ("time_varying::time_s=60,stiffening=1.12", [], "time_varying", ""),
]


def test_every_effect_the_loop_names_is_tried_from_the_command_line():
    """Each registry entry is planted here, but the missing mode, which lives in the model and is
    tried by ``diagnose --model`` (tests/diagnosis/test_diagnose.py)."""
    assert {name for _, _, name, _ in CASES} | {"unmodelled_mode"} == {e.name for e in REGISTRY}


@pytest.mark.parametrize(("planted", "options", "name", "where"), CASES, ids=[c[2] for c in CASES])
def test_a_planted_effect_is_named_first(tmp_path, capsys, planted, options, name, where):
    ride = tmp_path / "ride.csv"
    assert main(["--quiet", "simulate", "--seed", "11", "--effect", planted, "--out", str(ride)]) == 0
    capsys.readouterr()
    assert main(["--quiet", "diagnose", str(ride), *options]) == 0
    out, err = capsys.readouterr()
    shown = out.strip().splitlines() + err.strip().splitlines()
    assert len(shown) <= 25 and max(map(len, shown)) <= 100, shown  # one screen
    lines = out.splitlines()
    first = next(k for k, line in enumerate(lines) if line.startswith("verdict: "))
    assert first <= 2, lines[:4]  # after the record's line (two where its path is long)
    verdict = " ".join(lines[first : first + 2])
    assert verdict.startswith(f"verdict: found and confirmed: {name}"), verdict
    assert where in verdict.split(";")[0], verdict
