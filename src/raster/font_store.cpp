#include "raster/font_store.hpp"

#include "text/effect_code.hpp"

#include <algorithm>
#include <cstring>
#include <optional>
#include <string>
#include <utility>

namespace crisp::raster {

FontStore::FontStore(const vk::DeviceRef& ref, VkDeviceSize max_range) : ref_(ref), max_range_(max_range) {}

const HeldFont* FontStore::find(FontId id) const {
    const auto slot = font_slot_.find(id);
    return slot == font_slot_.end() ? nullptr : &fonts_[slot->second];
}

// Finds `font` its ranges in a page with room, or in a new page.
Status FontStore::place(GpuFont& font) {
    for (uint32_t i = 0; i < pages_.size(); ++i) {
        FontPage& page = pages_[i];
        const auto points_at = page.point_ranges.take(font.points_bytes, sizeof(Point));
        if (!points_at) continue;
        const auto bands_at = page.band_ranges.take(font.bands_bytes, sizeof(uint32_t));
        if (!bands_at) {
            page.point_ranges.give(*points_at, font.points_bytes);
            continue;
        }
        font.page = i;
        font.points_at = *points_at;
        font.bands_at = *bands_at;
        return {};
    }
    const auto empty = std::find_if(pages_.begin(), pages_.end(), [](const FontPage& p) { return !p.points.buffer; });
    if (empty == pages_.end() && pages_.size() >= kRendererFontPages) {
        return Error{ErrorCode::invalid_argument,
                     "renderer: the font does not fit the " + std::to_string(kRendererFontPages) +
                         " font pages, which the fonts added before fill; remove one first"};
    }
    const auto capacity = [&](VkDeviceSize need, VkDeviceSize least) {
        return std::max(need, std::min(std::max(2 * need, least), max_range_));
    };
    FontPage page;
    const VkBufferUsageFlags usage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT;
    Status status =
        vk::create_buffer(ref_, capacity(font.points_bytes, kMinPagePoints), usage, false, "font points", page.points);
    if (status) {
        status =
            vk::create_buffer(ref_, capacity(font.bands_bytes, kMinPageBands), usage, false, "font bands", page.bands);
    }
    if (!status) {
        page.points.reset();
        page.bands.reset();
        return status;
    }
    page.point_ranges = RangeAllocator(page.points.size);
    page.band_ranges = RangeAllocator(page.bands.size);
    if (empty != pages_.end()) {
        *empty = std::move(page);
    } else {
        pages_.push_back(std::move(page));
    }
    return place(font);
}

Status FontStore::stage(GpuFont& gpu) {
    const FontAsset& asset = *gpu.asset;
    gpu.points_bytes = asset.points.size() * sizeof(Point);
    gpu.flat_row_of.assign(asset.glyphs.size(), kNoFlatRow);
    for (size_t g = 0; g < asset.glyphs.size(); ++g) {
        const std::vector<uint32_t> row = flat_curve_words(asset, asset.glyphs[g]);
        if (row.empty()) continue;
        gpu.flat_row_of[g] = static_cast<uint32_t>(asset.band_words.size() + gpu.flat_words.size());
        gpu.flat_words.insert(gpu.flat_words.end(), row.begin(), row.end());
    }
    gpu.flat_rows = gpu.flat_row_of;  // moving the vector keeps its storage
    gpu.bands_bytes = (asset.band_words.size() + gpu.flat_words.size()) * sizeof(uint32_t);
    if (std::max(gpu.points_bytes, gpu.bands_bytes) > max_range_) {
        return Error{ErrorCode::vulkan,
                     "renderer: the font's " +
                         std::string(gpu.points_bytes > gpu.bands_bytes ? "curve points" : "band bitsets") + " (" +
                         std::to_string(std::max(gpu.points_bytes, gpu.bands_bytes)) +
                         " bytes) pass the device's maxStorageBufferRange of " + std::to_string(max_range_)};
    }
    if (Status placed = place(gpu); !placed) return placed;
    if (Status made = vk::create_buffer(ref_, gpu.points_bytes + gpu.bands_bytes, VK_BUFFER_USAGE_TRANSFER_SRC_BIT,
                                        true, "font staging", gpu.staging);
        !made) {
        pages_[gpu.page].point_ranges.give(gpu.points_at, gpu.points_bytes);
        pages_[gpu.page].band_ranges.give(gpu.bands_at, gpu.bands_bytes);
        return made;
    }
    auto* bytes = static_cast<std::byte*>(gpu.staging.mapped);
    if (gpu.points_bytes) std::memcpy(bytes, asset.points.data(), gpu.points_bytes);
    const size_t asset_band_bytes = asset.band_words.size() * sizeof(uint32_t);
    if (asset_band_bytes) std::memcpy(bytes + gpu.points_bytes, asset.band_words.data(), asset_band_bytes);
    if (!gpu.flat_words.empty()) {
        std::memcpy(bytes + gpu.points_bytes + asset_band_bytes, gpu.flat_words.data(),
                    gpu.flat_words.size() * sizeof(uint32_t));
    }
    return {};
}

uint32_t FontStore::keep(GpuFont&& gpu) {
    // A removed font's place is taken again before the list grows.
    const auto free_place = std::find_if(fonts_.begin(), fonts_.end(), [](const GpuFont& f) { return !f.asset; });
    const auto index = static_cast<uint32_t>(free_place - fonts_.begin());
    if (free_place == fonts_.end()) {
        fonts_.push_back(std::move(gpu));
    } else {
        *free_place = std::move(gpu);
    }
    return index;
}

Status FontStore::add(const Font& font) {
    if (font_slot_.count(font.id()) && std::find(removals_.begin(), removals_.end(), font.id()) == removals_.end()) {
        return Error{ErrorCode::invalid_argument,
                     "renderer: a font with id " + std::to_string(font.id()) + " was added already"};
    }
    if (font_slot_.count(font.id())) {
        return Error{ErrorCode::invalid_argument, "renderer: the font with id " + std::to_string(font.id()) +
                                                      " is removed at the next begin_frame(); add it after that"};
    }
    GpuFont gpu;
    gpu.asset = &font.asset();
    if (Status staged = stage(gpu); !staged) return staged;
    font_slot_[font.id()] = keep(std::move(gpu));
    return {};
}

HeldGlyph FontStore::glyph(const GlyphKey& key) const {
    if (key.effect == 0) return HeldFonts::glyph(key);
    HeldGlyph held;
    const auto slot = derived_slot_.find({key.font, key.glyph, key.effect, effect_octave(key)});
    if (slot == derived_slot_.end()) return held;
    const GpuFont& font = fonts_[slot->second];
    held.font = &font;
    held.record = &font.derived->glyphs.front();
    held.flat_row = font.flat_rows.empty() ? kNoFlatRow : font.flat_rows.front();
    held.set_b_first = font.set_b_first;
    held.op = font.op;
    held.derived = true;
    return held;
}

Status FontStore::derive(const GlyphKey& key) {
    const DerivedKey id{key.font, key.glyph, key.effect, effect_octave(key)};
    if (const auto held = derived_slot_.find(id); held != derived_slot_.end()) {
        fonts_[held->second].last_used = frame_;
        return {};
    }
    const HeldFont* source = find(key.font);
    const FontAsset* from = source ? source->asset : nullptr;
    const uint32_t glyph = key.glyph & ~kSilhouetteGlyph;
    const bool silhouette = (key.glyph & kSilhouetteGlyph) != 0;
    const ColourGlyph* colour = silhouette && from ? from->colour_glyph(glyph) : nullptr;
    if (key.effect == 0 || !from || glyph >= from->glyphs.size() || (silhouette && !colour)) {
        return Error{ErrorCode::invalid_argument, std::string("renderer: no ") + (silhouette ? "colour " : "") +
                                                      "glyph " + std::to_string(glyph) + " of font " +
                                                      std::to_string(key.font) + " to derive an effect from"};
    }
    const double tolerance = effect_tolerance(id.octave);
    Result<DerivedGlyph> made = colour ? derive_silhouette_glyph(*from, *colour, key.effect, tolerance)
                                       : derive_effect_glyph(*from, from->glyphs[glyph], key.effect, tolerance);
    if (!made) return made.error();
    const uint64_t bytes = made->points.size() * sizeof(Point) + made->band_words.size() * sizeof(uint32_t);
    // Room: derived glyphs not drawn this frame go, least lately drawn first.
    while (derived_bytes_ + bytes > kMaxDerivedBytes || derived_slot_.size() >= kMaxDerivedGlyphs) {
        uint32_t oldest = UINT32_MAX;
        for (const auto& [k, slot] : derived_slot_) {
            if (fonts_[slot].last_used < frame_ &&
                (oldest == UINT32_MAX || fonts_[slot].last_used < fonts_[oldest].last_used)) {
                oldest = slot;
            }
        }
        if (oldest == UINT32_MAX || !retired_) {
            return Error{ErrorCode::invalid_argument,
                         "renderer: this frame's derived glyphs (effects) take all of their " +
                             std::to_string(kMaxDerivedBytes >> 20) + " MiB"};
        }
        forget_derived(oldest, *retired_, frame_);
    }
    auto asset = std::make_unique<FontAsset>();
    made->record.point_offset = 0;
    made->record.band_offset = 0;
    asset->glyphs.push_back(made->record);
    asset->points = std::move(made->points);
    asset->band_words = std::move(made->band_words);
    GpuFont gpu;
    gpu.asset = asset.get();
    gpu.derived = std::move(asset);
    gpu.source = key.font;
    gpu.set_b_first = made->set_b_first;
    gpu.op = decode_effect(key.effect).op;
    gpu.last_used = frame_;
    if (Status staged = stage(gpu); !staged) return staged;
    derived_bytes_ += gpu.points_bytes + gpu.bands_bytes;
    ++derived_made_;
    derived_slot_[id] = keep(std::move(gpu));
    return {};
}

Status FontStore::remove(FontId id) {
    if (!font_slot_.count(id) || std::find(removals_.begin(), removals_.end(), id) != removals_.end()) {
        return Error{ErrorCode::invalid_argument, "renderer: no font with id " + std::to_string(id) + " to remove"};
    }
    removals_.push_back(id);
    return {};
}

void FontStore::release(uint32_t slot, RetireLists& retired, uint64_t frame) {
    GpuFont& font = fonts_[slot];
    if (font.staging.buffer) retired.buffers.push_back({std::move(font.staging), frame});
    retired.ranges.push_back(
        {font.page, {font.points_at, font.points_bytes}, {font.bands_at, font.bands_bytes}, frame});
    font = GpuFont{};
}

void FontStore::forget_derived(uint32_t slot, RetireLists& retired, uint64_t frame) {
    const GpuFont& font = fonts_[slot];
    derived_bytes_ -= font.points_bytes + font.bands_bytes;
    std::erase_if(derived_slot_, [&](const auto& d) { return d.second == slot; });
    release(slot, retired, frame);
}

void FontStore::apply_removals(GlyphAtlas& atlas, RetireLists& retired, uint64_t frame) {
    for (FontId id : removals_) {
        const auto slot = font_slot_.find(id);
        if (slot == font_slot_.end()) continue;
        atlas.evict_font(id);  // its effect layers' entries too: their keys name it
        release(slot->second, retired, frame);
        font_slot_.erase(slot);
        for (uint32_t i = 0; i < fonts_.size(); ++i) {
            if (fonts_[i].derived && fonts_[i].source == id) forget_derived(i, retired, frame);
        }
    }
    removals_.clear();
}

void FontStore::begin_frame(RetireLists& retired, uint64_t frame) {
    retired_ = &retired;
    frame_ = frame;
    derived_made_ = 0;
    for (uint32_t i = 0; i < fonts_.size(); ++i) {
        if (fonts_[i].derived && frame > fonts_[i].last_used + kForgetDerivedFrames) forget_derived(i, retired, frame);
    }
}

bool FontStore::record_uploads(VkCommandBuffer command_buffer, uint64_t this_frame, RetireLists& retired,
                               RendererStats& stats) {
    uploaded_.clear();
    bool uploaded = false;
    for (GpuFont& font : fonts_) {
        if (font.uploaded || !font.asset) continue;
        uploaded_.push_back(static_cast<uint32_t>(&font - fonts_.data()));
        const FontPage& page = pages_[font.page];
        if (font.points_bytes) {
            const VkBufferCopy copy{0, font.points_at, font.points_bytes};
            ref_.fn->vkCmdCopyBuffer(command_buffer, font.staging.buffer, page.points.buffer, 1, &copy);
        }
        if (font.bands_bytes) {
            const VkBufferCopy copy{font.points_bytes, font.bands_at, font.bands_bytes};
            ref_.fn->vkCmdCopyBuffer(command_buffer, font.staging.buffer, page.bands.buffer, 1, &copy);
        }
        stats.upload_bytes += font.points_bytes + font.bands_bytes;
        font.uploaded = true;
        font.retired_staging = font.staging.buffer;
        retired.buffers.push_back({std::move(font.staging), this_frame});
        uploaded = true;
    }
    return uploaded;
}

void FontStore::abandon_uploads(RetireLists& retired, uint64_t frame) {
    for (uint32_t index : uploaded_) {
        GpuFont& font = fonts_[index];
        std::optional<vk::DeviceBuffer> staging = retired.take_back(font.retired_staging, frame);
        if (!staging) continue;
        font.staging = std::move(*staging);
        font.uploaded = false;
    }
}

void FontStore::give_back(const RetiredRanges& ranges) {
    FontPage& page = pages_[ranges.page];
    page.point_ranges.give(ranges.points.offset, ranges.points.size);
    page.band_ranges.give(ranges.bands.offset, ranges.bands.size);
    // A page that no font uses any more gives its buffers back (the GPU is done with the ranges:
    // they retire once the frames that may read them are), and its place waits for a new page.
    if (page.point_ranges.all_free() && page.band_ranges.all_free()) {
        page.points.reset();
        page.bands.reset();
        page.point_ranges = RangeAllocator();
        page.band_ranges = RangeAllocator();
    }
}

}  // namespace crisp::raster
