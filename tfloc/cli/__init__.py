"""The ``tfloc`` command. One small module per subcommand in this package (evo-style).

Each module defines ``HELP`` (one line), ``add_arguments(parser)`` and ``run(args) -> int``;
they are discovered by name, so adding a command is adding a file.
"""

from __future__ import annotations

import argparse
import importlib
import pkgutil
import sys
import textwrap

from tfloc.errors import TflocError


def _commands() -> dict[str, object]:
    mods = {}
    for info in pkgutil.iter_modules(__path__):
        if info.name.startswith("_"):
            continue
        mods[info.name.replace("_", "-")] = importlib.import_module(f"{__name__}.{info.name}")
    return dict(sorted(mods.items()))


class HelpFormatter(argparse.RawDescriptionHelpFormatter):
    """A command's description as written (its examples line by line); option help wrapped at
    spaces only, so that names like ``csm-corr`` never break across lines."""

    def _split_lines(self, text: str, width: int) -> list[str]:
        return textwrap.wrap(" ".join(text.split()), width, break_on_hyphens=False, break_long_words=False)


def version() -> str:
    """tfloc's version, and the commit of the checkout it runs from when there is one."""
    from importlib import metadata

    from tfloc.harness.identity import git_state

    try:
        v = metadata.version("tfloc")
    except metadata.PackageNotFoundError:
        v = "unknown"
    git = git_state()
    where = ""
    if git.get("commit"):
        where = f" (commit {git['commit'][:12]}{', with uncommitted changes' if git.get('dirty') else ''})"
    return f"tfloc {v}{where}"


class _Version(argparse.Action):
    def __init__(self, option_strings, dest=argparse.SUPPRESS, **kw) -> None:
        super().__init__(option_strings, dest, nargs=0, help="print tfloc's version (and commit) and exit")

    def __call__(self, parser, namespace, values, option_string=None) -> None:
        print(version())
        parser.exit()


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="tfloc", formatter_class=HelpFormatter,
        description="2D laser localization benchmark: the turning-function matcher of the paper "
                    "and baselines, run on the same scans and compared.",
        epilog="Run 'tfloc COMMAND --help' for a command's options; 'tfloc matchers' lists the "
               "matchers and presets.")
    parser.add_argument("--version", action=_Version)
    sub = parser.add_subparsers(dest="command", metavar="COMMAND", required=True)
    for name, mod in _commands().items():
        p = sub.add_parser(name, help=mod.HELP, description=(mod.__doc__ or mod.HELP).strip(),
                           formatter_class=HelpFormatter)
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
