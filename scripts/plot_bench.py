#!/usr/bin/env python3
"""Plots crisp-bench's JSON: python3 scripts/plot_bench.py RESULTS.json

Writes PNGs beside the JSON, named after it (lavapipe.json -> lavapipe-error-vs-samples.png, ...),
for the suites the JSON holds, and prints each PNG's path on a line of its own:

- error-vs-samples: the coverage suite's error (mean per texel channel, worst texel) against the
  sample count, row and point samples, with FreeType's peers as horizontal lines;
- error-vs-time: the same errors against the GPU ms the frames suite's screen took to reach each
  sample count, with FreeType at its CPU ms for the same glyphs;
- scaling: the scaling suite's GPU ms against canvas size and against glyphs on screen;
- atlas: the atlas suite's entries and quantization error against subpixel steps;
- contrast: the contrast suite's ink ratio (dark on light / light on dark) and dark stems' contrast
  against the size, per setting and font, with the issue's band for the ratio.

Needs matplotlib (Debian: python3-matplotlib, which scripts/setup.sh installs).
"""
import json
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

KIND_STYLE = {"rows": dict(color="tab:blue", marker="o"), "points": dict(color="tab:orange", marker="s")}
PEER_STYLE = {"gray": "tab:green", "lcd": "tab:red", "lcd-unfiltered": "tab:purple"}
LAYOUTS = ["gray", "rgb"]
METRICS = [("mean", "mean abs. error per texel channel"), ("worst", "worst texel channel")]


def panels(rows):
    """A figure of `rows` x 2 panels, the size and layout every plot here shares."""
    return plt.subplots(rows, 2, figsize=(11, 4 * rows + 0.5), squeeze=False, layout="constrained")


def finish(fig, data, title, stem, name, written):
    """Titles the figure after what it shows and the device, writes stem-name.png, closes it."""
    device = f"{data.get('device', '?')}{' (--quick)' if data.get('quick') else ''}"
    fig.suptitle(f"{title} — {device}")
    path = f"{stem}-{name}.png"
    fig.savefig(path, dpi=110)
    plt.close(fig)
    written.append(path)


def log_axes(ax, xlabel, ylabel, title, x_base=10):
    """Log-log axes with a grid and a legend."""
    ax.set_xscale("log", base=x_base)
    ax.set_yscale("log")
    ax.set_xlabel(xlabel)
    ax.set_ylabel(ylabel)
    ax.set_title(title)
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8)


def error_panels(axes, coverage):
    """The 2 x 2 error grid (rows: layouts, columns: metrics): per panel its axes, layout, metric,
    the metric's label, and the coverage suite's runs and FreeType peers of that layout."""
    for row, layout in enumerate(LAYOUTS):
        for col, (metric, label) in enumerate(METRICS):
            runs = [run for run in coverage["runs"] if run["layout"] == layout]
            peers = [peer for peer in coverage.get("freetype", []) if peer["layout"] == layout]
            yield axes[row][col], layout, metric, label, runs, peers


def plot_error_vs_samples(data, stem, written):
    coverage = data["suites"].get("coverage")
    if not coverage:
        return
    fig, axes = panels(2)
    glyphs = len(coverage.get("glyphs", []))
    counts = sorted({p["samples"] for run in coverage["runs"] for p in run["points"]})
    for ax, layout, metric, label, runs, peers in error_panels(axes, coverage):
        for run in runs:
            xs = [p["samples"] for p in run["points"]]
            ys = [max(p[metric], 1e-6) for p in run["points"]]
            ax.plot(xs, ys, label=f"crisp, {run['sample_kind']}", **KIND_STYLE.get(run["sample_kind"], {}))
        for peer in peers:
            ax.axhline(max(peer[metric], 1e-6), linestyle="--", color=PEER_STYLE.get(peer["mode"], "gray"),
                       label=f"FreeType {peer['mode']} ({peer['us_per_glyph']:.2g} µs/glyph, CPU)")
        log_axes(ax, "samples per texel", label, f"{layout}: {label}", x_base=2)
        ax.set_xticks(counts, [str(n) for n in counts])
    finish(fig, data, f"crisp coverage error against samples, {glyphs} glyphs, vs. FreeType area coverage", stem,
           "error-vs-samples", written)


