#!/usr/bin/env bash
# cli_test.sh CRISP_BAKE SOURCE_DIR WORK_DIR: crisp-bake's exit codes, --json, --check and its
# promise never to leave a broken or half-written asset.
set -uo pipefail
bake=$1 source=$2 work=$3
rm -rf "$work" && mkdir -p "$work" && cd "$work"
failures=0
fail() { echo "FAIL: $*" >&2; failures=$((failures + 1)); }
expect_exit() {  # expect_exit CODE DESCRIPTION -- COMMAND...
  local want=$1 what=$2; shift 3
  "$@" >"$work/out" 2>"$work/err"
  local got=$?
  [ "$got" -eq "$want" ] || fail "$what: exit $got, want $want; stderr: $(head -c 400 "$work/err")"
}
font=$source/fonts/DejaVuSans.ttf

expect_exit 0 "--help" -- "$bake" --help
grep -q "exit codes" "$work/out" || fail "--help does not list the exit codes"
expect_exit 2 "no arguments" -- "$bake"
expect_exit 2 "unknown option" -- "$bake" "$font" --frobnicate
expect_exit 2 "bad tolerance" -- "$bake" "$font" --tolerance -1
expect_exit 2 "bad number" -- "$bake" "$font" --face x
expect_exit 2 "bad variation" -- "$bake" "$font" --var wght
expect_exit 2 "bad ranges" -- "$bake" "$font" --codepoints 10-5
expect_exit 2 "text and codepoints" -- "$bake" "$font" --text a --codepoints 65
expect_exit 3 "missing font" -- "$bake" "$work/missing.ttf"
head -c 5000 /dev/urandom > "$work/noise.ttf"
expect_exit 3 "not a font" -- "$bake" "$work/noise.ttf" -o "$work/noise.crisp"
[ ! -e "$work/noise.crisp" ] || fail "a failed bake left an asset"
expect_exit 3 "variation on a static font" -- "$bake" "$font" --var wght=700 -o "$work/x.crisp"
expect_exit 4 "unwritable output" -- "$bake" "$font" --text abc -o "$work/no/such/dir/out.crisp"
grep -q "no/such/dir" "$work/err" || fail "the output error does not name the path"

# A good bake, then a failing one onto the same path: the good asset survives byte for byte.
expect_exit 0 "subset bake" -- "$bake" "$font" --text "Hello" -o "$work/good.crisp" -q
cp "$work/good.crisp" "$work/good.copy"
expect_exit 5 "failed glyphs" -- "$bake" "$font" --text "Hello" --max-curves 3 -o "$work/good.crisp"
grep -q "failed" "$work/err" || fail "glyph failures are not reported"
cmp -s "$work/good.crisp" "$work/good.copy" || fail "a failed bake changed an existing asset"
expect_exit 0 "allow failed" -- "$bake" "$font" --text "Hello" --max-curves 3 --allow-failed -o "$work/partial.crisp" -q
[ -z "$(ls -A "$work" | grep -E '\.tmp')" ] || fail "temporary files were left behind"

# --check on good and bad assets.
expect_exit 0 "check valid" -- "$bake" --check "$work/good.crisp"
grep -q "valid crisp asset" "$work/out" || fail "--check prints no summary"
head -c 1000 "$work/good.crisp" > "$work/truncated.crisp"
expect_exit 6 "check truncated" -- "$bake" --check "$work/truncated.crisp"
grep -q "truncated" "$work/err" || fail "--check does not name the fault: $(cat "$work/err")"
cp "$work/good.crisp" "$work/flipped.crisp"
printf '\x55' | dd of="$work/flipped.crisp" bs=1 seek=200 conv=notrunc 2>/dev/null
expect_exit 6 "check flipped" -- "$bake" --check "$work/flipped.crisp"
expect_exit 6 "check missing" -- "$bake" --check "$work/none.crisp"
expect_exit 6 "check a font" -- "$bake" --check "$font"

# --json is JSON on stdout with the report's fields; nothing else goes to stdout.
expect_exit 0 "json bake" -- "$bake" "$source/fonts/Inter-Regular.otf" --text "Quick brown fox" --json -o "$work/inter.crisp"
python3 - "$work/out" <<'PY' || fail "--json output is not the expected JSON"
import json, sys
r = json.load(open(sys.argv[1]))
assert r["failed_glyphs"] == 0 and r["baked_glyphs"] > 10, r
assert r["cubics"] > 0 and r["cubic_pieces"] >= r["cubics"], r
lowering = r["cubic_lowering"]
assert 0 < lowering["max_deviation_em"] <= lowering["tolerance_em"], lowering
assert lowering["seed_split_max_deviation_em"] > lowering["max_deviation_em"], lowering
assert r["bands"]["total"] > 0 and r["curves_per_glyph"]["max"] > 0, r
assert r["asset_bytes"] > 0 and r["seconds"] >= 0 and r["peak_rss_bytes"] > 0, r
PY
expect_exit 0 "json check" -- "$bake" --check "$work/inter.crisp" --json
python3 -c "import json,sys; r=json.load(open(sys.argv[1])); assert r['valid'] and r['cubic'], r" "$work/out" ||
  fail "--check --json output is wrong"

# A collection face and a variable instance.
expect_exit 0 "ttc face" -- "$bake" /usr/share/fonts/opentype/noto/NotoSansCJK-Regular.ttc --face 2 --text "骨" -o "$work/cjk.crisp" --json
python3 -c "import json,sys; r=json.load(open(sys.argv[1])); assert r['face_index']==2 and 'CJK' in r['family'], r" "$work/out" ||
  fail "--face did not pick face 2"
expect_exit 3 "ttc face out of range" -- "$bake" /usr/share/fonts/opentype/noto/NotoSansCJK-Regular.ttc --face 40 -o "$work/x.crisp"
expect_exit 0 "variable" -- "$bake" "$source/fonts/Inter-roman.var.ttf" --var wght=800 --text "Hi" -o "$work/bold.crisp" --json
python3 -c "import json,sys; r=json.load(open(sys.argv[1])); assert any(a['tag']=='wght' and a['value']==800 for a in r['axes']), r" "$work/out" ||
  fail "--var did not reach the asset"

if [ "$failures" -ne 0 ]; then
  echo "$failures CLI checks failed" >&2
  exit 1
fi
echo "all CLI checks passed"
