"""The ``tfloc`` command. One small module per subcommand in this package (evo-style).

Each module defines ``HELP`` (one line), ``add_arguments(parser)`` and ``run(args) -> int``;
they are discovered by name, so adding a command is adding a file.
"""

from __future__ import annotations

import argparse
import importlib
import pkgutil
import sys

from tfloc.errors import TflocError


def _commands() -> dict[str, object]:
    mods = {}
    for info in pkgutil.iter_modules(__path__):
        if info.name.startswith("_"):
            continue
        mods[info.name.replace("_", "-")] = importlib.import_module(f"{__name__}.{info.name}")
    return dict(sorted(mods.items()))


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="tfloc",
        description="2D laser localization benchmark: the turning-function matcher of the paper "
                    "and baselines, run on the same scans and compared.",
        epilog="Run 'tfloc COMMAND --help' for a command's options.")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND", required=True)
    for name, mod in _commands().items():
        p = sub.add_parser(name, help=mod.HELP, description=(mod.__doc__ or mod.HELP).strip(),
                           formatter_class=argparse.RawDescriptionHelpFormatter)
        mod.add_arguments(p)
        p.set_defaults(_run=mod.run)
    return parser


def main(argv: list[str] | None = None) -> int:
    """Entry point: exits non-zero with a one-line message (no traceback) on a TflocError."""
    args = build_parser().parse_args(argv)
    try:
        return int(args._run(args) or 0)
    except TflocError as exc:
        print(f"tfloc {args.command}: error: {exc}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print(f"tfloc {args.command}: interrupted", file=sys.stderr)
        return 130


if __name__ == "__main__":
    sys.exit(main())
