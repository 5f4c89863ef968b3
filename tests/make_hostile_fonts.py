#!/usr/bin/env python3
"""Makes small TrueType fonts that expand to huge work, for the baker's limits (docs/limits.md),
with fontTools (Debian: python3-fonttools).

    make_hostile_fonts.py composites OUT [PARTS]
        30 glyphs ('A' to '^'), each a three-level composite of PARTS x PARTS x PARTS empty parts
        (PARTS 1000, the default: 200 KB, and FreeType would load 10^9 parts a glyph). Then composites of one part nested 1
        to 9 deep ('a' to 'i') and one that contains itself ('z').
    make_hostile_fonts.py curve-composites GLYPHS OUT
        one glyph of 1024 squares (4096 curves, the most a glyph may have) and GLYPHS - 2
        composites of it: a 4096-curve glyph for every 6 bytes of the font.
    make_hostile_fonts.py gsub-multiply OUT [COUNT]
        'A' is substituted (GSUB multiple substitution, ccmp) by COUNT (default 1000) small squares,
        'B' is one square: a character of 'A' makes COUNT glyphs.
"""
import logging
import sys

from fontTools.fontBuilder import FontBuilder
from fontTools.pens.ttGlyphPen import TTGlyphPen
from fontTools.ttLib import newTable
from fontTools.ttLib.tables._g_l_y_f import Glyph, GlyphComponent


def composite(name, count):
    glyph = Glyph()
    glyph.numberOfContours = -1
    glyph.components = []
    for _ in range(count):
        component = GlyphComponent()
        component.glyphName = name
        component.x = component.y = 0
        component.flags = 0x0002  # ARGS_ARE_XY_VALUES, byte arguments
        glyph.components.append(component)
    return glyph


def squares(count):
    pen = TTGlyphPen(None)
    for i in range(count):
        x, y = 20 * (i % 32), 20 * (i // 32)
        pen.moveTo((x, y))
        for corner in ((x, y + 10), (x + 10, y + 10), (x + 10, y)):
            pen.lineTo(corner)
        pen.closePath()
    return pen.glyph()


def build(glyphs, cmap, out, features=None, advance=700):
    names = list(glyphs)
    builder = FontBuilder(1000, isTTF=True)
    builder.setupGlyphOrder(names)
    builder.setupCharacterMap(cmap)
    # Set up by hand: FontBuilder.setupGlyf and fontTools' bounds and maxp would expand every
    # composite (10^9 parts).
    for glyph in glyphs.values():
        if glyph.isComposite() or not hasattr(glyph, "xMin"):
            glyph.xMin = glyph.yMin = glyph.xMax = glyph.yMax = 0
    glyf = newTable("glyf")
    glyf.glyphs = glyphs
    glyf.glyphOrder = names
    builder.font["glyf"] = glyf
    builder.font["loca"] = newTable("loca")
    builder.setupMaxp()
    builder.setupHorizontalMetrics({name: (advance, 0) for name in names})
    builder.setupHorizontalHeader(ascent=800, descent=-200)
    builder.setupNameTable({"familyName": "Hostile", "styleName": "Regular"})
    builder.setupOS2()
    builder.setupPost(keepGlyphNames=False)  # format 2 cannot name 65,535 glyphs
    builder.font.recalcBBoxes = False
    if features is not None:
        builder.addOpenTypeFeatures(features)
    builder.save(out)


def main():
    logging.getLogger("fontTools").setLevel(logging.ERROR)
    if len(sys.argv) in (3, 4) and sys.argv[1] == "composites":
        parts = int(sys.argv[3]) if len(sys.argv) == 4 else 1000
        glyphs = {".notdef": Glyph(), "leaf": Glyph(), "mid": composite("leaf", parts), "upper": composite("mid", parts)}
        cmap = {}
        for i in range(30):
            glyphs["top%d" % i] = composite("upper", parts)
            cmap[ord("A") + i] = "top%d" % i
        for depth in range(1, 10):
            glyphs["deep%d" % depth] = composite("deep%d" % (depth - 1) if depth > 1 else "leaf", 1)
            cmap[ord("a") + depth - 1] = "deep%d" % depth
        glyphs["loop"] = composite("loop", 1)
        cmap[ord("z")] = "loop"
        build(glyphs, cmap, sys.argv[2])
    elif len(sys.argv) == 4 and sys.argv[1] == "curve-composites":
        count = int(sys.argv[2])
        glyphs = {".notdef": Glyph(), "dense": squares(1024)}
        for i in range(count - 2):
            glyphs["c%d" % i] = composite("dense", 1)
        build(glyphs, {ord("A"): "dense", ord("B"): "c0"}, sys.argv[3])
    elif len(sys.argv) in (3, 4) and sys.argv[1] == "gsub-multiply":
        count = int(sys.argv[3]) if len(sys.argv) == 4 else 1000
        glyphs = {".notdef": Glyph(), "A": squares(1), "square": squares(1)}
        features = "feature ccmp { sub A by %s; } ccmp;" % " ".join(["square"] * count)
        build(glyphs, {ord("A"): "A", ord("B"): "square"}, sys.argv[2], features, advance=20)
    else:
        sys.exit(__doc__)


if __name__ == "__main__":
    main()
