"""Write a static site of leaderboards from the run directories: OUT/index.html (one leaderboard
per question, sortable by any column, filterable by matcher family, "which localizer for which
robot" computed from the rows) and one page per run (its report, timing and provenance, with its
figures). It opens from disk: no server, no network. Which runs each leaderboard reads is
declared once, in tfloc/site/pages.toml.

--readme also renders the generated blocks (<!-- tfloc:begin NAME --> … <!-- tfloc:end NAME -->)
of README.md and docs/*.md in the current directory from the same rows; --only-registry renders
only the blocks drawn from the matcher registry (docs/matchers.md's table: every matcher the
project's modules declare), reading no run and writing no site; --screenshots writes
OUT/screenshots/index-1280.png and index-390.png with headless Chromium (make browser).

Examples:
  tfloc site
  tfloc site --readme --screenshots
  tfloc site --only-quick          # make quick's runs (results/*-quick) → results/site-quick/
  tfloc site --only-registry       # docs/matchers.md's table after adding a matcher
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

HELP = "write a static site of leaderboards from the run directories (results/site/index.html)"


def add_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument("--results", type=Path, default=Path("results"), metavar="DIR",
                   help="the results root holding the run directories (default: results)")
    p.add_argument("--out", type=Path, metavar="DIR",
                   help="where to write the site (default: DIR/site, with --only-quick DIR/site-quick)")
    p.add_argument("--only-quick", action="store_true",
                   help="read make quick's runs (each run directory's -quick variant)")
    p.add_argument("--readme", action="store_true",
                   help="also refresh the generated blocks of README.md and docs/*.md here")
    p.add_argument("--only-registry", action="store_true",
                   help="only refresh the generated blocks drawn from the matcher registry "
                        "(docs/matchers.md's table) here: no run read, no site written")
    p.add_argument("--screenshots", nargs="?", const=True, default=None, metavar="DIR",
                   help="also write index-1280.png and index-390.png (default DIR: OUT/screenshots)")


def run(args: argparse.Namespace) -> int:
    from tfloc.errors import ConfigError
    from tfloc.site.build import build_site, markdown_files, refresh_markdown
    from tfloc.site.shots import screenshots

    if args.only_registry:
        changed = refresh_markdown(markdown_files(Path.cwd()), None)
        print(f"generated blocks: {', '.join(str(f) for f in changed) if changed else 'unchanged'}",
              file=sys.stderr)
        return 0
    if args.readme and args.only_quick:
        raise ConfigError("--readme renders the committed runs' blocks: not with --only-quick")
    if not args.results.is_dir():
        raise ConfigError(f"{args.results}: no such results directory")
    out = args.out or args.results / ("site-quick" if args.only_quick else "site")
    from tfloc.harness.identity import derived_code

    data = build_site(args.results, out, quick=args.only_quick, generator=derived_code("tfloc.site.build")[:12])
    shown = sum(1 for r in data.runs.values() if r.rows)
    missing = [n for n, r in data.runs.items() if not r.exists]
    unreported = [n for n, r in data.runs.items() if r.exists and not r.reported]
    print(f"site: {out / 'index.html'} ({shown} runs{'; not yet run: ' + ', '.join(missing) if missing else ''}"
          f"{'; no headline.csv yet (tfloc report RUN): ' + ', '.join(unreported) if unreported else ''})",
          file=sys.stderr)
    if args.readme:
        changed = refresh_markdown(markdown_files(Path.cwd()), data)
        print(f"generated blocks: {', '.join(str(f) for f in changed) if changed else 'unchanged'}",
              file=sys.stderr)
    if args.screenshots is not None:
        where = out / "screenshots" if args.screenshots is True else Path(args.screenshots)
        for f in screenshots(out / "index.html", where):
            print(f"screenshot: {f}", file=sys.stderr)
    return 0
