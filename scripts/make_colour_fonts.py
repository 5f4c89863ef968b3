#!/usr/bin/env python3
"""Makes crisp's colour test fonts (tests/fonts/colour/) with fontTools (Debian: python3-fonttools):
small TrueType fonts whose colour glyphs cover COLRv0 layers, every COLRv1 paint format crisp
reads, and hostile tables. tests/fonts/colour/README.md lists each font's glyphs and code points.

    make_colour_fonts.py OUT_DIR [CORPUS_DIR]

With CORPUS_DIR, also writes each font's COLR table there as a seed for fuzz/fuzz_colr.cpp.

The output is byte for byte the same on every run (fixed timestamps, no names from the system), so
a CTest can regenerate the fonts and compare them with the committed copies.
"""
import logging
import math
import os
import sys

from fontTools.colorLib.builder import buildCOLR
from fontTools.fontBuilder import FontBuilder
from fontTools.pens.ttGlyphPen import TTGlyphPen
from fontTools.ttLib import TTCollection, TTFont
from fontTools.ttLib.tables import otTables as ot
from fontTools.ttLib.tables.DefaultTable import DefaultTable

UPEM = 1000
NO_VAR = 0xFFFFFFFF  # VarIndexBase: no variation
TIMESTAMP = 3881174400  # head.created and head.modified: 2026-12-01, seconds since 1904

# ---- Outlines (quadratic, clockwise outer contours as TrueType wants).


def rect(pen, x0, y0, x1, y1):
    pen.moveTo((x0, y0))
    pen.lineTo((x0, y1))
    pen.lineTo((x1, y1))
    pen.lineTo((x1, y0))
    pen.closePath()


def circle(pen, cx, cy, r, clockwise=True):
    # Eight off-curve points on the circumscribed octagon: every on-curve point is implied.
    k = r / math.cos(math.pi / 8)
    points = []
    for i in range(8):
        a = math.pi / 8 + i * math.pi / 4
        points.append((round(cx + k * math.cos(a)), round(cy + k * math.sin(a))))
    if clockwise:
        points.reverse()
    pen.qCurveTo(*points, None)
    pen.closePath()


def heart(pen):
    pen.moveTo((500, 0))
    pen.qCurveTo((100, 350), (100, 550))
    pen.qCurveTo((100, 800), (300, 800))
    pen.qCurveTo((450, 800), (500, 650))
    pen.qCurveTo((550, 800), (700, 800))
    pen.qCurveTo((900, 800), (900, 550))
    pen.qCurveTo((900, 350), (500, 0))
    pen.closePath()


SHAPES = {
    "square": lambda p: rect(p, 100, 0, 900, 800),
    "circle": lambda p: circle(p, 500, 400, 400),
    "ring": lambda p: (circle(p, 500, 400, 400), circle(p, 500, 400, 200, clockwise=False)),
    "bar": lambda p: rect(p, 100, 300, 900, 500),
    "small": lambda p: rect(p, 300, 200, 700, 600),
    "eye_l": lambda p: circle(p, 330, 520, 70),
    "eye_r": lambda p: circle(p, 670, 520, 70),
    "mouth": lambda p: rect(p, 300, 200, 700, 280),
    "heart": heart,
    "thumb": lambda p: (rect(p, 150, 0, 650, 450), rect(p, 300, 450, 450, 800)),
    "stripe_lo": lambda p: rect(p, 100, 0, 900, 267),
    "stripe_hi": lambda p: rect(p, 100, 533, 900, 800),
    "canton": lambda p: rect(p, 100, 400, 500, 800),
}


def shape_glyph(name):
    pen = TTGlyphPen(None)
    SHAPES[name](pen)
    return pen.glyph()


def empty_glyph():
    return TTGlyphPen(None).glyph()


# ---- Paints (fontTools colorLib dicts).


def solid(index, alpha=1.0):
    return {"Format": ot.PaintFormat.PaintSolid, "PaletteIndex": index, "Alpha": alpha}


def glyph(name, paint):
    return {"Format": ot.PaintFormat.PaintGlyph, "Glyph": name, "Paint": paint}


def layers(*paints):
    return {"Format": ot.PaintFormat.PaintColrLayers, "Layers": list(paints)}


def colour_line(extend, stops, var=False):
    if var:
        stops = [dict(s, VarIndexBase=NO_VAR) for s in stops]
    return {"Extend": extend, "ColorStop": stops}


