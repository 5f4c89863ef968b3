#!/usr/bin/env bash
# cli_test.sh CRISP_BAKE SOURCE_DIR WORK_DIR: crisp-bake's exit codes, --json, --check and its
# promise never to leave a broken or half-written asset.
set -uo pipefail
bake=$1 source=$2 work=$3
rm -rf "$work" && mkdir -p "$work" && cd "$work"
. "$(dirname "${BASH_SOURCE[0]}")/cli_common.sh"
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
expect_exit 2 "max size and tolerance" -- "$bake" "$font" --max-size 32 --tolerance 0.001
grep -q "exclude each other" "$work/err" || fail "--max-size with --tolerance: $(cat "$work/err")"
expect_exit 2 "max size out of range" -- "$bake" "$font" --max-size 2000
expect_exit 2 "max size below a pixel" -- "$bake" "$font" --max-size 0.5
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
[ -z "$(ls -A "$work" | grep -E '\.tmp|crisp-tmp')" ] || fail "temporary files were left behind"

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
assert lowering["max_size_px"] == 16 and 0 < lowering["max_deviation_px"] <= 1 / 1024, lowering
assert r["bands"]["total"] > 0 and r["curves_per_glyph"]["max"] > 0, r
assert r["asset_bytes"] > 0 and r["seconds"] >= 0 and r["peak_rss_bytes"] > 0, r
PY
# --max-size sets the tolerance to 1/1024 px at that size, and the report gives the deviation there.
expect_exit 0 "max size bake" -- "$bake" "$source/fonts/Inter-Regular.otf" --text "Quick" --max-size 64 --json -o "$work/inter64.crisp"
python3 - "$work/out" <<'PY' || fail "--max-size 64: the report is not as expected"
import json, sys
lowering = json.load(open(sys.argv[1]))["cubic_lowering"]
assert abs(lowering["tolerance_em"] - 1 / 65536) < 1e-12, lowering
assert lowering["max_size_px"] == 64 and 0 < lowering["max_deviation_px"] <= 1 / 1024, lowering
assert abs(lowering["thirds_coverage_per_edge"] - 3 * lowering["max_deviation_px"]) < 1e-12, lowering
PY
expect_exit 0 "json check" -- "$bake" --check "$work/inter.crisp" --json
python3 -c "import json,sys; r=json.load(open(sys.argv[1])); assert r['valid'] and r['cubic'], r" "$work/out" ||
  fail "--check --json output is wrong"
expect_exit 0 "json check of a max size bake" -- "$bake" --check "$work/inter64.crisp" --json
python3 -c "import json,sys; r=json.load(open(sys.argv[1])); assert r['tolerance_size_px'] == 64, r" "$work/out" ||
  fail "--check --json does not give the size the asset was baked for"

# A collection face and a variable instance.
expect_exit 0 "ttc face" -- "$bake" /usr/share/fonts/opentype/noto/NotoSansCJK-Regular.ttc --face 2 --text "骨" -o "$work/cjk.crisp" --json
python3 -c "import json,sys; r=json.load(open(sys.argv[1])); assert r['face_index']==2 and 'CJK' in r['family'], r" "$work/out" ||
  fail "--face did not pick face 2"
expect_exit 3 "ttc face out of range" -- "$bake" /usr/share/fonts/opentype/noto/NotoSansCJK-Regular.ttc --face 40 -o "$work/x.crisp"
expect_exit 0 "variable" -- "$bake" "$source/fonts/Inter-roman.var.ttf" --var wght=800 --text "Hi" -o "$work/bold.crisp" --json
python3 -c "import json,sys; r=json.load(open(sys.argv[1])); assert any(a['tag']=='wght' and a['value']==800 for a in r['axes']), r" "$work/out" ||
  fail "--var did not reach the asset"

# Bounded inputs and safe outputs (docs/limits.md): a device is not read, nothing but a regular
# file is replaced, the input is never the output, and containers crisp cannot shape say so.
expect_exit 3 "/dev/zero as the font" -- timeout 20 "$bake" /dev/zero -o "$work/zero.crisp"
grep -q "not a regular file" "$work/err" || fail "/dev/zero: $(cat "$work/err")"
mkfifo "$work/fifo.crisp"
expect_exit 4 "a FIFO as the output" -- timeout 20 "$bake" "$font" --text a -o "$work/fifo.crisp"
[ -p "$work/fifo.crisp" ] || fail "the FIFO was replaced"
cp "$font" "$work/input.ttf"
expect_exit 4 "the input as the output" -- "$bake" "$work/input.ttf" --text a -o "$work/input.ttf"
cmp -s "$font" "$work/input.ttf" || fail "the input was overwritten"
grep -q "input" "$work/err" || fail "the refusal does not say why: $(cat "$work/err")"
# A FIFO as the font or as --check's asset is refused at once: opening it used to wait for a writer.
mkfifo "$work/in.fifo"
expect_exit 3 "a FIFO as the font" -- timeout 20 "$bake" "$work/in.fifo" -o "$work/fifo-font.crisp"
grep -q "not a regular file" "$work/err" || fail "a FIFO as the font: $(cat "$work/err")"
expect_exit 6 "a FIFO as --check's asset" -- timeout 20 "$bake" --check "$work/in.fifo"
grep -q "not a regular file" "$work/err" || fail "a FIFO as --check's asset: $(cat "$work/err")"
# A link to a device, to nothing or to an open descriptor is refused like a device, the link kept
# (`-o /dev/stdout` as root replaced /dev's link by a file); a link to a file writes the file.
ln -s /dev/null "$work/null.crisp"
ln -s "$work/no/such/file.crisp" "$work/dangling.crisp"
ln -s /proc/self/fd/1 "$work/stdout.crisp"
for link in null dangling stdout; do
  expect_exit 4 "a link to $link as the output" -- "$bake" "$font" --text a -o "$work/$link.crisp"
  [ -L "$work/$link.crisp" ] || fail "the link to $link was replaced"
