#!/usr/bin/env bash
# bench_cli_test.sh CRISP_BENCH SOURCE_DIR WORK_DIR: crisp-bench works. Its usage errors exit 2;
# --quick runs every suite on whatever Vulkan device there is (lavapipe in CI) with the validation
# layer on, and writes well-formed Markdown, JSON and (where matplotlib is installed) PNG plots.
# It checks the shape of what is written, never the numbers: a benchmark measures, a test checks.
set -uo pipefail
bench=$1 source=$2 work=$3
rm -rf "$work" && mkdir -p "$work"
cd "$source" || exit 1  # the suites' default fonts are relative to the repository root
. "$(dirname "${BASH_SOURCE[0]}")/cli_common.sh"
suites=(frames coverage compositing scaling atlas frame-cpu cpu contrast colour transform)

# ---- --help and usage errors: exit 2, nothing measured.
expect_exit 0 "--help" -- "$bench" --help
for suite in "${suites[@]}"; do
  grep -q "^  $suite " "$work/out" || fail "--help does not list the suite $suite"
done
for option in --quick --suite --out --canvas --samples --sample-kind --clock-load --modes --variants --steps --pictures --glyphs --glyph --tolerance; do
  grep -qF -- "$option" "$work/out" || fail "--help does not list $option"
done
expect_exit 2 "unknown suite" -- "$bench" --suite nonesuch
expect_stderr "unknown suite 'nonesuch'" "unknown suite"
expect_exit 2 "unknown option" -- "$bench" --frobnicate
expect_exit 2 "option without its value" -- "$bench" --suite
expect_exit 2 "--samples 0" -- "$bench" --samples 0
expect_exit 2 "--canvas not WxH" -- "$bench" --canvas 640
expect_exit 2 "unknown compositing mode" -- "$bench" --modes tiled,bogus
expect_stderr "unknown mode 'bogus'" "unknown compositing mode"
expect_exit 2 "unknown sample kind" -- "$bench" --sample-kind lines
expect_exit 2 "--steps not a power of two" -- "$bench" --steps 3
expect_exit 2 "--glyph without a size" -- "$bench" --glyph fonts/DejaVuSans.ttf:g
expect_stderr "PATH:PX:TEXT" "--glyph without a size"
expect_exit 2 "--glyph size out of range" -- "$bench" --glyph fonts/DejaVuSans.ttf:0:g
expect_exit 2 "compositing warm-up below its frames in flight" -- "$bench" --suite compositing --warmup 1

# ---- From another directory: the default fonts come from the source tree it was built from.
mkdir -p "$work/elsewhere"
expect_exit 0 "--suite atlas from another directory" -- env -C "$work/elsewhere" "$bench" --quick --suite atlas \
  --no-plots --out "$work/elsewhere/results" --name elsewhere
[ -s "$work/elsewhere/results/elsewhere.json" ] || fail "--suite atlas from another directory wrote no JSON"

# ---- --quick, every suite, validation layer on.
validate=()
if [ -n "$(find /usr/share/vulkan /etc/vulkan -name 'VkLayer_khronos_validation.json' 2>/dev/null)" ]; then
  validate=(--validate)
fi
start=$(date +%s)
expect_exit 0 "--quick --suite all" -- "$bench" --quick --suite all "${validate[@]}" --out "$work/results" --name quick
echo "crisp-bench --quick took $(( $(date +%s) - start )) s" >&2
md=$work/results/quick.md json=$work/results/quick.json
[ -s "$md" ] || fail "no $md"
[ -s "$json" ] || fail "no $json"
cmp -s "$work/out" /dev/null && fail "nothing on stdout"
grep -qF -- "crisp-bench --quick --suite all" "$md" || fail "the Markdown does not name the command that made it"
for suite in "${suites[@]}"; do
  grep -q "^## $suite: " "$md" || fail "the Markdown has no section for $suite"
  grep -qF "[$suite] done" "$work/err" || fail "no progress line for $suite on stderr"
done
grep -q "^## Error against cumulative GPU time" "$md" || fail "the Markdown has no error-against-time table"
python3 - "$json" <<'EOF' || fail "the JSON is not what the suites write"
import json, math, sys
data = json.load(open(sys.argv[1]))
suites = data["suites"]
for name in ["frames", "coverage", "compositing", "scaling", "atlas", "frame-cpu", "cpu", "contrast", "colour", "transform"]:
    assert name in suites, name
assert data["tool"] == "crisp-bench" and data["quick"] is True and data["command"].startswith("crisp-bench")
def unit(x):
    return isinstance(x, (int, float)) and math.isfinite(x) and 0.0 <= x <= 1.0
