"""What every command shares: validated number types, the data arguments and loading,
output paths checked before any work, and outputs written all or none."""

from __future__ import annotations

import argparse
import os
import re
import sys
import textwrap
from pathlib import Path

import numpy as np

from armaxmodal.exceptions import DataError, OrderError
from armaxmodal.io.read import read_recording
from armaxmodal.io.write import write_all
from armaxmodal.systems import datasets

#: Output options checked before any work (every command that writes files).
OUTPUT_OPTIONS = ("json", "csv", "plot", "out")


def _number(kind, lo: float, lo_open: bool, what: str):
    """An argparse type: a finite number of ``kind`` above ``lo`` (strictly when ``lo_open``)."""

    def parse(text: str):
        try:
            value = kind(text)
        except ValueError as exc:
            raise argparse.ArgumentTypeError(f"expected {what}, got {text!r}") from exc
        if not np.isfinite(value) or value < lo or (lo_open and value == lo):
            raise argparse.ArgumentTypeError(f"expected {what}, got {text!r}")
        return value

    return parse


POSITIVE_INT = _number(int, 1, False, "a whole number >= 1")


NONNEG_INT = _number(int, 0, False, "a whole number >= 0")


POSITIVE = _number(float, 0.0, True, "a finite number > 0")


NONNEG = _number(float, 0.0, False, "a finite number >= 0")


def check_output_paths(args) -> None:
    """Every output path usable before any work: not a directory, its parent a directory (or
    creatable), not one of the input files, and no two outputs the same file."""
    from pathlib import Path

    inputs = [Path(p).resolve() for p in input_files(args)]
    seen = {}
    for option in OUTPUT_OPTIONS:
        value = getattr(args, option, None)
        if value is None or (option == "out" and args.command in ("study", "track")):  # their --out is a folder
            continue
        path = Path(value).resolve()
        flag = f"--{option}"
        if path.is_dir():
            raise DataError(f"{flag} {value}: is a directory; give a file name inside it.")
        if path in inputs:
            raise DataError(f"{flag} {value}: is an input file; writing there would destroy it. Choose another name.")
        if path in seen:
            raise DataError(f"{flag} and {seen[path]} name the same file {value}; give each its own.")
        seen[path] = flag
        parent = next((q for q in path.parents if q.exists()), None)
        if parent is not None and not parent.is_dir():
            raise DataError(f"{flag} {value}: {parent} is a file, not a folder; choose a path in a folder.")
        if parent is not None and not os.access(parent, os.W_OK):
            raise DataError(f"{flag} {value}: no permission to write in {parent}.")


def input_files(args) -> list[str]:
    data = getattr(args, "data", None)
    files = list(data) if isinstance(data, list) else ([data] if data else [])
    for option in ("modes", "recording"):
        value = getattr(args, option, None)
        if isinstance(value, str):
            files.append(value)
    return files


def add_data_args(p: argparse.ArgumentParser) -> None:
    p.add_argument("data", nargs="+", help="recording: .csv[.gz], .mat or .uff; or one Xsens DOT export per sensor")
    p.add_argument("--input", default="base", help="input (base acceleration) column or sensor; default 'base'")
    p.add_argument("--fs", type=POSITIVE, default=None, help="sampling rate in Hz if the file has no time column")
    p.add_argument("--outputs", default=None, help="comma-separated output columns to use (default: all)")
    p.add_argument("--axis", default="Acc_X", help="Xsens exports: the column to use; default Acc_X")
    p.add_argument(
        "--fill-gaps",
        type=POSITIVE,
        default=None,
        metavar="SECONDS",
        help="fill gaps (missing cells, dropped rows) of up to SECONDS by interpolation, each named in a warning",
    )


def load_recording(args):
    outputs = args.outputs.split(",") if args.outputs else None
    if len(args.data) > 1:
        from armaxmodal.io.xsens import read_xsens

        if getattr(args, "fill_gaps", None) is not None:
            raise DataError(
                "--fill-gaps fills the gaps of one file; per-sensor exports bridge up to 3 dropped packets "
                "each and refuse longer gaps (cut the record there)."
            )
        rec = read_xsens(args.data, input=args.input, axis=args.axis)
        args.data = " + ".join(args.data)
        return rec if outputs is None else rec.select(outputs)
    args.data = args.data[0]
    rec = read_recording(args.data, input=args.input, fs=args.fs, outputs=outputs, fill_gaps=args.fill_gaps)
    skipped = rec.meta.get("axis_columns", ())
    if skipped and not getattr(args, "quiet", False):
        named = ", ".join(f"'{c}'" for c in skipped)
        print(f"{args.data}: column(s) {named} increase in equal steps (a row index or time axis): not outputs")
    return rec


