import json

import numpy as np
import pytest

import armaxmodal as am
from armaxmodal.cli import main


def test_info(fixtures_dir, capsys):
    assert main(["info", str(fixtures_dir / "supine_random.csv")]) == 0
    out = capsys.readouterr().out
    assert "7200 samples at 60 Hz" in out and "legs" in out


def test_modes_json(tmp_path, capsys):
    out = tmp_path / "modes.json"
    assert main(["--quiet", "modes", "--system", "supine", "--json", str(out)]) == 0
    data = json.loads(out.read_text())
    np.testing.assert_allclose([m["freq_hz"] for m in data["modes"]], am.supine_human().modes().freq_hz)


def test_quiet_is_accepted_before_or_after_the_command(tmp_path, capsys):
    out = tmp_path / "modes.json"
    assert main(["modes", "--system", "supine", "--json", str(out)]) == 0
    assert "wrote" in capsys.readouterr().out
    for argv in (["--quiet", "modes"], ["modes", "--quiet"]):
        assert main([*argv, "--system", "supine", "--json", str(out)]) == 0
        assert "wrote" not in capsys.readouterr().out


def test_simulate_writes_a_readable_recording(tmp_path):
    out = tmp_path / "sim.csv"
    assert (
        main(
            [
                "--quiet",
                "simulate",
                "--system",
                "chapter2",
                "--fs",
                "100",
                "--duration",
                "5",
                "--out",
                str(out),
            ]
        )
        == 0
    )
    rec = am.read_recording(out)
    assert rec.n_samples == 500 and rec.sensors == ("m1", "m2", "m3", "m4")


def test_errors_exit_2_with_a_message(tmp_path, capsys):
    p = tmp_path / "r.csv"
    p.write_text("time,plat,a\n0,1,2\n1,2,3\n2,0,1\n")
    assert main(["info", str(p)]) == 2
    err = capsys.readouterr().err
    assert "input channel 'base' not found" in err and "--input" in err
    assert main(["info", str(p), "--input", "plat"]) == 0


def test_identify_fixed_orders_writes_the_json_contract(fixtures_dir, tmp_path, capsys):
    out, poles = tmp_path / "modes.json", tmp_path / "poles.csv"
    code = main(
        [
            "identify",
            str(fixtures_dir / "supine_random_zoh.csv"),
            "--model",
            "8,9,8,0",
            "--json",
            str(out),
            "--csv",
            str(poles),
        ]
    )
    assert code == 0
    data = json.loads(out.read_text())
    assert data["fs"] == 60.0 and data["input"] == "base" and data["outputs"] == ["head", "chest", "pelvis", "legs"]
    freqs = [m["freq_hz"] for m in data["modes"]]
    assert freqs == sorted(freqs) and len(freqs) == 4
    np.testing.assert_allclose(freqs, am.supine_human().modes().freq_hz, rtol=0.01)
    mode = data["modes"][0]
    assert mode["freq_ci95"][0] < mode["freq_hz"] < mode["freq_ci95"][1]
    assert set(mode["shape"]) == {"head", "chest", "pelvis", "legs"}
    assert max(v["mag"] for v in mode["shape"].values()) == 1.0
    assert {"sensor", "mode", "freq_hz", "damping", "residue_mag"} <= set(data["per_sensor"][0])
    assert poles.read_text().startswith("sensor,freq_hz")


def test_identify_rejects_bad_orders(fixtures_dir, capsys):
    assert main(["identify", str(fixtures_dir / "supine_random_zoh.csv"), "--model", "8,9"]) == 2
    assert "na,nb,nc,nk" in capsys.readouterr().err


