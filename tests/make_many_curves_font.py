#!/usr/bin/env python3
"""Makes a test font whose 'H' is a grid of COUNT small squares (4 * COUNT line segments, each one
curve once baked): a glyph that is cheap to store and dear to rasterize. With `bars`, the 'H' is
COUNT thin bars of the glyph's full height instead, so that every band lists both sides of every
bar (2 * COUNT curves a band, the dearest glyph a font can hold). From FONT (a TrueType font with
an 'H'), with fontTools (Debian: python3-fonttools).

    make_many_curves_font.py FONT COUNT OUT [squares|bars]
"""
import logging
import math
import sys

from fontTools import subset
from fontTools.pens.ttGlyphPen import TTGlyphPen
from fontTools.ttLib import TTFont


def main():
    if len(sys.argv) not in (4, 5) or sys.argv[4:] not in ([], ["squares"], ["bars"]):
        sys.exit(__doc__)
    source, count, out = sys.argv[1], int(sys.argv[2]), sys.argv[3]
    bars = sys.argv[4:] == ["bars"]
    logging.getLogger("fontTools").setLevel(logging.ERROR)
    font = TTFont(source)
    options = subset.Options()
    options.name_IDs = []
    options.notdef_outline = True
    subsetter = subset.Subsetter(options)
    subsetter.populate(text="H")
    subsetter.subset(font)

    name = font.getBestCmap()[ord("H")]
    upem = font["head"].unitsPerEm
    columns = math.ceil(math.sqrt(count))
    pitch = upem * 0.7 / columns  # the grid fills 0.7 em square
    side = pitch * 0.6
    pen = TTGlyphPen(None)
    for i in range(count):
        if bars:
            # Bars one unit wide and 0.7 em tall, spread over 0.7 em.
            x = round(upem * 0.05 + i * upem * 0.7 / count)
            corners = [(x, 0), (x, round(upem * 0.7)), (x + 1, round(upem * 0.7)), (x + 1, 0)]
        else:
            x = round(upem * 0.05 + (i % columns) * pitch)
            y = round((i // columns) * pitch)
            s = max(1, round(side))
            # Counter-clockwise and clockwise squares alternate, so that winding numbers vary.
            corners = [(x, y), (x, y + s), (x + s, y + s), (x + s, y)]
        if i % 2:
            corners.reverse()
        pen.moveTo(corners[0])
        for corner in corners[1:]:
            pen.lineTo(corner)
        pen.closePath()
    glyph = pen.glyph()
    font["glyf"][name] = glyph
    glyph.recalcBounds(font["glyf"])
    font["hmtx"][name] = (round(upem * 0.8), glyph.xMin)
    font.save(out)


if __name__ == "__main__":
    main()