def parse_pair(text: str, what: str) -> tuple[float, float]:
    try:
        lo, hi = (float(v) for v in text.split(":"))
    except ValueError as exc:
        raise DataError(f"{what}: expected LO:HI in Hz, got {text!r}.") from exc
    return lo, hi


def order_range(text: str) -> range:
    """``--orders LO:HI`` as the even-step range of ``na``."""
    try:
        lo, hi = (int(v) for v in text.split(":"))
    except ValueError as exc:
        raise OrderError(f"--orders: expected LO:HI model orders such as 2:40, got {text!r}.") from exc
    if not 1 <= lo <= hi:
        raise OrderError(f"--orders: expected 1 <= LO <= HI, got {text!r}.")
    return range(lo, hi + 1, 2)


def model_orders(text: str) -> tuple[int, int, int, int] | None:
    """``--model``: ``'auto'`` (None: chosen by BIC) or the four orders ``na,nb,nc,nk``.

    Parameters
    ----------
    text : str

    Returns
    -------
    tuple of int or None

    Raises
    ------
    OrderError
        Not 'auto' and not four integers.

    Examples
    --------
    >>> from armaxmodal.cli.common import model_orders
    >>> model_orders("6,12,6,-5"), model_orders("auto")
    ((6, 12, 6, -5), None)
    """
    if text == "auto":
        return None
    try:
        orders = tuple(int(v) for v in text.split(","))
    except ValueError as exc:
        raise OrderError(f"--model: expected 'auto' or na,nb,nc,nk, got {text!r}.") from exc
    if len(orders) != 4:
        raise OrderError(f"--model: expected four integers na,nb,nc,nk, got {text!r}.")
    return orders  # type: ignore[return-value]


#: a note's line on the terminal, and how many lines of codes fit one screen with the header
NOTE_WIDTH, NOTE_LINES = 100, 23


def print_notes(warnings, verbose: bool = False) -> None:
    """The notes on stderr (even with --quiet), on one screen: per code one line within
    ``NOTE_WIDTH`` characters with its severity (:func:`armaxmodal.quality_warnings.severity`), how
    many, the channels and the frequencies (``QualityWarning.freq_hz``) and what was found (the first
    note's text without its asides, :func:`headline`). Problems first, then warnings, then
    information; at most ``NOTE_LINES`` codes. ``verbose``: every code with its advice and every full
    text. The JSON and ``--report`` always hold the full texts and what to do."""
    from armaxmodal.quality_warnings import CODES, UNCERTAIN_CODES, severity

    if not warnings:
        return
    advice, order = {c.code: c.advice for c in CODES}, {c.code: k for k, c in enumerate(CODES)}
    levels = ("problem", "warning", "info")
    groups: dict[str, list] = {}
    for w in warnings:
        groups.setdefault(w.code, []).append(w)
    # problems, then what makes the verdict uncertain, then the other warnings, then information
    codes = sorted(groups, key=lambda c: (levels.index(severity(c)), c not in UNCERTAIN_CODES, order.get(c, 99)))
    counts = [
        f"{n} {level}{'s' if n > 1 and level != 'info' else ''}"  # notes, of each severity
        for level in levels
        if (n := sum(severity(w.code) == level for w in warnings))
    ]
    more = "" if verbose else " (what to do, full texts: --verbose, --json, --report)"
    print(f"notes: {', '.join(counts)}{more}", file=sys.stderr)
    if verbose:
        lines = [
            line for code in codes for line in _verbose_block(code, groups[code], advice.get(code, ""), severity(code))
        ]
    else:
        lines = [_code_line(code, groups[code], severity(code)) for code in codes[:NOTE_LINES]]
    print("\n".join(lines), file=sys.stderr)
    if not verbose and len(codes) > NOTE_LINES:
        print(f"  ... {len(codes) - NOTE_LINES} more codes (--verbose)", file=sys.stderr)


def _code_head(code: str, notes: list, level: str) -> str:
    """``  <severity> <code> (<how many>, <channels>, at <frequencies>): ``."""
    channels = sorted({c for w in notes for c in w.channels})
    where = f", {', '.join(channels)}" if channels and len(", ".join(channels)) <= 30 else ""
    # each frequency once, to 0.01 Hz, or to three digits below 1 Hz (a drift's 0.00417 Hz is not 0)
    shown_hz = {round(f, 2) if abs(f) >= 1 else float(f"{f:.3g}") for w in notes for f in w.freq_hz}
    return f"  {level:<8}{code} ({len(notes)}{where}{_frequencies(sorted(shown_hz))}): "