def stop(offset, index, alpha=1.0):
    return {"StopOffset": offset, "PaletteIndex": index, "Alpha": alpha}


RED_BLUE = [stop(0.0, 0), stop(0.5, 3, 0.5), stop(1.0, 2)]


def gradient(kind, extend, stops, var, **geometry):
    # PaintFormat names the Var* format after its plain one: PaintVarLinearGradient, ...
    paint = {"Format": getattr(ot.PaintFormat, "Paint" + ("Var" if var else "") + kind + "Gradient"),
             "ColorLine": colour_line(extend, stops, var)}
    paint.update(geometry)
    if var:
        paint["VarIndexBase"] = NO_VAR
    return paint


def linear(extend, stops=RED_BLUE, var=False):
    # p2 is not perpendicular to p0->p1, so the p1 correction matters.
    return gradient("Linear", extend, stops, var, x0=100, y0=100, x1=500, y1=100, x2=200, y2=500)


def radial(extend, var=False):
    return gradient("Radial", extend, RED_BLUE, var, x0=450, y0=350, r0=50, x1=500, y1=400, r1=300)


def sweep(extend, var=False):
    # Angles in degrees (fontTools encodes them biased, as OpenType 1.9.1 does): 45 to 270.
    return gradient("Sweep", extend, RED_BLUE, var, centerX=500, centerY=400, startAngle=45.0, endAngle=270.0)


def transform(fmt, child, **fields):
    paint = {"Format": fmt, "Paint": child}
    paint.update(fields)
    # The Var* transforms have odd formats; PaintVarTransform's index is in its matrix.
    if fmt % 2 == 1 and fmt > ot.PaintFormat.PaintVarTransform:
        paint["VarIndexBase"] = NO_VAR
    return paint


def composite(mode, source, backdrop):
    return {"Format": ot.PaintFormat.PaintComposite, "CompositeMode": mode, "SourcePaint": source,
            "BackdropPaint": backdrop}


def colr_glyph(name):
    return {"Format": ot.PaintFormat.PaintColrGlyph, "Glyph": name}


# ---- Palettes: RGBA floats; the values are multiples of 1/255 so that they round trip exactly.


def rgba(r, g, b, a=255):
    return (r / 255, g / 255, b / 255, a / 255)


PALETTE_0 = [rgba(255, 0, 0), rgba(0, 128, 0), rgba(0, 0, 255), rgba(255, 204, 0), rgba(255, 0, 255, 128),
             rgba(255, 255, 255), rgba(0, 0, 0)]
PALETTE_1 = [rgba(0, 255, 255), rgba(128, 0, 128), rgba(255, 128, 0), rgba(64, 64, 64), rgba(0, 0, 128, 64),
             rgba(16, 32, 48), rgba(250, 250, 250)]

# ---- The emoji shared by colrv0.ttf and colrv1.ttf, for the layout tests.

EMOJI_CMAP = {0x1F600: "smile", 0x2764: "heart_emoji", 0x1F44D: "thumbs", 0x1F3FD: "tone", 0x200D: "zwj",
              0xFE0F: "vs16", 0x1F1FA: "ri_u", 0x1F1F8: "ri_s"}
# Ligatures HarfBuzz forms: a skin-tone sequence, a ZWJ sequence and a flag.
EMOJI_FEATURES = """
languagesystem DFLT dflt;
feature ccmp {
    sub thumbs tone by thumbs_tone;
    sub heart_emoji zwj smile by heart_zwj_smile;
    sub heart_emoji vs16 zwj smile by heart_zwj_smile;
    sub ri_u ri_s by flag_us;
} ccmp;
"""
EMOJI_V0 = {
    "smile": [("circle", 3), ("eye_l", 6), ("eye_r", 6), ("mouth", 6)],
    "heart_emoji": [("heart", 0)],
    "thumbs": [("thumb", 3)],
    "tone": [("square", 2)],
    "thumbs_tone": [("thumb", 2)],
    "heart_zwj_smile": [("heart", 0), ("eye_l", 6), ("eye_r", 6), ("mouth", 6)],
    "ri_u": [("square", 2)],
    "ri_s": [("square", 0)],
    "flag_us": [("square", 5), ("stripe_lo", 0), ("stripe_hi", 0), ("canton", 2)],
}


def emoji_v1():
    v1 = {name: layers(*(glyph(g, solid(i)) for g, i in stack)) for name, stack in EMOJI_V0.items()}
    v1["smile"] = layers(glyph("circle", radial("pad")), glyph("eye_l", solid(6)), glyph("eye_r", solid(6)),
                         glyph("mouth", solid(6)))
    return v1


