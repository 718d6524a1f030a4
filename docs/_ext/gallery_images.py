"""sphinx-gallery scraper: the figure files an example writes, shown in its page.

pamsim draws on matplotlib ``Figure`` objects of its own, which pyplot (and so sphinx-gallery's
matplotlib scraper) never sees; an example writes them the way a reader would
(``result.plot("fig4.png")``).  After each code block, the PNG and SVG files in the example's folder
(the folder the gallery runs it in) are moved into the gallery's images, so that the page shows
the files the reader's own run writes and the source tree keeps none of them.
"""

from __future__ import annotations

from pathlib import Path

EXTENSIONS = ("png", "svg")


def scrape_written_images(block, block_vars, gallery_conf) -> str:
    """Move the image files the block wrote into the gallery and return the reST that shows them."""
    from sphinx_gallery.scrapers import figure_rst

    folder = Path(block_vars["src_file"]).parent
    written = sorted(p for ext in EXTENSIONS for p in folder.glob(f"*.{ext}"))
    shown = []
    for src, target in zip(written, block_vars["image_path_iterator"]):
        target = Path(target).with_suffix(src.suffix)
        src.replace(target)
        shown.append(str(target))
    return figure_rst(shown, gallery_conf["src_dir"])


def _get_sg_image_scraper():
    """sphinx-gallery's hook: ``image_scrapers = ("gallery_images", ...)`` names this module."""
    return scrape_written_images
