"""sphinx-gallery scraper: the figure files an example writes, shown in its page.

pamsim draws on matplotlib ``Figure`` objects of its own, which pyplot (and so sphinx-gallery's
matplotlib scraper) never sees; an example writes them the way a reader would
(``result.plot("fig4.png")``).  After each code block, the PNG and SVG files the block wrote into the
example's folder (the folder the gallery runs it in) are moved into the gallery's images, so that the
page shows the files the reader's own run writes and the source tree keeps none of them.  Files older
than the block (left there by a reader's own run) are left alone.
"""

from __future__ import annotations

import time
from pathlib import Path

EXTENSIONS = ("png", "svg")

# The blocks run one after another, so a block's files are newer than the scrape after the block before
# (less a second: file times may lag the clock by a tick; the previous block's files are gone by then).
SLACK_S = 1.0
_since = time.time() - SLACK_S


def scrape_written_images(block, block_vars, gallery_conf) -> str:
    """Move the image files the block wrote into the gallery and return the reST that shows them."""
    global _since
    from sphinx_gallery.scrapers import figure_rst

    folder = Path(block_vars["src_file"]).parent
    written = sorted(p for ext in EXTENSIONS for p in folder.glob(f"*.{ext}") if p.stat().st_mtime >= _since)
    _since = time.time() - SLACK_S
    shown = []
    for src, target in zip(written, block_vars["image_path_iterator"]):
        target = Path(target).with_suffix(src.suffix)
        src.replace(target)
        shown.append(str(target))
    return figure_rst(shown, gallery_conf["src_dir"])


def _get_sg_image_scraper():
    """sphinx-gallery's hook: ``image_scrapers = ("gallery_images", ...)`` names this module."""
    return scrape_written_images