# ---- Building a font.


class Font:
    """A font of outline glyphs (SHAPES), colour base glyphs (each with the square as its plain
    outline) and empty glyphs, with a cmap."""

    def __init__(self, family):
        self.family = family
        self.order = [".notdef"] + list(SHAPES)
        self.outlines = {".notdef": shape_glyph("small")}
        self.outlines.update({name: shape_glyph(name) for name in SHAPES})
        self.advances = {name: UPEM for name in self.order}
        self.cmap = {}

    def add(self, name, codepoint=None, outline="square", advance=UPEM):
        if name not in self.outlines:
            self.order.append(name)
            self.outlines[name] = shape_glyph(outline) if outline else empty_glyph()
            self.advances[name] = advance
        if codepoint is not None:
            self.cmap[codepoint] = name

    def add_emoji(self):
        for codepoint, name in EMOJI_CMAP.items():
            empty = name in ("zwj", "vs16")
            self.add(name, codepoint, outline=None if empty else "square", advance=0 if empty else UPEM)
        for name in EMOJI_V0:
            self.add(name)

    def build(self, features=None):
        fb = FontBuilder(UPEM, isTTF=True)
        fb.updateHead(created=TIMESTAMP, modified=TIMESTAMP)
        fb.setupGlyphOrder(self.order)
        fb.setupCharacterMap(self.cmap)
        fb.setupGlyf(self.outlines)
        glyf = fb.font["glyf"]
        fb.setupHorizontalMetrics({n: (self.advances[n], getattr(glyf[n], "xMin", 0)) for n in self.order})
        fb.setupHorizontalHeader(ascent=800, descent=-200)
        fb.setupNameTable({"familyName": self.family, "styleName": "Regular"})
        fb.setupOS2(sTypoAscender=800, sTypoDescender=-200, usWinAscent=800, usWinDescent=200)
        fb.setupPost()
        if features:
            fb.addOpenTypeFeatures(features)
        return fb


def colrv0(out):
    font = Font("crisp COLRv0 test")
    colour = {
        "two_layers": [("square", 0), ("circle", 1)],
        "foreground": [("square", 0xFFFF), ("ring", 2)],
        "four_layers": [("square", 0), ("circle", 1), ("ring", 2), ("bar", 3)],
        "alpha_layer": [("circle", 4)],
    }
    for i, name in enumerate(colour):
        font.add(name, 0xE000 + i)
    font.add_emoji()
    colour.update(EMOJI_V0)
    fb = font.build(EMOJI_FEATURES)
    fb.setupCOLR(colour, version=0)
    fb.setupCPAL([PALETTE_0, PALETTE_1])
    fb.save(out)