runs = suites["coverage"]["runs"]
assert {(r["layout"], r["sample_kind"]) for r in runs} == {(l, k) for l in ("gray", "rgb") for k in ("rows", "points")}
for r in runs:
    assert [p["samples"] for p in r["points"]] == [1, 2, 4, 8, 16], r["points"]
    for p in r["points"]:
        assert unit(p["mean"]) and unit(p["worst"]) and p["mean"] <= p["worst"], p
        assert len(p["glyph_mean"]) == len(suites["coverage"]["glyphs"])
    # The split of the last count's error: its three signed parts add up to the worst texel's.
    split = r["split"]
    assert split["samples"] == 16 and len(split["glyphs"]) == len(suites["coverage"]["glyphs"]), split
    for g, p in zip(split["glyphs"], r["points"][-1]["glyph_worst"]):
        parts = g["worst_texel_sampling"] + g["worst_texel_lowering"] + g["worst_texel_reference"]
        assert abs(abs(parts) - g["total_worst"]) < 1e-5 and abs(g["total_worst"] - p) < 1e-9, (g, p)
        assert all(unit(g[k + "_worst"]) for k in ("sampling", "lowering", "reference")), g
for b in suites["coverage"]["bakes"]:
    assert b["tolerance_em"] > 0 and b["size_px"] >= 1 and 0 <= b["max_deviation_px"] <= 1 / 1024 * (1 + 1e-6), b
assert {p["mode"] for p in suites["coverage"]["freetype"]} == {"gray", "lcd", "lcd-unfiltered"}
for p in suites["coverage"]["freetype"]:
    assert unit(p["mean"]) and unit(p["worst"]) and p["us_per_glyph"] > 0, p
assert len(suites["frames"]["runs"]) == 4
for r in suites["frames"]["runs"]:
    assert r["converged"] and r["frames"], r
    assert all(f["gpu_ms"] >= 0 for f in r["frames"])
    assert sum(f["samples"] for f in r["frames"]) == 16 * r["atlas_entries"], r["frames"]
assert set(suites["frames"]["freetype_screen_ms"]) == {"gray", "lcd", "lcd-unfiltered"}
assert [p["series"] for p in suites["scaling"]["points"]] == ["same text"] * 2 + ["more text"] * 2
assert [r["steps"] for r in suites["atlas"]["rows"]] == [256, 4, 1]
assert suites["atlas"]["rows"][0]["gray_mean"] == 0 and suites["atlas"]["rows"][0]["entries"] > 0
assert [v["name"] for v in suites["frame-cpu"]["variants"]] == ["static", "changed", "moving"]
assert suites["compositing"]["scenes"] and not suites["compositing"]["warnings"], suites["compositing"]["warnings"]
contrast = suites["contrast"]
settings = ["linear", "default", "gamma 1.8", "contrast 0.5", "stem darkening 1", "FreeType, linear", "FreeType, sRGB"]
assert [f["name"] for f in contrast["fonts"]] == ["DejaVu Sans"], contrast["fonts"]
rows = contrast["fonts"][0]["rows"]
assert [(r["size"], r["setting"]) for r in rows] == [(s, n) for s in (9, 11, 16) for n in settings], rows
for r in rows:
    for k in ("ink_dark", "ink_light", "stem_dark", "stem_light"):
        assert unit(r[k]) and r[k] > 0, r
    assert r["ratio"] > 0 and math.isclose(r["ratio"], r["ink_dark"] / r["ink_light"], rel_tol=1e-9), r
assert contrast["pictures"] == ["quick-%s-%s.png" % (p, s) for s in ("linear", "default") for p in ("dark", "light")]
colour = suites["colour"]
assert colour["count"] == 100 and colour["size"] == 24, colour
screens = {s["name"]: s for s in colour["screens"]}
assert list(screens) == ["bitmap", "colrv1", "monochrome"], screens
assert not screens["colrv1"]["skipped"] and not screens["monochrome"]["skipped"], screens
for name, s in screens.items():
    if s["skipped"]:
        assert name == "bitmap" and "NotoColorEmoji" in s["skipped"], s
        continue
    assert s["converged"] and s["shaped_glyphs"] == 100 and s["colour_glyphs"] == (0 if name == "monochrome" else 100), s
    first, last = s["first"], s["converged_frame"]
    assert s["layout_ms"] > 0 and first["quads"] > 0 and last["quads"] == first["quads"], s
    assert first["glyphs_refined"] > 0 and last["glyphs_refined"] == 0, s
    for f in (first, last):
        assert f["cpu_ms"] > 0 and f["raster_gpu_ms"] >= 0 and f["composite_gpu_ms"] > 0 and f["bitmap_misses"] == 0, f
        assert (f["colour_layers"] > 0) == (name != "monochrome"), (name, f)
    assert (first["bitmap_uploads"] > 0) == (name == "bitmap") and last["bitmap_uploads"] == 0, s
    assert (first["frame_paints"] > 0) == (name != "monochrome"), s