def test_invert_from_stabilise_json(fixtures_dir, tmp_path, capsys):
    """stabilise -> invert on the simulated supine ride recovers the Section 4.4 model."""
    modes, phys = tmp_path / "modes.json", tmp_path / "phys.json"
    rec = str(fixtures_dir / "supine_random.csv")
    assert main(["--quiet", "stabilise", rec, "--orders", "2:20", "--json", str(modes)]) == 0
    assert (
        main(
            [
                "--quiet",
                "invert",
                str(modes),
                "--recording",
                rec,
                "--total-mass",
                "77.5663",
                "--json",
                str(phys),
                "--plot",
                str(tmp_path / "fit.png"),
            ]
        )
        == 0
    )
    data = json.loads(phys.read_text())
    assert (tmp_path / "fit.png").stat().st_size > 20_000
    assert min(data["prediction_fit_percent"].values()) > 90.0
    truth = am.supine_human()
    k = np.array(data["components"]["k"])
    np.testing.assert_allclose(k[:3], truth.chain_components().k[:3], rtol=0.05)  # k4 is small and weakly seen
    np.testing.assert_allclose([m["freq_hz"] for m in data["modes"]], truth.modes().freq_hz, rtol=0.01)
    assert main(["--quiet", "invert", str(modes), "--method", "evphc"]) == 2
    assert "--recording" in capsys.readouterr().err


_ARENAS_AFTER_TWO_THREADS = """
import ctypes, os, sys, tempfile, threading
import numpy as np
from armaxmodal.cli.main import _one_malloc_arena
if sys.argv[1] == "one":
    _one_malloc_arena()
def churn():
    for _ in range(200):
        np.ones(20_000).sum()  # 160 kB: below the mmap threshold, so from an arena
threads = [threading.Thread(target=churn) for _ in range(2)]
[t.start() for t in threads]
[t.join() for t in threads]
libc = ctypes.CDLL("libc.so.6")
libc.fdopen.restype = ctypes.c_void_p
with tempfile.TemporaryFile() as f:
    stream = libc.fdopen(os.dup(f.fileno()), b"w")
    libc.malloc_info(0, ctypes.c_void_p(stream))
    libc.fclose(ctypes.c_void_p(stream))
    f.seek(0)
    print(f.read().decode().count("<heap nr="))
"""


def test_the_command_keeps_one_malloc_arena_for_its_worker_threads():
    import ctypes
    import subprocess
    import sys

    try:
        if not hasattr(ctypes.CDLL("libc.so.6"), "malloc_info"):
            pytest.skip("a libc without malloc_info")
    except OSError:
        pytest.skip("not glibc")
    heaps = {
        mode: int(subprocess.run([sys.executable, "-c", _ARENAS_AFTER_TWO_THREADS, mode], capture_output=True,
                                 text=True, check=True).stdout)
        for mode in ("one", "default")
    }  # fmt: skip
    assert heaps["one"] == 1 and heaps["default"] > 1, heaps


def test_a_ride_with_a_filled_gap_gives_the_modes_of_the_whole_ride(fixtures_dir, tmp_path):
    """A 40 ms dropped packet (two empty cells of the head at 60 Hz), filled on request: every
    mode within the intervals of the ride without the gap."""
    from tests.io.test_io import _ride_with_gap

    gapped = _ride_with_gap(fixtures_dir, tmp_path, range(3000, 3002))
    runs = {}
    cases = (("whole", fixtures_dir / "supine_random.csv", []), ("filled", gapped, ["--fill-gaps", "0.04"]))
    for name, data, extra in cases:
        out = tmp_path / f"{name}.json"
        assert main(["--quiet", "stabilise", str(data), "--orders", "2:20", "--json", str(out), *extra]) == 0
        runs[name] = json.loads(out.read_text())
    assert "gap_filled" in [w["code"] for w in runs["filled"]["warnings"]]
    for whole, filled in zip(runs["whole"]["modes"], runs["filled"]["modes"], strict=True):
        assert whole["freq_ci95"][0] <= filled["freq_hz"] <= whole["freq_ci95"][1]
        assert whole["damping_ci95"][0] <= filled["damping"] <= whole["damping_ci95"][1]


def test_every_flag_of_every_command_says_what_it_does():
    """The command-line reference (docs/user_guide/cli.md) is written from the parser: a flag
    without help text would be a bare name there."""
    import argparse

    from armaxmodal.cli.main import build_parser

    parser = build_parser()
    (commands,) = [a for a in parser._actions if isinstance(a, argparse._SubParsersAction)]
    bare = [f"{name} {'/'.join(action.option_strings) or action.dest}"
            for name, sub in commands.choices.items() for action in sub._actions
            if not action.help and not isinstance(action, argparse._HelpAction)]  # fmt: skip
    assert not bare, bare
    assert all(choice.help for choice in commands._choices_actions)  # every command too
