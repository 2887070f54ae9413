"""The ``armaxmodal`` command: one module per command, their shared helpers in
:mod:`armaxmodal.cli.common`, the parser and entry point in :mod:`armaxmodal.cli.main`."""

from armaxmodal.cli.main import build_parser, main, run

__all__ = ["build_parser", "main", "run"]