transform = suites["transform"]
assert transform["canvas"] == [256, 128] and transform["samples"] == 16 and transform["laid_out_glyphs"] > 0, transform
def measured(e, glyphs=1):
    assert unit(e["mean"]) and unit(e["worst"]) and e["mean"] <= e["worst"], e
    assert e["glyphs"] >= glyphs and (e["channels"] > 0) == (e["glyphs"] > 0), e
assert [r["variant"] for r in transform["animated"]] == ["plain", "named"], transform["animated"]
for r in transform["animated"]:
    assert len(r["frames"]) == 3, r
    for f in r["frames"]:
        assert f["gpu_ms"] >= 0 and f["cpu_ms"] > 0 and f["samples"] > 0 and f["curve_tests"] > 0, f
        assert f["glyphs_drawn"] > 0 and f["culled"] > 0 and f["atlas_allocations"] > 0, f
        assert (f["moving"] > 0) == (r["variant"] == "named"), f
        measured(f)
        assert unit(f["still_key_mean"]) and unit(f["still_key_worst"]), f
        # An unnamed draw's keys are the still keys: the same texels against the same areas.
        assert r["variant"] == "named" or math.isclose(f["still_key_mean"], f["mean"], rel_tol=1e-9), f
still = transform["still"]
assert still["converged"] and still["frames"] > 1 and still["total_gpu_ms"] >= still["first_gpu_ms"] >= 0, still
assert [p["samples"] for p in still["points"]] == [8, 16], still
for p in still["points"]:
    measured(p)
assert [(c["degrees"], c["scale"], c["shear"]) for c in transform["grid"]] == [
    (a, s, h) for a in (37, 211) for s in (0.25, 8) for h in (0, 0.5)], transform["grid"]
for c in transform["grid"]:
    assert [p["samples"] for p in c["points"]] == [8, 16] and c["glyphs_drawn"] == 2, c
    for p in c["points"]:
        measured(p, 2)
assert [t["tilt_degrees"] for t in transform["perspective"]] == [45, 80], transform["perspective"]
for t in transform["perspective"]:
    assert t["glyphs"] > 0 and 0 <= t["projective"] <= t["glyphs"] - t["culled"], t
    # The suite's own place_on_plane() count is the renderer's (RendererStats::projective_glyphs).
    assert t["renderer_projective_glyphs"] == t["projective"], t
    assert len(t["affine_error"]) == t["glyphs"] - t["culled"] and t["affine_error_max"] >= t["affine_error_median"] >= 0
    assert [p["samples"] for p in t["points"]] == [8, 16] and len(t["projective_points"]) == 2, t
    for p in t["points"]:
        measured(p)
EOF
for picture in quick-{dark,light}-{linear,default}.png; do
  [ "$(head -c 4 "$work/results/$picture" 2>/dev/null | od -An -c | tr -d ' ')" = "211PNG" ] || fail "$picture is not a PNG"
  grep -qF "]($picture)" "$md" || fail "the Markdown does not show $picture"
done
# Plots where some python3 has matplotlib, else the Markdown says how to make them.
if python3 -c 'import matplotlib' 2>/dev/null || /usr/bin/python3 -c 'import matplotlib' 2>/dev/null; then
  for plot in error-vs-samples error-vs-time scaling atlas contrast; do
    png=$work/results/quick-$plot.png
    [ "$(head -c 4 "$png" 2>/dev/null | od -An -c | tr -d ' ')" = "211PNG" ] || fail "$png is not a PNG"
    grep -qF "](quick-$plot.png)" "$md" || fail "the Markdown does not show quick-$plot.png"
  done
else
  grep -qF "python3-matplotlib" "$md" || fail "no plots, and the Markdown does not say how to make them"
fi

# One suite alone, JSON on stdout, no files.
expect_exit 0 "--suite atlas --quick --json --no-files" -- "$bench" --suite atlas --quick --json --no-files
python3 -c 'import json,sys; d=json.load(open(sys.argv[1])); assert list(d["suites"]) == ["atlas"], d' "$work/out" \
  || fail "--json does not print the one suite's JSON"

[ "$failures" -eq 0 ] || { echo "$failures failures" >&2; exit 1; }
echo "crisp-bench: all checks passed"