# COLRv1 glyphs, in code point order from U+E000: name -> paint. Each format and extend mode once
# or more; README.md says what each tests.
def colrv1_glyphs():
    pf = ot.PaintFormat
    sq = "square"
    g = {}
    g["v1_layers"] = layers(glyph(sq, solid(0)), glyph("circle", solid(1, 0.5)))
    g["v1_solid"] = glyph("ring", solid(2, 0.75))
    for extend in ("pad", "repeat", "reflect"):
        g["v1_linear_" + extend] = glyph(sq, linear(extend))
        g["v1_radial_" + extend] = glyph("circle", radial(extend))
        g["v1_sweep_" + extend] = glyph("circle", sweep(extend))
    g["v1_foreground_stop"] = glyph(sq, linear("pad", [stop(0.0, 0xFFFF, 0.5), stop(1.0, 1)]))
    g["v1_colr_glyph"] = layers(glyph("circle", solid(3)), colr_glyph("v1_linear_pad"))
    # Transforms above the PaintGlyph (a synthetic outline) and below it (the paint only).
    g["v1_transform"] = transform(pf.PaintTransform, glyph(sq, linear("pad")),
                                  Transform={"xx": 0.5, "yx": 0.25, "xy": -0.25, "yy": 0.75, "dx": 100, "dy": 50})
    g["v1_translate"] = transform(pf.PaintTranslate, glyph("circle", radial("pad")), dx=100, dy=-50)
    g["v1_translate_paint"] = glyph("circle", transform(pf.PaintTranslate, radial("pad"), dx=100, dy=-50))
    g["v1_scale"] = transform(pf.PaintScale, glyph(sq, linear("pad")), scaleX=0.5, scaleY=1.5)
    g["v1_scale_center"] = transform(pf.PaintScaleAroundCenter, glyph(sq, linear("pad")), scaleX=0.5,
                                     scaleY=1.5, centerX=500, centerY=400)
    g["v1_scale_uniform"] = transform(pf.PaintScaleUniform, glyph(sq, linear("pad")), scale=0.5)
    g["v1_scale_uniform_center"] = transform(pf.PaintScaleUniformAroundCenter, glyph(sq, linear("pad")),
                                             scale=0.5, centerX=500, centerY=400)
    g["v1_rotate"] = transform(pf.PaintRotate, glyph(sq, sweep("pad")), angle=30.0)
    g["v1_rotate_center"] = transform(pf.PaintRotateAroundCenter, glyph(sq, sweep("pad")), angle=90.0,
                                      centerX=500, centerY=400)
    g["v1_skew"] = transform(pf.PaintSkew, glyph(sq, linear("pad")), xSkewAngle=30.0, ySkewAngle=-15.0)
    g["v1_skew_center"] = transform(pf.PaintSkewAroundCenter, glyph(sq, linear("pad")), xSkewAngle=30.0,
                                    ySkewAngle=0.0, centerX=500, centerY=400)
    # Composites: backdrop the square in red, source the circle in blue.
    backdrop, source = glyph(sq, solid(0)), glyph("circle", solid(2))
    for mode in ("src_over", "dest_over", "src", "dest", "clear", "multiply"):
        g["v1_composite_" + mode] = composite(mode, source, backdrop)
    g["v1_nested_clip"] = glyph(sq, glyph("circle", solid(0)))
    # The Var* formats, read at their default values.
    g["v1_var_solid"] = glyph(sq, {"Format": pf.PaintVarSolid, "PaletteIndex": 1, "Alpha": 0.5,
                                   "VarIndexBase": NO_VAR})
    g["v1_var_linear"] = glyph(sq, linear("repeat", var=True))
    g["v1_var_radial"] = glyph("circle", radial("reflect", var=True))
    g["v1_var_sweep"] = glyph("circle", sweep("repeat", var=True))
    g["v1_var_transforms"] = transform(
        pf.PaintVarTransform,
        transform(pf.PaintVarTranslate,
                  transform(pf.PaintVarScale,
                            transform(pf.PaintVarScaleAroundCenter, glyph(sq, solid(0)), scaleX=0.75, scaleY=1.25,
                                      centerX=500, centerY=400),
                            scaleX=1.25, scaleY=0.75),
                  dx=20, dy=-30),
        Transform={"xx": 1.0, "yx": 0.0, "xy": 0.125, "yy": 1.0, "dx": 0, "dy": 0, "VarIndexBase": NO_VAR})
    g["v1_var_uniform_rotate"] = transform(
        pf.PaintVarScaleUniform,
        transform(pf.PaintVarScaleUniformAroundCenter,
                  transform(pf.PaintVarRotate,
                            transform(pf.PaintVarRotateAroundCenter, glyph(sq, solid(1)), angle=45.0, centerX=500,
                                      centerY=400),
                            angle=-45.0),
                  scale=0.5, centerX=500, centerY=400),
        scale=1.5)
    g["v1_var_skew"] = transform(
        pf.PaintVarSkew,
        transform(pf.PaintVarSkewAroundCenter, glyph(sq, solid(2)), xSkewAngle=-20.0, ySkewAngle=10.0,
                  centerX=500, centerY=400),
        xSkewAngle=10.0, ySkewAngle=0.0)
    # Two layers of the same glyph under the same transform: one synthetic outline.
    shifted = lambda index: transform(pf.PaintTranslate, glyph(sq, solid(index)), dx=100, dy=0)
    g["v1_shared_synthetic"] = layers(shifted(0), shifted(1))
    g["v1_clipped"] = glyph("circle", radial("pad"))
    g["v1_clipped_var"] = glyph("circle", solid(3))
    g["v1_with_v0"] = glyph(sq, solid(1))
    return g


CLIP_BOXES = {"v1_clipped": (200, 100, 800, 700), "v1_clipped_var": (0, 0, 500, 400, NO_VAR)}
# COLRv0 layers beside the COLRv1 paint: v1_with_v0 shows that COLRv1 wins; the multiply composite
# falls back to its COLRv0 layers; the nested clip has none and falls back to its plain outline.
V0_IN_V1 = {"v1_with_v0": [("circle", 0)], "v1_composite_multiply": [("ring", 1), ("bar", 3)]}


