"""``armaxmodal modes``: the exact modes of a reference structure from the thesis."""

from __future__ import annotations

from armaxmodal.cli.common import SYSTEMS
from armaxmodal.io.write import write_json


def add_parser(sub, parents) -> None:
    """Register the ``modes`` command."""
    p = sub.add_parser("modes", parents=parents, help="exact modes of a reference structure from the thesis")
    p.add_argument(
        "--system",
        choices=sorted(SYSTEMS),
        default="supine",
        help="the structure: the thesis's supine body (Table 4.3) or Chapter 2's chain; default supine",
    )
    p.add_argument("--json", default=None, help="write the modes as JSON")
    p.set_defaults(func=run)


def run(args) -> int:
    modes = SYSTEMS[args.system]().modes()
    print(modes.to_frame().to_string(index=False, float_format=lambda v: f"{v:.4f}"))
    if args.json:
        write_json(modes.to_dict(), args.json)
        if not args.quiet:
            print(f"wrote {args.json}")
    return 0
