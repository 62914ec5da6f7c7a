"""Screenshots of the site's index at a desktop's and a phone's width, taken by headless
Chromium from Debian's package (``make browser`` installs it; no browser is downloaded):
``screenshots/index-1280.png`` and ``index-390.png`` (widths in CSS px)."""

from __future__ import annotations

import shutil
import subprocess
import tempfile
from pathlib import Path

from tfloc.errors import ConfigError

#: (width, height) of each screenshot, CSS px
SIZES = ((1280, 1800), (390, 1800))
BROWSERS = ("chromium", "chromium-browser", "google-chrome")


def browser() -> str:
    """The Chromium executable on PATH."""
    for name in BROWSERS:
        if path := shutil.which(name):
            return path
    raise ConfigError("no Chromium found for the screenshots: run 'make browser' (Debian's chromium)")


def screenshots(index: Path, out_dir: Path, timeout_s: float = 60.0) -> list[Path]:
    """Screenshots of ``index`` at every :data:`SIZES` into ``out_dir``; their paths."""
    out_dir.mkdir(parents=True, exist_ok=True)
    exe, written = browser(), []
    for w, h in SIZES:
        dst = out_dir / f"index-{w}.png"
        with tempfile.TemporaryDirectory(prefix="tfloc-chromium-") as profile:
            cmd = [exe, "--headless=new", "--no-sandbox", "--disable-gpu", "--disable-dev-shm-usage",
                   "--disable-background-networking", "--disable-component-update", "--disable-sync",
                   "--no-first-run", "--hide-scrollbars", f"--user-data-dir={profile}",
                   f"--window-size={w},{h}", f"--screenshot={dst}", Path(index).resolve().as_uri()]
            r = subprocess.run(cmd, capture_output=True, text=True, timeout=timeout_s)
        if r.returncode != 0 or not dst.is_file():
            raise ConfigError(f"chromium could not take {dst.name}: {r.stderr.strip()[-300:]}")
        written.append(dst)
    return written
