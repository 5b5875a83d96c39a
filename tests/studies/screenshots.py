"""Headless Chromium screenshots of the HTML reports, and the pixel counts their tests read."""

from __future__ import annotations

import shutil
import subprocess
from pathlib import Path

import numpy as np
import pytest
from matplotlib.image import imread

CHROMIUM = shutil.which("chromium") or shutil.which("chromium-browser")
needs_chromium = pytest.mark.skipif(CHROMIUM is None,
                                    reason="chromium is not installed (CI installs it)")

# A page must render from its own file: any request would leave through a dead proxy, and
# the browser's own background traffic (updates, accounts) is switched off.
OFFLINE = ("--proxy-server=127.0.0.1:9", "--host-resolver-rules=MAP * ~NOTFOUND",
           "--disable-background-networking", "--disable-component-update", "--disable-sync",
           "--no-first-run", "--disable-default-apps")


def screenshot(page: Path, shot: Path, height: int, *flags: str) -> np.ndarray:
    """`page` rendered 1280 px wide and `height` px tall: its RGB pixels, shape (n, 3), uint8."""
    subprocess.run([CHROMIUM, "--headless=new", "--no-sandbox", "--disable-gpu",
                    "--hide-scrollbars", f"--window-size=1280,{height}", f"--screenshot={shot}",
                    *OFFLINE, *flags, page.resolve().as_uri()],
                   check=True, capture_output=True, timeout=120)
    return np.round(imread(shot)[..., :3] * 255).astype(np.uint8).reshape(-1, 3)


def n_colours(pixels: np.ndarray) -> int:
    """How many distinct colours: each RGB triple packed into one integer (``np.unique`` over
    rows of a 6000 x 1280 screenshot sorts 7.7 M rows: ~6 s; the packed integers ~0.1 s)."""
    packed = (pixels[:, 0].astype(np.uint32) << 16) | (pixels[:, 1].astype(np.uint32) << 8) \
        | pixels[:, 2]
    return int(np.unique(packed).size)


def n_close(pixels: np.ndarray, rgb: tuple[int, int, int], tol: int = 12) -> int:
    """How many pixels are within `tol` of `rgb` in each channel."""
    return int(np.all(np.abs(pixels.astype(np.int16) - np.array(rgb, np.int16)) <= tol,
                      axis=1).sum())