done
ln -s target.crisp "$work/link.crisp"
printf 'old' > "$work/target.crisp"
expect_exit 0 "a link to a file as the output" -- "$bake" "$font" --text a -o "$work/link.crisp" -q
[ -L "$work/link.crisp" ] || fail "the link to a file was replaced"
expect_exit 0 "the file the link leads to" -- "$bake" --check "$work/target.crisp"
# A read-only output is refused and left as it was; a writable one keeps its mode (and owner, as root).
printf 'old' > "$work/read-only.crisp" && chmod 0444 "$work/read-only.crisp"
expect_exit 4 "a read-only output" -- "$bake" "$font" --text a -o "$work/read-only.crisp"
grep -q "read-only" "$work/err" || fail "a read-only output: $(cat "$work/err")"
[ "$(cat "$work/read-only.crisp")" = old ] || fail "the read-only output was replaced"
printf 'old' > "$work/mode.crisp" && chmod 0640 "$work/mode.crisp"
[ "$(id -u)" -eq 0 ] && chown 65534:65534 "$work/mode.crisp"
owner=$(stat -c %u:%g "$work/mode.crisp")
expect_exit 0 "a writable output of mode 0640" -- "$bake" "$font" --text a -o "$work/mode.crisp" -q
[ "$(stat -c %a "$work/mode.crisp")" = 640 ] || fail "the mode was not kept: $(stat -c %a "$work/mode.crisp")"
[ "$(stat -c %u:%g "$work/mode.crisp")" = "$owner" ] || fail "the owner was not kept: $(stat -c %u:%g "$work/mode.crisp")"
# A name longer than the file system takes fails before the baking; the longest it takes is written.
name_max=$(getconf NAME_MAX "$work")
long=$(printf 'n%.0s' $(seq "$name_max"))
expect_exit 4 "a name of NAME_MAX + 1 bytes" -- "$bake" "$work/missing.ttf" -o "$work/${long}x"
grep -q "File name too long" "$work/err" || fail "a name too long: $(cat "$work/err")"
expect_exit 0 "a name of NAME_MAX bytes" -- "$bake" "$font" --text a -o "$work/$long" -q
[ -f "$work/$long" ] || fail "the NAME_MAX name was not written"
# Files named as temporaries were (and a killed writer's), which a write used to remove: kept.
printf 'mine' > "$work/.kept.crisp.tmp-ABCDEF" && touch -d '-2 minutes' "$work/.kept.crisp.tmp-ABCDEF"
expect_exit 0 "a write beside a user's .NAME.tmp-XXXXXX" -- "$bake" "$font" --text a -o "$work/kept.crisp" -q
[ -f "$work/.kept.crisp.tmp-ABCDEF" ] || fail "a user's file named like a temporary was removed"
printf 'wOF2\0\1\0\0xxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxx' > "$work/font.woff2"
expect_exit 3 "WOFF2" -- "$bake" "$work/font.woff2" -o "$work/woff2.crisp"
grep -q "decompress" "$work/err" || fail "WOFF2: no advice: $(cat "$work/err")"
expect_exit 2 "a tolerance below float range" -- "$bake" "$font" --tolerance 1e-46
grep -q "out of range" "$work/err" || fail "1e-46: $(cat "$work/err")"
# A family name with terminal escapes (a crafted asset could retitle the terminal) is printed escaped.
/usr/bin/python3 - "$font" "$work/evil.ttf" <<'PY' || fail "could not make the escape font"  # Debian's python3 has fontTools
import sys
from fontTools.ttLib import TTFont
font = TTFont(sys.argv[1])
for record in font["name"].names:
    if record.nameID in (1, 16):
        record.string = "Evil\x1b]0;pwned\x07Sans"
font.save(sys.argv[2])
PY
expect_exit 0 "escape font" -- "$bake" "$work/evil.ttf" --text a -o "$work/evil.crisp" -q
# The baker already turns the control characters into '?'; an asset written by other means may keep
# them: put them back and fix the checksum (CRC-32C of all but bytes 24..27, docs/asset-format.md).
/usr/bin/python3 - "$work/evil.crisp" <<'PY' || fail "could not craft the escape asset"
import struct, sys
path = sys.argv[1]
data = bytearray(open(path, "rb").read())
at = data.find(b"Evil?]0;pwned?Sans")
assert at > 0
data[at + 4] = 0x1B
data[at + 13] = 0x07
table = []
for n in range(256):
    c = n
    for _ in range(8):
        c = (c >> 1) ^ 0x82F63B78 if c & 1 else c >> 1
    table.append(c)
crc = 0xFFFFFFFF
for byte in bytes(data[:24]) + bytes(data[28:]):
    crc = table[(crc ^ byte) & 0xFF] ^ (crc >> 8)
struct.pack_into("<I", data, 24, crc ^ 0xFFFFFFFF)
open(path, "wb").write(data)
PY
expect_exit 0 "check escape asset" -- "$bake" --check "$work/evil.crisp"
if grep -q $'\x1b' "$work/out" || grep -q $'\x07' "$work/out"; then
  fail "--check printed a raw control character"
fi
grep -q 'Evil\\x1b' "$work/out" || fail "--check does not show the escaped name: $(cat -v "$work/out")"

if [ "$failures" -ne 0 ]; then
  echo "$failures CLI checks failed" >&2
  exit 1
fi
echo "all CLI checks passed"