def add_v0_layers(colr, font, glyphs):
    """Adds COLRv0 base glyph and layer records to a COLRv1 table (fontTools builds one or the
    other per glyph)."""
    table = colr.table
    order = font.getReverseGlyphMap()
    records, layer_records = [], []
    for name in sorted(glyphs, key=lambda n: order[n]):
        base = ot.BaseGlyphRecord()
        base.BaseGlyph, base.FirstLayerIndex, base.NumLayers = name, len(layer_records), len(glyphs[name])
        records.append(base)
        for layer_glyph, index in glyphs[name]:
            layer = ot.LayerRecord()
            layer.LayerGlyph, layer.PaletteIndex = layer_glyph, index
            layer_records.append(layer)
    table.BaseGlyphRecordArray = ot.BaseGlyphRecordArray()
    table.BaseGlyphRecordArray.BaseGlyphRecord = records
    table.BaseGlyphRecordCount = len(records)
    table.LayerRecordArray = ot.LayerRecordArray()
    table.LayerRecordArray.LayerRecord = layer_records
    table.LayerRecordCount = len(layer_records)


def colrv1_font(family, colour, codepoint_names, clip_boxes=None, v0=None, palettes=(PALETTE_0, PALETTE_1),
                emoji=False):
    font = Font(family)
    for i, name in enumerate(codepoint_names):
        font.add(name, 0xE000 + i)
    for name in colour:
        font.add(name)
    if emoji:
        font.add_emoji()
    fb = font.build(EMOJI_FEATURES if emoji else None)
    colr = buildCOLR(colour, version=1, glyphMap=fb.font.getReverseGlyphMap(), clipBoxes=clip_boxes,
                     allowLayerReuse=False)
    if v0:
        add_v0_layers(colr, fb.font, v0)
    fb.font["COLR"] = colr
    fb.setupCPAL(list(palettes))
    return fb


def colrv1(out):
    colour = colrv1_glyphs()
    names = list(colour)
    colour.update(emoji_v1())
    colrv1_font("crisp COLRv1 test", colour, names, CLIP_BOXES, V0_IN_V1, emoji=True).save(out)


def colr_cycle(out):
    colour = {"cycle_a": colr_glyph("cycle_b"), "cycle_b": colr_glyph("cycle_a"),
              "self_layers": layers(glyph("square", solid(0)), glyph("circle", solid(1)))}
    fb = colrv1_font("crisp COLR cycle test", colour, list(colour))
    # fontTools builds no cycle through a layer list: point the second layer of self_layers at
    # the PaintColrLayers that holds it.
    table = fb.font["COLR"].table
    base = next(r for r in table.BaseGlyphList.BaseGlyphPaintRecord if r.BaseGlyph == "self_layers")
    table.LayerList.Paint[1] = base.Paint
    fb.save(out)


def colr_deep(out):
    # 100 PaintTranslates above one PaintGlyph: deeper than crisp's limit of 64.
    paint = glyph("square", solid(0))
    for _ in range(100):
        paint = transform(ot.PaintFormat.PaintTranslate, paint, dx=1, dy=0)
    # And a chain of 100 PaintColrGlyphs.
    colour = {"deep_transforms": paint}
    for i in range(100):
        colour["chain_%03d" % i] = colr_glyph("chain_%03d" % (i + 1)) if i < 99 else glyph("circle", solid(1))
    colrv1_font("crisp COLR deep test", colour, ["deep_transforms", "chain_000"]).save(out)


def colr_wide(out):
    # A DAG that doubles at each of 11 levels: 2^11 = 2048 layers once flattened (the table holds 24
    # paints), more than crisp's 1024.
    colour = {"wide_00": layers(glyph("square", solid(0)), glyph("circle", solid(1)))}
    for i in range(1, 11):
        colour["wide_%02d" % i] = layers(colr_glyph("wide_%02d" % (i - 1)), colr_glyph("wide_%02d" % (i - 1)))
    # 1024 layers exactly (level 9) are allowed.
    colrv1_font("crisp COLR wide test", colour, ["wide_10", "wide_09"]).save(out)