def plot_error_vs_time(data, stem, written):
    coverage = data["suites"].get("coverage")
    frames = data["suites"].get("frames")
    if not coverage or not frames:
        return
    screen_ms = frames.get("freetype_screen_ms", {})
    entries = frames.get("screen_atlas_entries", 0)
    fig, axes = panels(2)
    plotted = False
    for ax, layout, metric, label, runs, peers in error_panels(axes, coverage):
        for run in runs:
            timing = next((f for f in frames["runs"]
                           if f["layout"] == layout and f["sample_kind"] == run["sample_kind"]), None)
            if timing is None or timing.get("frame_budget", 2**50) != 2**50:
                continue  # a bounded budget gives glyphs different samples in a frame
            cumulative, samples, total = {}, 0.0, 0.0
            for f in timing["frames"]:
                if f["glyphs_refined"] == 0:
                    break
                samples += f["samples"] / f["glyphs_refined"]
                total += f["gpu_ms"]
                cumulative[int(round(samples))] = total
            pts = [(cumulative[p["samples"]], max(p[metric], 1e-6), p["samples"]) for p in run["points"]
                   if p["samples"] in cumulative]
            if not pts:
                continue
            plotted = True
            ax.plot([p[0] for p in pts], [p[1] for p in pts], label=f"crisp, {run['sample_kind']} (GPU)",
                    **KIND_STYLE.get(run["sample_kind"], {}))
            for x, y, n in pts:
                ax.annotate(str(n), (x, y), textcoords="offset points", xytext=(3, 3), fontsize=7,
                            color=KIND_STYLE.get(run["sample_kind"], {}).get("color", "black"))
        for peer in peers:
            if peer["mode"] not in screen_ms:
                continue
            ax.scatter([screen_ms[peer["mode"]]], [max(peer[metric], 1e-6)], marker="*", s=140,
                       color=PEER_STYLE.get(peer["mode"], "gray"), label=f"FreeType {peer['mode']} (CPU, 1 thread)",
                       zorder=3)
        log_axes(ax, f"cumulative ms, frames suite's screen ({entries} atlas entries)", label,
                 f"{layout}: {label}")
    if not plotted:
        plt.close(fig)
        return
    finish(fig, data, "error against cumulative time (labels: samples per texel)", stem, "error-vs-time", written)


def plot_scaling(data, stem, written):
    scaling = data["suites"].get("scaling")
    if not scaling or not scaling.get("points"):
        return
    fig, axes = panels(1)
    series = [("same text", lambda p: p["width"] * p["height"] / 1e6, "canvas megapixels (same glyphs)"),
              ("more text", lambda p: p["glyphs"], "glyphs on screen (same canvas)")]
    lines = [("first_renderer_ms", "frame 1, renderer"), ("first_compositor_ms", "frame 1, compositor"),
             ("refining_renderer_ms", "frame 4, renderer"), ("static_compositor_ms", "static, compositor")]
    for col, (name, x_of, xlabel) in enumerate(series):
        ax = axes[0][col]
        pts = [p for p in scaling["points"] if p["series"] == name]
        for key, label in lines:
            ax.plot([x_of(p) for p in pts], [max(p[key], 1e-4) for p in pts], marker="o", label=label)
        log_axes(ax, xlabel, "GPU ms", name)
    finish(fig, data, "frame cost against screen and text", stem, "scaling", written)