def _code_line(code: str, notes: list, level: str) -> str:
    """A code's line on the screen: its head and what was found, within ``NOTE_WIDTH``."""
    head = _code_head(code, notes, level)
    others = f" (+{len(notes) - 1} more)" if len(notes) > 1 else ""
    budget = max(10, NOTE_WIDTH - len(head) - len(others))
    return (head + headline(notes[0].message, budget) + others)[:NOTE_WIDTH]


def _verbose_block(code: str, notes: list, advice: str, level: str) -> list[str]:
    """A code's advice on its line, every note's full text under it."""
    texts = [
        textwrap.fill(w.message, NOTE_WIDTH, initial_indent="      - ", subsequent_indent="        ") for w in notes
    ]
    return [_code_head(code, notes, level) + advice, *texts]


def headline(text: str, width: int) -> str:
    """What a note found, in at most ``width`` characters: its text without the asides in
    parentheses, as much of it as fits, cut where a clause or a list item ends (at '.', ':', ';' or
    ','), or at a word where that would leave less than half the width, marked '...' where a
    sentence was cut.

    Parameters
    ----------
    text : str
        A note's full text.
    width : int
        Characters available, at least 10.

    Returns
    -------
    str

    Raises
    ------
    ValueError
        ``width`` below 10: no cut with its mark fits.

    Examples
    --------
    >>> from armaxmodal.cli.common import headline
    >>> headline("'head' lags input 'base' by 32.9 ms (95 % interval 32.2 to 33.5 ms). Aligned by 2 samples.", 60)
    "'head' lags input 'base' by 32.9 ms. Aligned by 2 samples."
    >>> headline("a stable pole at 1.5 Hz is left out: the measured FRF does not need it", 40)
    'a stable pole at 1.5 Hz is left out ...'
    """
    if width < 10:
        raise ValueError(f"width: expected at least 10 characters, got {width}.")
    plain = text
    while (shorter := re.sub(r"\s+\([^()]*\)", "", plain)) != plain:  # asides, innermost first; not "sample(s)"
        plain = shorter
    plain = re.sub(r"\s+", " ", plain).strip()
    if len(plain) <= width:
        return plain
    kept = ""
    for piece in re.findall(r".+?(?:[.:;,](?=\s)|$)", plain):
        if len(kept + piece) > width - 4:
            break
        kept += piece
    if len(kept) < width // 2:  # the next clause is long: as many of its words as fit say more
        return _cut(plain, width)
    kept = kept.rstrip()
    return kept if kept.endswith(".") else kept.rstrip(":;,") + " ..."


def _cut(text: str, width: int) -> str:
    """``text`` within ``width`` characters, cut at a word and marked, where longer."""
    return text if len(text) <= width else text[: width - 4].rsplit(" ", 1)[0] + " ..."


def _frequencies(freqs: list[float], shown: int = 4) -> str:
    """The notes' frequencies for their code's line: up to ``shown`` of them, else the range."""
    if not freqs:
        return ""
    if len(freqs) <= shown:
        return f", at {', '.join(f'{f:.4g}' for f in freqs)} Hz"
    return f", at {len(freqs)} frequencies {freqs[0]:.4g}-{freqs[-1]:.4g} Hz"


def write_outputs(outputs) -> None:
    """All outputs or none, then the figures closed."""
    try:
        write_all(outputs)
    finally:
        # pyplot is loaded only when a figure was drawn; importing it to close nothing
        # cost every run without --plot 0.7 s
        if "matplotlib.pyplot" in sys.modules:
            sys.modules["matplotlib.pyplot"].close("all")


def check_report_path(path: str) -> None:
    """``--report FILE``: an .html name in a folder that exists, refused before any work."""
    target = Path(path)
    if target.suffix.lower() not in (".html", ".htm"):
        raise DataError(f"--report: expected an .html file name, got {path!r}.")
    if not target.parent.is_dir():
        raise DataError(f"--report {path}: the folder {str(target.parent)!r} does not exist; create it first.")


def output_format(path: str, option: str = "--plot") -> str:
    ext = path.rsplit(".", 1)[-1].lower()
    if ext not in ("png", "svg", "pdf"):
        raise DataError(f"{option}: expected a .png, .svg or .pdf file name, got {path!r}.")
    return ext


DETREND_HELP = (
    "remove each channel's mean (default) or least-squares line before fitting, and any level shift "
    "(a sensor offset jumping mid-record); 'none' only reports them"
)


SYSTEMS = {"supine": datasets.supine_human, "chapter2": datasets.chapter2_system}
