#include "bake/colr.hpp"

#include <crisp/bake.hpp>

#include <algorithm>

namespace crisp {

using sfnt::fits;
using sfnt::s16;
using sfnt::u16;
using sfnt::u24;
using sfnt::u32;
using sfnt::u8;

namespace {

Error unreadable(std::string_view table, const std::string& why) {
    return Error{ErrorCode::font_unreadable, std::string(table) + ": " + why};
}

std::string at(size_t offset) {
    return "offset " + std::to_string(offset);
}

// Refuses `count` records of `size` bytes at `offset` that do not fit in the table.
Status check_array(std::span<const std::byte> table, std::string_view name, std::string_view what, size_t offset,
                   size_t count, size_t size) {
    if (count == 0 || fits(table, offset, count * size)) return {};
    return unreadable(name, "the " + std::to_string(count) + " " + std::string(what) + " at " + at(offset) +
                                " run past the table's end (" + std::to_string(table.size()) + " bytes)");
}

// A binary search of `count` records of `size` bytes from `offset`, sorted by the glyph ID that
// starts each (as both COLR versions require): the record of `glyph`, or SIZE_MAX. A table that is
// not sorted finds wrong records, never bytes outside the checked array.
size_t find_record(std::span<const std::byte> table, size_t offset, size_t count, size_t size, uint32_t glyph) {
    size_t low = 0, high = count;
    while (low < high) {
        const size_t middle = low + (high - low) / 2;
        const uint32_t id = u16(table, offset + middle * size);
        if (id == glyph) return offset + middle * size;
        if (id < glyph) {
            low = middle + 1;
        } else {
            high = middle;
        }
    }
    return SIZE_MAX;
}

template <class T>
void append_bytes(std::string& key, const T& value) {
    key.append(reinterpret_cast<const char*>(&value), sizeof value);
}

}  // namespace

Result<std::span<const std::byte>> find_sfnt_table(std::span<const std::byte> font, uint32_t face_index, uint32_t tag) {
    const std::string name = tag_to_string(tag);
    size_t directory = 0;
    if (fits(font, 0, 4) && u32(font, 0) == make_tag("ttcf")) {
        if (!fits(font, 0, 12) || face_index >= u32(font, 8) || !fits(font, 12 + size_t{4} * face_index, 4)) {
            return unreadable(name, "the collection header holds no face " + std::to_string(face_index));
        }
        directory = u32(font, 12 + size_t{4} * face_index);
    }
    if (!fits(font, directory, 12)) {
        return unreadable(name, "the table directory at " + at(directory) + " lies past the font's end");
    }
    const size_t table_count = u16(font, directory + 4);
    if (!fits(font, directory + 12, table_count * 16)) {
        return unreadable(name,
                          "the table directory's " + std::to_string(table_count) + " records run past the font's end");
    }
    for (size_t i = 0; i < table_count; ++i) {
        const size_t record = directory + 12 + 16 * i;
        if (u32(font, record) != tag) continue;
        const size_t offset = u32(font, record + 8), length = u32(font, record + 12);
        if (!fits(font, offset, length)) {
            return unreadable(name, "the table (" + std::to_string(length) + " bytes at " + at(offset) +
                                        ") runs past the font's end (" + std::to_string(font.size()) + " bytes)");
        }
        return font.subspan(offset, length);
    }
    return std::span<const std::byte>{};
}

Result<ColrReader> ColrReader::open(std::span<const std::byte> colr, std::span<const std::byte> cpal,
                                    uint32_t glyph_count, uint32_t units_per_em) {
    ColrReader reader;
    reader.colr_ = colr;
    reader.cpal_ = cpal;
    reader.glyph_count_ = glyph_count;
    reader.units_per_em_ = units_per_em;
    if (Status status = reader.read_colr(); !status) return status.error();
    if (Status status = reader.read_cpal(); !status) return status.error();
    return reader;
}

Status ColrReader::read_colr() {
    if (!fits(colr_, 0, 14)) {
        return unreadable("COLR", std::to_string(colr_.size()) + " bytes, shorter than its 14-byte header");
    }
    version_ = u16(colr_, 0);
    if (version_ > 1) return unreadable("COLR", "version " + std::to_string(version_) + " (crisp reads 0 and 1)");
    base_record_count_ = u16(colr_, 2);
    base_records_ = u32(colr_, 4);
    layer_records_ = u32(colr_, 8);
    layer_record_count_ = u16(colr_, 12);
    if (Status s = check_array(colr_, "COLR", "base glyph records", base_records_, base_record_count_, 6); !s) return s;
    if (Status s = check_array(colr_, "COLR", "layer records", layer_records_, layer_record_count_, 4); !s) return s;
    if (version_ == 0) return {};

    if (!fits(colr_, 0, 34)) {
        return unreadable("COLR", std::to_string(colr_.size()) + " bytes, shorter than its 34-byte version 1 header");
    }
    // A list's count comes first, then its records: BaseGlyphList and LayerList count in 32 bits,
    // ClipList after a format byte.
    const auto read_list = [&](size_t header, size_t count_at, size_t record_size, std::string_view what, size_t& list,
                               size_t& count) -> Status {
        list = u32(colr_, header);
        count = 0;
        if (list == 0) return {};
        if (!fits(colr_, list, count_at + 4)) {
            return unreadable("COLR", "the " + std::string(what) + " at " + at(list) + " lies past the table's end (" +
                                          std::to_string(colr_.size()) + " bytes)");
        }
        count = u32(colr_, list + count_at);
        return check_array(colr_, "COLR", std::string(what) + " records", list + count_at + 4, count, record_size);
    };
    if (Status s = read_list(14, 0, 6, "BaseGlyphList", base_glyph_list_, base_glyph_count_); !s) return s;
    if (Status s = read_list(18, 0, 4, "LayerList", layer_list_, layer_count_); !s) return s;
    if (Status s = read_list(22, 1, 7, "ClipList", clip_list_, clip_count_); !s) return s;
    if (clip_list_ != 0 && u8(colr_, clip_list_) != 1) {
        return unreadable("COLR", "ClipList format " + std::to_string(u8(colr_, clip_list_)) + " at " + at(clip_list_) +
                                      " (crisp reads format 1)");
    }
    has_variation_data_ = u32(colr_, 26) != 0 || u32(colr_, 30) != 0;
    return {};
}

Status ColrReader::read_cpal() {
    if (cpal_.empty()) return {};
    if (!fits(cpal_, 0, 12)) {
        return unreadable("CPAL", std::to_string(cpal_.size()) + " bytes, shorter than its 12-byte header");
    }
    const uint32_t entries = u16(cpal_, 2), palettes = u16(cpal_, 4), records = u16(cpal_, 6);
    const size_t records_offset = u32(cpal_, 8);
    if (Status s = check_array(cpal_, "CPAL", "palette starts", 12, palettes, 2); !s) return s;
    if (Status s = check_array(cpal_, "CPAL", "colour records", records_offset, records, 4); !s) return s;
    if (entries > kMaxPaletteSize) {
        return unreadable("CPAL", std::to_string(entries) + " entries per palette, more than crisp's limit of " +
                                      std::to_string(kMaxPaletteSize) + " (kMaxPaletteSize)");
    }
    table_palettes_ = palettes;
    const uint32_t kept = std::min(palettes, kMaxPalettes);
    if (kept == 0 || entries == 0) return {};
    palette_size_ = entries;
    palette_colours_.reserve(size_t{kept} * entries);
    for (uint32_t palette = 0; palette < kept; ++palette) {
        const uint32_t first = u16(cpal_, 12 + size_t{2} * palette);
        if (first + entries > records) {
            return unreadable("CPAL", "palette " + std::to_string(palette) + " starts at colour record " +
                                          std::to_string(first) + ": its " + std::to_string(entries) +
                                          " entries run past the " + std::to_string(records) + " records");
        }
        for (uint32_t entry = 0; entry < entries; ++entry) {
            // A colour record is blue, green, red, alpha.
            const size_t record = records_offset + size_t{4} * (first + entry);
            palette_colours_.push_back(u8(cpal_, record + 2) | u8(cpal_, record + 1) << 8 | u8(cpal_, record) << 16 |
                                       u8(cpal_, record + 3) << 24);
        }
    }
    return {};
}

std::vector<uint32_t> ColrReader::base_glyphs() const {
    std::vector<uint8_t> seen(glyph_count_, 0);
    for (size_t i = 0; i < base_record_count_; ++i) {
        const uint32_t glyph = u16(colr_, base_records_ + 6 * i);
        if (glyph < glyph_count_) seen[glyph] = 1;
    }
    for (size_t i = 0; i < base_glyph_count_; ++i) {
        const uint32_t glyph = u16(colr_, base_glyph_list_ + 4 + 6 * i);
        if (glyph < glyph_count_) seen[glyph] = 1;
    }
    std::vector<uint32_t> glyphs;
    for (uint32_t glyph = 0; glyph < glyph_count_; ++glyph) {
        if (seen[glyph]) glyphs.push_back(glyph);
    }
    return glyphs;
}

size_t ColrReader::v1_paint(uint32_t glyph) const {
    if (base_glyph_list_ == 0) return 0;
    const size_t record = find_record(colr_, base_glyph_list_ + 4, base_glyph_count_, 6, glyph);
    return record == SIZE_MAX ? 0 : base_glyph_list_ + u32(colr_, record + 2);
}

bool ColrReader::v0_record(uint32_t glyph, uint32_t& first_layer, uint32_t& layer_count) const {
    const size_t record = find_record(colr_, base_records_, base_record_count_, 6, glyph);
    if (record == SIZE_MAX) return false;
    first_layer = u16(colr_, record + 2);
    layer_count = u16(colr_, record + 4);
    return true;
}

bool ColrReader::check_palette_index(uint32_t index, std::string& reason) const {
    if (index == kForegroundPaletteIndex || index < palette_size_) return true;
    reason = "palette index " + std::to_string(index) + " is past the " + std::to_string(palette_size_) +
             " entries of CPAL" + (cpal_.empty() ? " (the font has no CPAL)" : "");
    return false;
}

ColrOutcome ColrReader::flatten(uint32_t glyph) {
    ColrOutcome outcome;
    uint32_t first_layer = 0, layer_count = 0;
    const bool has_v0 = v0_record(glyph, first_layer, layer_count);
    if (const size_t paint = v1_paint(glyph); paint != 0) {
        std::string reason;
        outcome.refusal = flatten_v1(glyph, paint, outcome.glyph, reason);
        if (outcome.refusal == ColrRefusal::none) {
            outcome.colour = true;
            return outcome;
        }
        outcome.reason = "COLRv1: " + reason;
        outcome.glyph = {};
        if (!has_v0) return outcome;
    }
    if (!has_v0) return outcome;
    std::string reason;
    ColrGlyph layers;
    const ColrRefusal refusal = flatten_v0(glyph, layers, reason);
    if (refusal == ColrRefusal::none) {
        outcome.colour = true;
        outcome.glyph = std::move(layers);
    } else if (outcome.refusal != ColrRefusal::malformed) {
        // COLRv1 merely unsupported (or absent): the broken COLRv0 layers are the glyph's fault.
        outcome.refusal = refusal;
        outcome.reason = "COLRv0: " + reason;
    }
    return outcome;
}

ColrRefusal ColrReader::flatten_v0(uint32_t glyph, ColrGlyph& out, std::string& reason) {
    uint32_t first = 0, count = 0;
    v0_record(glyph, first, count);
    if (count > kMaxColourLayers) {
        reason =
            std::to_string(count) + " layers, more than " + std::to_string(kMaxColourLayers) + " (kMaxColourLayers)";
        return ColrRefusal::malformed;
    }
    if (first + count > layer_record_count_) {
        reason = "layers " + std::to_string(first) + " to " + std::to_string(first + count - 1) + " are past the " +
                 std::to_string(layer_record_count_) + " layer records";
        return ColrRefusal::malformed;
    }
    font_nodes_ += count;
    if (font_nodes_ > kMaxFontPaintNodes) {
        reason = "the font's colour glyphs hold more than " + std::to_string(kMaxFontPaintNodes) +
                 " paints in all (kMaxFontPaintNodes)";
        return ColrRefusal::malformed;
    }
    for (uint32_t i = 0; i < count; ++i) {
        const size_t record = layer_records_ + size_t{4} * (first + i);
        const uint32_t layer_glyph = u16(colr_, record), palette_index = u16(colr_, record + 2);
        if (layer_glyph >= glyph_count_) {
            reason = "layer " + std::to_string(i) + " names glyph " + std::to_string(layer_glyph) +
                     ", past the face's " + std::to_string(glyph_count_) + " glyphs";
            return ColrRefusal::malformed;
        }
        if (!check_palette_index(palette_index, reason)) {
            reason = "layer " + std::to_string(i) + ": " + reason;
            return ColrRefusal::malformed;
        }
        ColrLayer& layer = out.layers.emplace_back();
        layer.glyph = layer_glyph;
        layer.paint.kind = PaintKind::solid;
        layer.stops.push_back({0.0f, palette_index, 1.0f});
    }
    return ColrRefusal::none;
}

ColrRefusal ColrReader::read_clip_box(uint32_t glyph, ColrGlyph& out, std::string& reason) const {
    if (clip_list_ == 0) return ColrRefusal::none;
    // The clips are sorted by their first glyph: the last that starts at or before `glyph`.
    const size_t records = clip_list_ + 5;
    size_t low = 0, high = clip_count_;
    while (low < high) {
        const size_t middle = low + (high - low) / 2;
        if (u16(colr_, records + 7 * middle) <= glyph) {
            low = middle + 1;
        } else {
            high = middle;
        }
    }
    if (low == 0) return ColrRefusal::none;
    const size_t clip = records + 7 * (low - 1);
    if (glyph > u16(colr_, clip + 2)) return ColrRefusal::none;
    const size_t box = clip_list_ + u24(colr_, clip + 4);
    const uint32_t format = fits(colr_, box, 1) ? u8(colr_, box) : 0;
    const bool known = format == 1 || format == 2;
    if (!known || !fits(colr_, box, format == 2 ? 13 : 9)) {
        reason = "the clip box at " + at(box) +
                 (known || !fits(colr_, box, 1) ? std::string(" lies past the table's end")
                                                : " has format " + std::to_string(format) + " (crisp reads 1 and 2)");
        return ColrRefusal::malformed;
    }
    const int32_t min_x = s16(colr_, box + 1), min_y = s16(colr_, box + 3);
    const int32_t max_x = s16(colr_, box + 5), max_y = s16(colr_, box + 7);
    if (min_x > max_x || min_y > max_y) {
        reason = "the clip box at " + at(box) + " is inverted";
        return ColrRefusal::malformed;
    }
    // No outline reaches past 64 em (the baker refuses it), so a box clamped there clips the same.
    const auto em = [this](int32_t units) {
        return static_cast<float>(std::clamp(units / units_per_em_, -64.0, 64.0));
    };
    out.flags |= kColourClipped;
    out.clip_min_x = em(min_x);
    out.clip_min_y = em(min_y);
    out.clip_max_x = em(max_x);
    out.clip_max_y = em(max_y);
    return ColrRefusal::none;
}

bool ColourAssembler::add(uint32_t glyph, const ColrGlyph& flat, std::string& reason) {
    std::vector<std::string> keys(flat.layers.size());
    size_t added = 0;
    for (size_t i = 0; i < flat.layers.size(); ++i) {
        const ColrLayer& layer = flat.layers[i];
        if (!layer.transformed) continue;
        append_bytes(keys[i], layer.glyph);
        append_bytes(keys[i], layer.outline_transform);
        if (!synthetic_keys_.contains(keys[i]) && std::find(keys.begin(), keys.begin() + static_cast<ptrdiff_t>(i),
                                                            keys[i]) == keys.begin() + static_cast<ptrdiff_t>(i)) {
            ++added;
        }
    }
    if (synthetic_.size() + added > kMaxSyntheticGlyphs) {
        reason = "its transformed layers take the synthetic outlines past " + std::to_string(kMaxSyntheticGlyphs) +
                 " (kMaxSyntheticGlyphs)";
        return false;
    }
    ColourGlyph& colour = colour_glyphs_.emplace_back();
    colour.glyph = glyph;
    colour.first_layer = static_cast<uint32_t>(layers_.size());
    colour.layer_count = static_cast<uint32_t>(flat.layers.size());
    colour.flags = flat.flags;
    colour.clip_min_x = flat.clip_min_x;
    colour.clip_min_y = flat.clip_min_y;
    colour.clip_max_x = flat.clip_max_x;
    colour.clip_max_y = flat.clip_max_y;
    if (flat.layers.empty()) {
        ColrLayer transparent;
        transparent.glyph = glyph;
        transparent.stops.push_back({0.0f, kForegroundPaletteIndex, 0.0f});
        colour.layer_count = 1;
        layers_.push_back({glyph, paint_index(transparent)});
    }
    for (size_t i = 0; i < flat.layers.size(); ++i) {
        const ColrLayer& layer = flat.layers[i];
        uint32_t outline = layer.glyph;
        if (layer.transformed) {
            const auto [it, inserted] =
                synthetic_keys_.try_emplace(keys[i], face_glyph_count_ + static_cast<uint32_t>(synthetic_.size()));
            if (inserted) synthetic_.push_back({layer.glyph, layer.outline_transform});
            outline = it->second;
        }
        layers_.push_back({outline, paint_index(layer)});
    }
    return true;
}

uint32_t ColourAssembler::paint_index(const ColrLayer& layer) {
    Paint paint = layer.paint;
    paint.first_stop = 0;
    paint.stop_count = 0;
    std::string key;
    append_bytes(key, paint);
    for (const ColourStop& stop : layer.stops) append_bytes(key, stop);
    const auto [it, inserted] = paint_keys_.try_emplace(std::move(key), static_cast<uint32_t>(paints_.size()));
    if (inserted) {
        paint.first_stop = static_cast<uint32_t>(stops_.size());
        paint.stop_count = static_cast<uint32_t>(layer.stops.size());
        stops_.insert(stops_.end(), layer.stops.begin(), layer.stops.end());
        paints_.push_back(paint);
    }
    return it->second;
}

void ColourAssembler::mark_layer_glyphs(std::vector<uint8_t>& wanted) const {
    for (const ColourLayer& layer : layers_) {
        if (layer.glyph < face_glyph_count_ && layer.glyph < wanted.size()) wanted[layer.glyph] = 1;
    }
}

Status ColourAssembler::drop_failed_outlines(const std::vector<std::string>& failures, bool allow_failed,
                                             FontAsset& asset, BakeReport& report) {
    if (std::all_of(failures.begin(), failures.end(), [](const std::string& why) { return why.empty(); })) return {};
    std::vector<uint32_t> renumbered(synthetic_.size());
    uint32_t next = face_glyph_count_;
    for (size_t i = 0; i < synthetic_.size(); ++i) renumbered[i] = failures[i].empty() ? next++ : UINT32_MAX;

    std::vector<ColourGlyph> kept;
    std::vector<ColourLayer> kept_layers;
    uint32_t dropped = 0;
    std::string first;
    for (const ColourGlyph& colour : colour_glyphs_) {
        const auto layers = std::span(layers_).subspan(colour.first_layer, colour.layer_count);
        const auto failed = std::find_if(layers.begin(), layers.end(), [&](const ColourLayer& layer) {
            return layer.glyph >= face_glyph_count_ && renumbered[layer.glyph - face_glyph_count_] == UINT32_MAX;
        });
        if (failed != layers.end()) {
            const SyntheticOutline& outline = synthetic_[failed->glyph - face_glyph_count_];
            const std::string why =
                "glyph " + std::to_string(colour.glyph) + ": the outline of its layer " +
                std::to_string(failed - layers.begin()) + " (glyph " + std::to_string(outline.glyph) +
                " under the layer's transform) failed: " + failures[failed->glyph - face_glyph_count_];
            if (dropped++ == 0) first = why;
            if (allow_failed && report.colour_fallbacks++ == 0) report.first_colour_fallback = why;
            continue;
        }
        ColourGlyph& copy = kept.emplace_back(colour);
        copy.first_layer = static_cast<uint32_t>(kept_layers.size());
        for (ColourLayer layer : layers) {
            if (layer.glyph >= face_glyph_count_) layer.glyph = renumbered[layer.glyph - face_glyph_count_];
            kept_layers.push_back(layer);
        }
    }
    if (!allow_failed) {
        return Error{ErrorCode::glyph_failed,
                     "a layer's outline failed in " + std::to_string(dropped) + " colour glyphs; first: " + first};
    }
    for (size_t i = synthetic_.size(); i-- > 0;) {
        if (failures[i].empty()) continue;
        asset.glyphs.erase(asset.glyphs.begin() + static_cast<ptrdiff_t>(face_glyph_count_ + i));
        synthetic_.erase(synthetic_.begin() + static_cast<ptrdiff_t>(i));
    }
    colour_glyphs_ = std::move(kept);
    layers_ = std::move(kept_layers);
    return {};
}

void ColourAssembler::finish(FontAsset& asset) {
    asset.colour_glyphs = std::move(colour_glyphs_);
    asset.layers = std::move(layers_);
    asset.paints = std::move(paints_);
    asset.stops = std::move(stops_);
}

Result<ColourAssembler> read_colour_glyphs(std::span<const std::byte> font_bytes, const FontInfo& info,
                                           uint32_t glyph_count, const BakeOptions& options,
                                           const std::vector<uint8_t>& wanted, FontAsset& asset, BakeReport& report) {
    ColourAssembler assembler(glyph_count);
    const auto refuse_tables = [&](const Error& error) -> Result<ColourAssembler> {
        if (!options.allow_failed) return error;
        report.colour_notes.push_back(error.message + "; no colour glyphs baked");
        return std::move(assembler);
    };
    const Result<std::span<const std::byte>> colr = find_sfnt_table(font_bytes, info.face_index, make_tag("COLR"));
    if (!colr) return refuse_tables(colr.error());
    if (colr->empty()) return assembler;
    const Result<std::span<const std::byte>> cpal = find_sfnt_table(font_bytes, info.face_index, make_tag("CPAL"));
    if (!cpal) return refuse_tables(cpal.error());
    Result<ColrReader> reader = ColrReader::open(*colr, *cpal, glyph_count, info.units_per_em);
    if (!reader) return refuse_tables(reader.error());

    if (reader->table_palettes() > kMaxPalettes) {
        report.colour_notes.push_back("CPAL holds " + std::to_string(reader->table_palettes()) +
                                      " palettes; the first " + std::to_string(kMaxPalettes) +
                                      " (kMaxPalettes) are kept");
    }
    const bool instance = std::any_of(info.axes.begin(), info.axes.end(),
                                      [](const AxisValue& axis) { return axis.value != axis.default_value; });
    if (instance && reader->has_variation_data()) {
        report.colour_notes.push_back(
            "COLR varies, but its deltas are not applied: the colour glyphs are those of "
            "the default instance");
    }
    asset.palette_size = reader->palette_size();
    asset.palette_colours = reader->palette_colours();

    uint32_t colour_count = 0, malformed = 0;
    std::string first_malformed;
    for (const uint32_t glyph : reader->base_glyphs()) {
        if (!wanted.empty() && !wanted[glyph]) continue;
        ++colour_count;
        ColrOutcome outcome = reader->flatten(glyph);
        if (outcome.colour && !assembler.add(glyph, outcome.glyph, outcome.reason)) {
            outcome.refusal = ColrRefusal::malformed;
        }
        if (outcome.refusal == ColrRefusal::none) continue;
        const std::string why = "glyph " + std::to_string(glyph) + ": " + outcome.reason;
        if (outcome.refusal == ColrRefusal::malformed && malformed++ == 0) first_malformed = why;
        if (outcome.refusal == ColrRefusal::unsupported || options.allow_failed) {
            if (report.colour_fallbacks++ == 0) report.first_colour_fallback = why;
        }
    }
    if (malformed > 0 && !options.allow_failed) {
        return Error{ErrorCode::glyph_failed, std::to_string(malformed) + " of " + std::to_string(colour_count) +
                                                  " colour glyphs are malformed; first: " + first_malformed};
    }
    return assembler;
}

}  // namespace crisp
