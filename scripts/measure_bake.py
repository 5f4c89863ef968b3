#!/usr/bin/env python3
"""Measures crisp-bake: cubic lowering tolerance against curve count and deviation, splitting at
y-extrema against its cost, and whole-font bake time and memory. Prints Markdown tables.

    scripts/measure_bake.py build/tools/crisp-bake > /tmp/tables.md
"""
import json
import os
import platform
import subprocess
import sys
import tempfile

FONTS = [
    ("Inter Regular (CFF)", "fonts/Inter-Regular.otf", []),
    ("Cantarell Regular (CFF)", "/usr/share/fonts/opentype/cantarell/Cantarell-Regular.otf", []),
    ("Noto Sans CJK JP (CFF, .ttc face 0)", "/usr/share/fonts/opentype/noto/NotoSansCJK-Regular.ttc", []),
]
QUADRATIC_FONTS = [
    ("DejaVu Sans (TrueType)", "fonts/DejaVuSans.ttf", []),
    ("Inter variable (gvar) at wght=400", "fonts/Inter-roman.var.ttf", ["--var", "wght=400"]),
]
TOLERANCES = [1 / 256, 1 / 1024, 1 / 4096, 1 / 16384, 1 / 65536]


def bake(tool, font, extra):
    with tempfile.TemporaryDirectory() as work:
        out = subprocess.run([tool, font, "-o", os.path.join(work, "a.crisp"), "--json", "-q"] + extra,
                             check=True, capture_output=True, text=True).stdout
    return json.loads(out)


def main():
    tool = sys.argv[1]
    cpu = next((l.split(":", 1)[1].strip() for l in open("/proc/cpuinfo") if l.startswith("model name")), "?")
    print(f"Measured on {platform.node()}: {cpu}, {os.cpu_count()} cores, {platform.system()} {platform.release()}.\n")

    print("## Cubic lowering: tolerance against curves and deviation\n")
    print("| font | tolerance (em) | cubics | quadratic pieces | pieces per cubic | largest deviation (em) "
          "| at 16 px (px) | at 256 px (px) | asset (MiB) |")
    print("|---|---|---|---|---|---|---|---|---|")
    for name, font, extra in FONTS:
        seed = None
        for tolerance in TOLERANCES:
            r = bake(tool, font, extra + ["--tolerance", repr(tolerance)])
            low = r["cubic_lowering"]
            seed = low
            print(f"| {name} | 1/{round(1 / tolerance)} | {r['cubics']} | {r['cubic_pieces']} | "
                  f"{r['cubic_pieces'] / r['cubics']:.2f} | {low['max_deviation_em']:.3g} | "
                  f"{low['max_deviation_em'] * 16:.4f} | {low['max_deviation_em'] * 256:.3f} | "
                  f"{r['asset_bytes'] / 2**20:.1f} |")
        print(f"| {name} | seed: split in two | {r['cubics']} | {seed['seed_split_pieces']} | 2.00 | "
              f"{seed['seed_split_max_deviation_em']:.3g} | {seed['seed_split_max_deviation_em'] * 16:.4f} | "
              f"{seed['seed_split_max_deviation_em'] * 256:.3f} | |")
    print()

    print("## Splitting at y-extrema\n")
    print("| font | split | curves | bands | mean curves per band | mean curve tests per ray | asset (MiB) |")
    print("|---|---|---|---|---|---|---|")
    for name, font, extra in FONTS + QUADRATIC_FONTS:
        for split in (False, True):
            r = bake(tool, font, extra + (["--split-y-extrema"] if split else []))
            b = r["bands"]
            print(f"| {name} | {'yes' if split else 'no'} | {r['curves']} | {b['total']} | "
                  f"{b['mean_curves_per_band']:.2f} | {b['mean_curve_tests_per_ray']:.2f} | "
                  f"{r['asset_bytes'] / 2**20:.1f} |")
    print()

    print("## Whole-font bakes at the default tolerance\n")
    print("| font | glyphs | curves | mean / max curves per glyph | max bands per glyph | asset (MiB) "
          "| time (s) | peak memory (MiB) |")
    print("|---|---|---|---|---|---|---|---|")
    for name, font, extra in QUADRATIC_FONTS + FONTS:
        r = bake(tool, font, extra)
        c = r["curves_per_glyph"]
        print(f"| {name} | {r['baked_glyphs']} | {r['curves']} | {c['mean']:.1f} / {c['max']} | "
              f"{r['bands']['max_per_glyph']} | {r['asset_bytes'] / 2**20:.1f} | {r['seconds']:.2f} | "
              f"{r['peak_rss_bytes'] / 2**20:.0f} |")


if __name__ == "__main__":
    main()
