#!/usr/bin/python3
"""Makes a small emoji test font: emoji characters, skin tones, regional indicators, tags, ZWJ and
the keycap as plain boxes, and the ligatures an emoji font forms of their sequences, in 'ccmp' as
Noto Color Emoji has them (U+FE0F has no glyph, as there: HarfBuzz skips it inside a keycap). The
colour layers are added to the baked asset by the tests; the font has no COLR table.

    make_emoji_font.py OUT.ttf

Needs fontTools (Debian's python3-fonttools)."""

import sys

from fontTools.feaLib.builder import addOpenTypeFeaturesFromString
from fontTools.fontBuilder import FontBuilder
from fontTools.pens.ttGlyphPen import TTGlyphPen

UNITS_PER_EM = 1000

# Code point, glyph name, advance.
CHARACTERS = [
    (0x20, "space", 300),
    (0x23, "numbersign", 600),
] + [(0x30 + d, name, 600) for d, name in enumerate(
    ["zero", "one", "two", "three", "four", "five", "six", "seven", "eight", "nine"])] + [
    (0x200D, "uni200D", 0),
    (0x20E3, "uni20E3", 0),
    (0x2764, "uni2764", 1000),
] + [(cp, f"u{cp:05X}", 1000) for cp in (0x1F1F8, 0x1F1FA, 0x1F3F4, 0x1F3FB, 0x1F3FD, 0x1F44D, 0x1F467,
                                          0x1F468, 0x1F469, 0x1F600)
] + [(cp, f"u{cp:05X}", 0) for cp in (0xE0062, 0xE0065, 0xE0067, 0xE006E, 0xE007F)]

LIGATURES = [
    ("keycap_one", "one uni20E3"),
    ("keycap_numbersign", "numbersign uni20E3"),
    ("flag_us", "u1F1FA u1F1F8"),
    ("flag_gbeng", "u1F3F4 uE0067 uE0062 uE0065 uE006E uE0067 uE007F"),
    ("thumbs_tone3", "u1F44D u1F3FD"),
    ("thumbs_tone1", "u1F44D u1F3FB"),
    ("family_mwg", "u1F468 uni200D u1F469 uni200D u1F467"),
]


def box(index, advance):
    """A box inside the advance (or a small one for zero-width glyphs), its height varying with
    the glyph so that glyphs differ."""
    pen = TTGlyphPen(None)
    width = advance if advance > 0 else 200
    left, right = 50, width - 50
    bottom, top = 0, 300 + (index * 37) % 500
    pen.moveTo((left, bottom))
    pen.lineTo((left, top))
    pen.lineTo((right, top))
    pen.lineTo((right, bottom))
    pen.closePath()
    return pen.glyph()


def main(out):
    order = [".notdef"] + [name for _, name, _ in CHARACTERS] + [name for name, _ in LIGATURES]
    advances = {".notdef": 500, **{name: advance for _, name, advance in CHARACTERS},
                **{name: 1000 for name, _ in LIGATURES}}
    glyphs = {}
    for index, name in enumerate(order):
        glyphs[name] = TTGlyphPen(None).glyph() if name == "space" else box(index, advances[name])
    builder = FontBuilder(UNITS_PER_EM, isTTF=True)
    builder.setupGlyphOrder(order)
    builder.setupCharacterMap({cp: name for cp, name, _ in CHARACTERS})
    builder.setupGlyf(glyphs)
    # Every box starts 50 units right of the pen.
    builder.setupHorizontalMetrics({name: (advances[name], 0 if name == "space" else 50) for name in order})
    builder.setupHorizontalHeader(ascent=800, descent=-200)
    builder.setupNameTable({"familyName": "crisp emoji test", "styleName": "Regular"})
    builder.setupOS2(sTypoAscender=800, sTypoDescender=-200, usWinAscent=800, usWinDescent=200)
    builder.setupPost()
    rules = "\n".join(f"  sub {components} by {name};" for name, components in LIGATURES)
    addOpenTypeFeaturesFromString(builder.font, f"languagesystem DFLT dflt;\nfeature ccmp {{\n{rules}\n}} ccmp;\n")
    builder.save(out)


if __name__ == "__main__":
    if len(sys.argv) != 2:
        sys.exit("usage: make_emoji_font.py OUT.ttf")
    main(sys.argv[1])
