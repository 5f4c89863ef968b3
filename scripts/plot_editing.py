#!/usr/bin/env python3
"""Draws docs/images/layout-editing.png from crisp-editing-picture's JSON (tools/editing_picture.cpp):
the glyphs, a selection's rectangles, the clusters by bidi level, and the carets of the positions
whose two sides are apart (direction boundaries): downstream red above, upstream blue below.

    build/tools/crisp-editing-picture > editing.json
    python3 scripts/plot_editing.py editing.json docs/images/layout-editing.png
"""
import json
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
from matplotlib.patches import PathPatch, Rectangle  # noqa: E402
from matplotlib.path import Path  # noqa: E402

LEVEL_COLOURS = {0: "#d9d9d9", 1: "#f4a261", 2: "#8fd18f"}


def glyph_path(contours):
    """A glyph's closed contours of quadratic curves (canvas pixels, y down) as one matplotlib path."""
    vertices, codes = [], []
    for contour in contours:
        if not contour:
            continue
        vertices.append(tuple(contour[0][0:2]))
        codes.append(Path.MOVETO)
        for _, _, x1, y1, x2, y2 in contour:
            vertices += [(x1, y1), (x2, y2)]
            codes += [Path.CURVE3, Path.CURVE3]
        vertices.append(vertices[-1])
        codes.append(Path.CLOSEPOLY)
    return Path(vertices, codes)


def main():
    if len(sys.argv) != 3:
        sys.exit("usage: plot_editing.py EDITING.json OUT.png")
    with open(sys.argv[1], encoding="utf-8") as file:
        data = json.load(file)
    box_x, box_y, box_width, box_height = data["box"]
    band = 10  # the cluster band below the line box, pixels
    top, bottom = box_y - 22, box_y + box_height + band + 26
    left, right = box_x - 8, box_x + box_width + 8
    scale = 2.0
    figure = plt.figure(figsize=((right - left) * scale / 100, (bottom - top) * scale / 100), dpi=100)
    axes = figure.add_axes([0, 0, 1, 1])
    axes.set_xlim(left, right)
    axes.set_ylim(bottom, top)  # y down, as on the canvas
    axes.axis("off")

    for x, y, width, height in data["selection"]["rects"]:
        axes.add_patch(Rectangle((x, y), width, height, facecolor="#bcd7f5", edgecolor="#5b8fd1", linewidth=0.8))
    for glyph in data["glyphs"]:
        if glyph:
            axes.add_patch(PathPatch(glyph_path(glyph), facecolor="black", edgecolor="none"))
    band_top = box_y + box_height + 2
    for cluster in data["clusters"]:
        colour = LEVEL_COLOURS.get(cluster["level"], "#c0a0e0")
        axes.add_patch(Rectangle((cluster["x"], band_top), cluster["advance"], band, facecolor=colour,
                                 edgecolor="white", linewidth=0.6))

    labels = []  # [x, colour, offsets]: carets of one colour within 3 px share one label
    for caret in data["carets"]:
        down, up = caret["downstream"], caret["upstream"]
        if abs(down[0] - up[0]) < 2.5:
            continue  # both sides at one edge: an ordinary position
        for rect, colour in ((down, "#d62828"), (up, "#1d4ed8")):
            x, y, width, height = rect
            axes.add_patch(Rectangle((x, y - 3), width, height + 6, facecolor=colour, edgecolor="none"))
            centre = x + width / 2
            near = [label for label in labels if label[1] == colour and abs(label[0] - centre) < 3]
            if near:
                near[0][2].append(caret["offset"])
            else:
                labels.append([centre, colour, [caret["offset"]]])
    for x, colour, offsets in labels:
        downstream = colour == "#d62828"
        text = ", ".join(str(offset) for offset in offsets) + (" \u2193" if downstream else " \u2191")
        axes.text(x, box_y - 4 if downstream else band_top + band + 3, text, color=colour, fontsize=7,
                  ha="center", va="bottom" if downstream else "top", family="DejaVu Sans")
    figure.savefig(sys.argv[2], dpi=100)


if __name__ == "__main__":
    main()