def colr_bad_palette(out):
    colour = {"bad_v1": glyph("square", solid(40)), "bad_v1_stop": glyph("square", linear("pad", [
        stop(0.0, 0), stop(1.0, 7)])), "good_v1": glyph("square", solid(6))}
    v0 = {"bad_v0": [("square", 0), ("circle", 9)]}
    font = Font("crisp COLR bad palette test")
    for i, name in enumerate(["bad_v1", "bad_v1_stop", "good_v1", "bad_v0"]):
        font.add(name, 0xE000 + i)
    fb = font.build()
    colr = buildCOLR(colour, version=1, glyphMap=fb.font.getReverseGlyphMap())
    add_v0_layers(colr, fb.font, v0)
    fb.font["COLR"] = colr
    fb.setupCPAL([PALETTE_0])  # 7 entries: 7, 9 and 40 are past them
    fb.save(out)


def colr_far(out):
    # A PaintTransform that scales the square 100 times: its outline reaches past 64 em and cannot
    # be baked. The next glyph's transform is fine.
    big = {"xx": 100.0, "yx": 0.0, "xy": 0.0, "yy": 100.0, "dx": 0, "dy": 0}
    colour = {"far": transform(ot.PaintFormat.PaintTransform, glyph("square", solid(0)), Transform=big),
              "near": transform(ot.PaintFormat.PaintTranslate, glyph("circle", solid(1)), dx=10, dy=20)}
    colrv1_font("crisp COLR far test", colour, list(colour)).save(out)


def colrv1_variable(out):
    # A wght axis and a COLR whose one delta moves the solid's alpha: crisp bakes the default
    # instance's paint and says that the deltas were not applied.
    from fontTools.varLib import builder as varlib
    regions = varlib.buildVarRegionList([{"wght": (0.0, 1.0, 1.0)}], ["wght"])
    store = varlib.buildVarStore(regions, [varlib.buildVarData([0], [[-8192]])])
    colour = {"var_alpha": glyph("square", {"Format": ot.PaintFormat.PaintVarSolid, "PaletteIndex": 0, "Alpha": 1.0,
                                            "VarIndexBase": 0})}
    font = Font("crisp COLRv1 variable test")
    font.add("var_alpha", 0xE000)
    fb = font.build()
    fb.setupFvar([("wght", 400, 400, 700, "Weight")], [])
    fb.setupGvar({})  # FreeType reads a TrueType fvar only beside a gvar
    fb.font["COLR"] = buildCOLR(colour, version=1, glyphMap=fb.font.getReverseGlyphMap(), varStore=store)
    fb.setupCPAL([PALETTE_0])
    fb.save(out)


def collection(out, paths):
    # colrv0.ttf and colrv1.ttf as faces 0 and 1 of one collection.
    ttc = TTCollection()
    ttc.fonts = [TTFont(path, recalcTimestamp=False) for path in paths]
    ttc.save(out)


def colr_truncated(out, colrv1_path):
    # colrv1.ttf with its COLR table cut to its first 40%: the header and the base glyph list
    # are whole, the layer list and the clip list lie past the end. Written as raw bytes, which
    # fontTools does not decompile.
    font = TTFont(colrv1_path, recalcTimestamp=False)
    data = font.getTableData("COLR")
    table = DefaultTable("COLR")
    table.data = data[:len(data) * 2 // 5]
    font["COLR"] = table
    font.save(out)


def write_corpus(fonts, corpus):
    os.makedirs(corpus, exist_ok=True)
    for name in sorted(os.listdir(fonts)):
        if name.endswith(".ttf"):  # the collection's faces are colrv0.ttf and colrv1.ttf
            with open(os.path.join(corpus, name[:-4] + ".colr"), "wb") as seed:
                seed.write(TTFont(os.path.join(fonts, name)).getTableData("COLR"))


def main():
    if len(sys.argv) not in (2, 3):
        sys.exit(__doc__)
    out = sys.argv[1]
    os.makedirs(out, exist_ok=True)
    logging.getLogger("fontTools").setLevel(logging.ERROR)
    path = lambda name: os.path.join(out, name)
    colrv0(path("colrv0.ttf"))
    colrv1(path("colrv1.ttf"))
    colr_cycle(path("colr_cycle.ttf"))
    colr_deep(path("colr_deep.ttf"))
    colr_wide(path("colr_wide.ttf"))
    colr_bad_palette(path("colr_bad_palette.ttf"))
    colr_far(path("colr_far.ttf"))
    colrv1_variable(path("colrv1_variable.ttf"))
    collection(path("colr_collection.ttc"), [path("colrv0.ttf"), path("colrv1.ttf")])
    colr_truncated(path("colr_truncated.ttf"), path("colrv1.ttf"))
    if len(sys.argv) == 3:
        write_corpus(out, sys.argv[2])


if __name__ == "__main__":
    main()