def plot_atlas(data, stem, written):
    atlas = data["suites"].get("atlas")
    if not atlas or not atlas.get("rows"):
        return
    rows = sorted(atlas["rows"], key=lambda r: r["steps"])
    fig, axes = panels(1)
    steps = [r["steps"] for r in rows]
    axes[0][0].plot(steps, [r["entries"] for r in rows], marker="o")
    axes[0][0].set_ylabel("distinct atlas entries")
    axes[0][0].set_title(f"a page of {atlas['page_glyphs']} glyphs")
    for layout, color in (("gray", "tab:green"), ("rgb", "tab:red")):
        for metric, style in (("mean", "-"), ("worst", "--")):
            ys = [r[f"{layout}_{metric}"] for r in rows if r["steps"] < 256]
            axes[0][1].plot([r["steps"] for r in rows if r["steps"] < 256], [max(y, 1e-6) for y in ys], style,
                            marker="o", color=color, label=f"{layout}, {metric}")
    axes[0][1].set_yscale("log")
    axes[0][1].set_ylabel("coverage error of the quantization")
    axes[0][1].set_title(f"exact coverage, {atlas['error_glyphs']} glyphs, against 1/256 px")
    axes[0][1].legend(fontsize=8)
    for ax, ticks in zip(axes[0], (steps, [n for n in steps if n < 256])):
        ax.set_xscale("log", base=2)
        ax.set_xticks(ticks, [str(n) for n in ticks])
        ax.set_xlabel("subpixel steps per pixel")
        ax.grid(True, which="both", alpha=0.3)
    finish(fig, data, "atlas reuse against subpixel quantization", stem, "atlas", written)


def plot_contrast(data, stem, written):
    contrast = data["suites"].get("contrast")
    if not contrast or not contrast.get("fonts"):
        return
    fig, axes = panels(1)
    styles = ["-", "--", ":"]
    colors = {}
    axes[0][0].axhspan(0.9, 1.1, color="tab:green", alpha=0.12, label="0.9 to 1.1")
    for f, font in enumerate(contrast["fonts"]):
        settings = list(dict.fromkeys(r["setting"] for r in font["rows"]))
        for i, setting in enumerate(settings):
            rows = sorted((r for r in font["rows"] if r["setting"] == setting), key=lambda r: r["size"])
            color = colors.setdefault(setting, f"C{i}")
            label = setting if f == 0 else None  # colours name the settings, line styles the fonts
            for col, key in enumerate(("ratio", "stem_dark")):
                axes[0][col].plot([r["size"] for r in rows], [r[key] for r in rows], styles[f % len(styles)],
                                  marker="o", markersize=3, color=color, label=label)
    names = ["solid", "dashed", "dotted"]
    fonts = ", ".join(f"{font['name']} {names[f % 3]}" for f, font in enumerate(contrast["fonts"]))
    for ax, ylabel, title in ((axes[0][0], "ink ratio, dark on light / light on dark", f"ink ratio ({fonts})"),
                              (axes[0][1], "encoded ink of pixels covered 1/2 or more", "dark stems")):
        ax.set_xlabel("size, px per em")
        ax.set_ylabel(ylabel)
        ax.set_title(title)
        ax.grid(True, alpha=0.3)
    axes[0][0].legend(fontsize=7, ncol=2, loc="center", bbox_to_anchor=(0.5, 0.42))
    finish(fig, data, "ink dark on light against light on dark", stem, "contrast", written)


def main():
    if len(sys.argv) != 2:
        sys.exit("usage: plot_bench.py RESULTS.json")
    with open(sys.argv[1], encoding="utf-8") as f:
        data = json.load(f)
    stem = os.path.splitext(sys.argv[1])[0]
    written = []
    plot_error_vs_samples(data, stem, written)
    plot_error_vs_time(data, stem, written)
    plot_scaling(data, stem, written)
    plot_atlas(data, stem, written)
    plot_contrast(data, stem, written)
    for path in written:
        print(path)


if __name__ == "__main__":
    main()
