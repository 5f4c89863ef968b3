#!/usr/bin/env python3
"""Makes fonts with the faults of issue 28 (items 18 and 19) that crisp-bake must refuse by name,
not as "the baked asset does not validate (a crisp bug)", with fontTools (Debian: python3-fonttools):

    make_font_faults.py SOURCE_DIR OUT_DIR

  upem15.ttf, upem16385.ttf   head's units per em outside 16..16384
  advance.ttf                 16 units per em, an empty glyph (space) advancing 65535 units: 4096 em
  bearing.otf                 CFF at 16 units per em, a glyph whose only curve, of zero length, is
                              at x = -30000 (the baker drops the curve; FreeType's bearing is -1875 em)
  maxp-cff.otf                maxp counts 5 glyphs more than the CFF table's CharStrings
  maxp-loca.ttf               maxp counts 100 glyphs more than loca has offsets for
  bare.cff                    the CFF table of bearing.otf on its own
  escape-axis.ttf             a variable font whose axis tag is ESC [ 2 J (clears a terminal)
"""
import os
import struct
import sys

from fontTools.fontBuilder import FontBuilder
from fontTools.misc.psCharStrings import T2CharString
from fontTools.ttLib import TTFont
from fontTools.ttLib.scaleUpem import scale_upem

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "scripts"))
from make_upem_font import subset_font  # noqa: E402 (from scripts/, beside this script's folder)


def patch(path, tag, offset, fmt, value):
    """Writes `value` at `offset` of table `tag` in the saved font, checksums left as they are."""
    data = bytearray(open(path, "rb").read())
    tables = struct.unpack_from(">H", data, 4)[0]
    for i in range(tables):
        record = 12 + 16 * i
        if data[record:record + 4] == tag:
            start = struct.unpack_from(">I", data, record + 8)[0]
            struct.pack_into(fmt, data, start + offset, value)
            open(path, "wb").write(data)
            return
    raise SystemExit(f"{path} has no {tag} table")


def glyph_count(path):
    return TTFont(path)["maxp"].numGlyphs


def cff_font(program):
    """A CFF font of 16 units per em: .notdef (empty) and 'A', drawn by the Type 2 charstring
    `program` (its width first)."""
    builder = FontBuilder(16, isTTF=False)
    builder.setupGlyphOrder([".notdef", "A"])
    builder.setupCharacterMap({ord("A"): "A"})
    charstrings = {".notdef": T2CharString(program=[8, "endchar"]), "A": T2CharString(program=program)}
    builder.setupCFF("Faults", {"FullName": "Faults"}, charstrings, {})
    builder.setupHorizontalMetrics({".notdef": (8, 0), "A": (8, 0)})
    builder.setupHorizontalHeader(ascent=12, descent=-4)
    builder.setupNameTable({"familyName": "Faults", "styleName": "Regular"})
    builder.setupOS2(sTypoAscender=12, usWinAscent=12, usWinDescent=4)
    builder.setupPost()
    return builder.font


def main():
    if len(sys.argv) != 3:
        sys.exit(__doc__)
    source, out = sys.argv[1], sys.argv[2]
    dejavu = source + "/fonts/DejaVuSans.ttf"

    for upem in (15, 16385):
        path = f"{out}/upem{upem}.ttf"
        subset_font(dejavu, "a").save(path)
        patch(path, b"head", 18, ">H", upem)

    font = subset_font(dejavu, "a ")
    scale_upem(font, 16)
    font["hmtx"]["space"] = (65535, 0)
    font.save(f"{out}/advance.ttf")

    # FreeType's bearing of a CFF glyph is its control box's, which keeps the points of a
    # zero-length curve that the baker drops.
    cff_font([8, -30000, 0, "rmoveto", 0, 0, 0, 0, 0, 0, "rrcurveto", "endchar"]).save(f"{out}/bearing.otf")
    with open(f"{out}/bare.cff", "wb") as bare:
        bare.write(TTFont(f"{out}/bearing.otf").getTableData("CFF "))

    cff_font([8, 1, 0, "rmoveto", 6, 0, "rlineto", -3, 10, "rlineto", "endchar"]).save(f"{out}/maxp-cff.otf")
    patch(f"{out}/maxp-cff.otf", b"maxp", 4, ">H", glyph_count(f"{out}/maxp-cff.otf") + 5)
    subset_font(dejavu, "ab").save(f"{out}/maxp-loca.ttf")
    patch(f"{out}/maxp-loca.ttf", b"maxp", 4, ">H", glyph_count(f"{out}/maxp-loca.ttf") + 100)

    # fvar's first axis record is at its axesArrayOffset; its tag is the record's first 4 bytes.
    path = f"{out}/escape-axis.ttf"
    TTFont(source + "/fuzz/corpus/font/inter-var-subset.ttf").save(path)
    axes = struct.unpack_from(">H", TTFont(path).reader["fvar"], 4)[0]
    patch(path, b"fvar", axes, ">4s", b"\x1b[2J")

if __name__ == "__main__":
    main()
