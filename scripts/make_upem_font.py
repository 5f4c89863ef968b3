#!/usr/bin/env python3
"""Makes a test font with a different units-per-em: a subset of FONT (the glyphs TEXT needs),
its outlines and metrics scaled to UPEM units per em, with fontTools (Debian: python3-fonttools).

    make_upem_font.py FONT TEXT UPEM OUT
"""
import logging
import sys

from fontTools import subset
from fontTools.ttLib import TTFont
from fontTools.ttLib.scaleUpem import scale_upem


def subset_font(source, text):
    """The glyphs of FONT that TEXT needs, without names (also tests/make_font_faults.py's)."""
    logging.getLogger("fontTools").setLevel(logging.ERROR)  # tables it drops are expected
    font = TTFont(source)
    options = subset.Options()
    options.name_IDs = []  # no names: the derived font carries none of the original's
    options.notdef_outline = True
    subsetter = subset.Subsetter(options)
    subsetter.populate(text=text)
    subsetter.subset(font)
    return font


def main():
    if len(sys.argv) != 5:
        sys.exit(__doc__)
    source, text, upem, out = sys.argv[1], sys.argv[2], int(sys.argv[3]), sys.argv[4]
    font = subset_font(source, text)
    scale_upem(font, upem)
    font.save(out)


if __name__ == "__main__":
    main()
