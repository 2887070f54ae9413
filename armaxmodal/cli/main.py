"""Command-line interface: a thin layer over the public API, one module per command.

armaxmodal stabilise DATA [--orders LO:HI] [--band LO:HI] [--modes N | --pick F1,F2] [--plot OUT] [--json OUT]
                          [--csv OUT] [--uff OUT] [--shapes-plot OUT] [--positions S=P,...] [--report OUT.html]
armaxmodal invert MODES.json|MODES.uff [--recording DATA] [--method ...] [--total-mass KG] [--json OUT]
armaxmodal identify DATA [--model auto|na,nb,nc,nk] [--band LO:HI] [--json OUT] [--csv OUT]
armaxmodal diagnose DATA [--input COL] [--fs HZ] [--json OUT] [--plot OUT] [--report OUT.html]
armaxmodal info DATA [--input COL] [--fs HZ]
armaxmodal modes --system supine|chapter2 [--json OUT]
armaxmodal simulate --system supine --excitation random|sweep --out DATA.csv
armaxmodal study MANIFEST_OR_FOLDER --out DIR [--report FILE] [--jobs N] [--scheduler ADDRESS]
armaxmodal track MANIFEST_OR_FOLDER --out DIR [--jobs N] [--scheduler ADDRESS] [--input-scale F --input-unit U]
armaxmodal lump DATA A B [--json OUT] [--plot OUT]

Every command that reads a recording takes --input COL, --fs HZ, --outputs A,B and --fill-gaps SECONDS.
"""

from __future__ import annotations

import argparse
import ctypes
import gc
import os
import sys
from collections.abc import Sequence

from armaxmodal.cli import diagnose, identify, info, invert, lump, modes, simulate, stabilise, study, track
from armaxmodal.cli.common import check_output_paths
from armaxmodal.exceptions import ArmaxModalError

#: the commands in the order ``--help`` lists them
COMMANDS = (stabilise, invert, identify, diagnose, info, modes, simulate, study, track, lump)


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="armaxmodal", description="Time-domain modal analysis of base-excited systems."
    )
    parser.add_argument("--quiet", action="store_true", help="no progress bars (the results still print)")
    # --quiet is accepted after the command too; SUPPRESS keeps a subcommand's unset default
    # from overwriting the top-level flag
    parser.add_argument("--verbose", action="store_true", help="every note's full text, not one line per code")
    quiet = argparse.ArgumentParser(add_help=False)
    quiet.add_argument(
        "--quiet", action="store_true", default=argparse.SUPPRESS, help="no progress bars (the results still print)"
    )
    quiet.add_argument(
        "--verbose",
        action="store_true",
        default=argparse.SUPPRESS,
        help="every note's full text, not one line per code",
    )
    sub = parser.add_subparsers(dest="command", required=True)
    for command in COMMANDS:
        command.add_parser(sub, [quiet])
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    # the command line draws to files only: a non-GUI backend unless the user chose one (set
    # here, by the application; no library function changes matplotlib's backend)
    os.environ.setdefault("MPLBACKEND", "Agg")
    parser = build_parser()
    args = parser.parse_args(argv)
    args.command_line = ["armaxmodal", *(sys.argv[1:] if argv is None else argv)]  # as run, for the reports
    try:
        check_output_paths(args)
        return args.func(args)
    except (ArmaxModalError, FileNotFoundError) as exc:
        print(f"armaxmodal: error: {exc}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        # outputs are staged and moved in whole, so an interrupted run leaves none behind
        print("armaxmodal: interrupted; no output was written.", file=sys.stderr)
        return 130


def _one_malloc_arena() -> None:
    """Let glibc's malloc keep one heap for every thread of this process.

    By default glibc gives each thread that allocates its own heap ("arena"), so the
    record-length arrays that the two worker threads free stay in two heaps: a one-hour
    ride (432,000 x 4) peaked at 738 MB with them and at 587 MB with one, in the same time.
    Only the command's own process is tuned: a program that calls the library keeps its
    allocator as it is. Other C libraries have no such setting and are left alone.
    """
    try:
        libc = ctypes.CDLL("libc.so.6")
    except OSError:  # not glibc (macOS, Windows, musl): nothing of this kind to set
        return
    m_arena_max = -8  # from glibc's malloc.h
    libc.mallopt(m_arena_max, 1)


def run() -> None:
    """Console entry point: :func:`main`, then exit with its status."""
    _one_malloc_arena()  # before any worker thread allocates
    status = main()
    # The process ends here with every output written and closed. Moving the live objects
    # (the imported libraries, the fits) out of the collector's reach spares the
    # interpreter's final collection, about 0.4 s of a 5 s command; only that scan is
    # skipped. Not in main(): called in-process, it would pin the caller's objects.
    gc.freeze()
    sys.exit(status)
