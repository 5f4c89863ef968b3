#include "shared.h"
#include "vk/barriers.hpp"
#include "vk/features.hpp"
#include "vk/memory.hpp"
#include "vk/resources.hpp"

#include <crisp/renderer.hpp>

#include <algorithm>
#include <cassert>
#include <array>
#include <cmath>
#include <cstring>
#include <optional>
#include <string>
#include <unordered_map>
#include <utility>
#include <vector>

namespace crisp {

namespace {

constexpr VkFormat kAtlasFormat = VK_FORMAT_R16G16B16A16_UINT;
static_assert(kCoverageOne == gpu::kRasterCoverageOne);
static_assert(static_cast<uint32_t>(SampleKind::rows) == gpu::kRasterSampleRows);
static_assert(static_cast<uint32_t>(SampleKind::points) == gpu::kRasterSamplePoints);
static_assert(kRendererFontPages == gpu::kRasterFontPages);

using GpuBuffer = vk::DeviceBuffer;

// A byte range of a font page's buffer.
struct Range {
    VkDeviceSize offset = 0;
    VkDeviceSize size = 0;
};

// Two device-local buffers (curve points, band words) that hold the ranges of several fonts:
// fonts are suballocated from at most kRendererFontPages pages, so their number is not bound to
// the shader's descriptor arrays, and removing a font frees its ranges for the next.
struct FontPage {
    GpuBuffer points;
    GpuBuffer bands;
    std::vector<Range> used_points;  // sorted by offset
    std::vector<Range> used_bands;
};

// The offset of the first gap of `size` bytes (aligned to `alignment`) in a buffer of `capacity`
// bytes whose taken ranges are `used` (sorted), inserted into `used`; nullopt when none fits.
std::optional<VkDeviceSize> take_range(std::vector<Range>& used, VkDeviceSize capacity, VkDeviceSize size,
                                       VkDeviceSize alignment) {
    if (size == 0) return VkDeviceSize{0};
    VkDeviceSize at = 0;
    auto next = used.begin();
    for (;; ++next) {
        at = (at + alignment - 1) / alignment * alignment;
        const VkDeviceSize end = next == used.end() ? capacity : next->offset;
        if (at <= end && end - at >= size) break;
        if (next == used.end()) return std::nullopt;
        at = next->offset + next->size;
    }
    used.insert(next, {at, size});
    return at;
}

void give_range(std::vector<Range>& used, VkDeviceSize offset, VkDeviceSize size) {
    if (size == 0) return;
    std::erase_if(used, [&](const Range& r) { return r.offset == offset; });
}

struct GpuFont {
    const Font* font = nullptr;  // null: a removed font's place, free for the next
    uint32_t page = 0;
    VkDeviceSize points_at = 0;  // byte offsets of its ranges in the page's buffers
    VkDeviceSize bands_at = 0;
    VkDeviceSize points_bytes = 0;
    VkDeviceSize bands_bytes = 0;
    GpuBuffer staging;  // host-visible, points then bands; freed once copied and done
    bool uploaded = false;
    VkBuffer retired_staging = VK_NULL_HANDLE;  // the staging buffer the last upload retired
};

struct Retired {
    GpuBuffer buffer;
    uint64_t frame = 0;  // free once frames_in_flight frames have been recorded after this one
};

// A removed font's page ranges, free once the frames that may read them are done.
struct RetiredRanges {
    uint32_t page = 0;
    Range points, bands;
    uint64_t frame = 0;
};

// Smallest capacities of a new font page; a page holds at least twice the font that makes it.
constexpr VkDeviceSize kMinPagePoints = VkDeviceSize{4} << 20;
constexpr VkDeviceSize kMinPageBands = VkDeviceSize{1} << 20;

}  // namespace

struct CRISP_HIDDEN Renderer::State {
    VkDevice device = VK_NULL_HANDLE;
    VkPhysicalDevice physical_device = VK_NULL_HANDLE;
    const VkAllocationCallbacks* allocator = nullptr;
    vk::Functions fn;  // the caller's Vulkan entry points (RendererCreateInfo::get_instance_proc_addr)
    std::unique_ptr<vk::MemoryArena> arena;  // every buffer's memory: declared first, destroyed last
    vk::DeviceRef ref;                       // device, allocator, memory properties, pipeline cache, debug names, arena
    std::vector<ShaderStatistic> shader_statistics;  // the driver's, where the device enabled them
    VkDeviceSize max_storage_buffer_range = 0;
    uint32_t frames_in_flight = 2;
    bool shared_row_roots = true;
    SampleKind sample_kind = SampleKind::rows;

    GlyphAtlas atlas;
    SubpixelLayout layout;

    vk::DeviceImage atlas_image;
    uint32_t image_width = 0, image_height = 0;  // atlas_image's size (the atlas's, once grown)
    bool atlas_initialized = false;
    uint64_t atlas_budget = 0;  // bytes the atlas image may grow to
    uint32_t max_image_side = 0;
    struct RetiredImage {
        vk::DeviceImage image;
        uint64_t frame = 0;
    };
    std::vector<RetiredImage> retired_images;  // smaller atlas images, until the GPU is done

    // Device-local: RasterItem[item_capacity], then at table_offset the item of each workgroup,
    // uint[workgroup_capacity].
    GpuBuffer items;
    // Host-visible and mapped, one per frame in flight, laid out as `items`: a frame's items and
    // table are written here and copied into `items` by its command buffer.
    std::vector<GpuBuffer> item_staging;
    uint32_t item_capacity = 0;
    uint32_t workgroup_capacity = 0;
    VkDeviceSize table_offset = 0;
    std::vector<uint32_t> workgroup_items;  // this frame's table
    GpuBuffer dummy;  // bound to the font slots no font uses

    std::vector<GpuFont> fonts;                      // index order; removed ones have no font
    std::unordered_map<FontId, uint32_t> font_slot;  // FontId -> index in fonts
    std::vector<FontPage> pages;                     // at most kRendererFontPages
    std::vector<FontId> removals;                    // remove_font()s, applied at begin_frame()
    std::vector<RetiredRanges> retired_ranges;
    std::vector<Retired> retired;

    vk::DeviceObjects objects;  // the shader module and the pipeline
    VkShaderModule shader = VK_NULL_HANDLE;
    vk::DescriptorSets descriptors;  // one set per frame in flight
    VkPipeline pipeline = VK_NULL_HANDLE;

    uint64_t frame = 0;
    struct Pending {
        DrawnGlyph glyph;
        uint32_t entry = kNoAtlasEntry;
    };
    std::vector<Pending> pending;  // draw()n this frame, before record() knows their samples
    struct Clipped {
        GlyphInstance glyph;
        TexelRect part;  // visible texels of its rect
    };
    std::vector<Clipped> clipped;  // draw()n partly visible, acquired in record()
    std::unordered_map<GlyphKey, TexelRect, GlyphKeyHash> clipped_parts;  // scratch: bounding parts
    std::vector<DrawnGlyph> drawn;
    std::vector<gpu::RasterItem> item_data;
    struct Motion {
        double pen_x = 0.0, pen_y = 0.0;  // a named draw's first glyph's pen, offset included
        uint64_t moved = 0;               // the frame its pen last changed (0: never seen move)
        uint64_t seen = 0;                // the frame it was last drawn
    };
    // What the frame committed, so that abandon_frame() can take it back.
    struct Undo {
        bool recorded = false;
        bool atlas_was_initialized = false;
        // The atlas image this frame replaced by a larger one (its copy is in the dropped commands).
        bool grew_image = false;
        VkImage old_image = VK_NULL_HANDLE;  // in retired_images until the frame is known submitted
        uint32_t old_width = 0, old_height = 0;
        std::vector<uint32_t> uploaded_fonts;  // slots whose staging went to `retired` this frame
        // The named draws this frame changed, as they were before it (nullopt: new this frame).
        std::vector<std::pair<uint64_t, std::optional<Motion>>> motions;
        // The subpixel-step level and its clock as they were at begin_frame().
        size_t level = 0;
        uint32_t calm_frames = 0, calm_needed = 0;
        bool just_refined = false;
    } undo;
    RendererStats stats;
    bool converged = true;

    // Subpixel steps per pixel of each level of coarsening (kSubpixelSteps: the layout's own).
    static constexpr std::array<uint32_t, 3> kLevelSteps = {kSubpixelSteps, 4, 1};
    // Frames whose glyphs take under a quarter of the atlas before the steps get finer again; the
    // wait doubles each time finer steps did not fit after all (up to kMaxCalmFrames).
    static constexpr uint32_t kCalmFrames = 120;
    static constexpr uint32_t kMaxCalmFrames = 120u << 6;
    struct Request {
        GlyphInstance glyph;  // moved, recoloured and at its depth as the draw's options asked
        bool has_visible = false;
        VkRect2D visible{};
        uint32_t steps = kSubpixelSteps;  // the finest subpixel steps it may take (moving text: fewer)
    };
    std::vector<Request> requests;  // this frame's draw()n instances, as asked
    size_t level = 0;               // index into kLevelSteps
    uint32_t calm_frames = 0;
    uint32_t calm_needed = kCalmFrames;
    bool just_refined = false;  // the level went down at the end of the last frame
    uint32_t atlas_full = 0;    // instances refused as atlas_full this frame
    uint32_t unplaceable = 0;   // instances draw() could not move (a pen out of range)

    // Where each named draw (DrawOptions::id) was, to tell moving text from static text.
    std::unordered_map<uint64_t, Motion> motions;
    uint64_t frames_begun = 0;  // begin_frame() calls, the clock of `motions`
    // Named draws not seen for this many frames are forgotten.
    static constexpr uint64_t kForgetMotionFrames = 256;

    explicit State(GlyphAtlas glyph_atlas) : atlas(std::move(glyph_atlas)) {}

    // Finds or places `glyph` with `part` of its rect visible and adds it to the pending glyphs.
    // `shown` (within `part`; nullptr: all the atlas holds) is what drawn() reports of it: a
    // clipped glyph shows only its visible texels, though the atlas holds a margin around them.
    void acquire(const GlyphInstance& glyph, const TexelRect& part, const TexelRect* shown = nullptr) {
        if (glyph.width == 0 || glyph.height == 0) return;
        const auto slot = font_slot.find(glyph.key.font);
        if (slot == font_slot.end()) {
            ++stats.unknown_fonts;
            ++stats.skipped_glyphs;
            return;
        }
        const FontAsset& asset = fonts[slot->second].font->asset();
        if (glyph.key.glyph >= asset.glyphs.size()) {
            ++stats.skipped_glyphs;
            return;
        }
        const AtlasLookup lookup = place(asset, glyph, part);
        if (lookup.status == AtlasStatus::placed) {
            const TexelRect& held = lookup.part;
            TexelRect show = held;
            if (shown) {  // the visible texels, within what the atlas holds
                const uint32_t x0 = std::max(shown->x, held.x), y0 = std::max(shown->y, held.y);
                const uint32_t x1 = std::min(shown->x + shown->width, held.x + held.width);
                const uint32_t y1 = std::min(shown->y + shown->height, held.y + held.height);
                if (x0 >= x1 || y0 >= y1) return;
                show = {x0, y0, x1 - x0, y1 - y0};
            }
            DrawnGlyph placed{glyph, lookup.x + (show.x - held.x), lookup.y + (show.y - held.y), 0, show.x, show.y};
            placed.instance.x += static_cast<int32_t>(show.x);
            placed.instance.y += static_cast<int32_t>(show.y);
            placed.instance.width = show.width;
            placed.instance.height = show.height;
            pending.push_back({placed, lookup.entry});
        } else if (lookup.status == AtlasStatus::atlas_full || lookup.status == AtlasStatus::too_large) {
            ++stats.failed_glyphs;
            ++stats.skipped_glyphs;
            if (lookup.status == AtlasStatus::atlas_full) ++atlas_full;
        }
    }

    // Finds or places one instance whose `part` is visible.
    AtlasLookup place(const FontAsset& asset, const GlyphInstance& glyph, const TexelRect& part) {
        // Only a glyph the atlas may place anew needs its cost: a new one, or one held in part.
        uint64_t cost = 0;
        const AtlasEntry* resident = atlas.entry(atlas.find(glyph.key));
        if (!resident || resident->part.width != resident->width || resident->part.height != resident->height)
            cost = curve_tests_per_sample(asset, asset.glyphs[glyph.key.glyph], glyph.key);
        return atlas.acquire(glyph.key, glyph.width, glyph.height, cost, part);
    }

    // `glyph` with its pen moved to the nearest of `steps` subpixel positions per pixel: its key,
    // rect and position follow, its pen moves by at most half a step.
    GlyphInstance coarsened(const GlyphInstance& glyph, uint32_t steps) const {
        if (steps >= kSubpixelSteps) return glyph;
        const auto slot = font_slot.find(glyph.key.font);
        if (slot == font_slot.end()) return glyph;
        const FontAsset& asset = fonts[slot->second].font->asset();
        if (glyph.key.glyph >= asset.glyphs.size()) return glyph;
        const GlyphRecord& record = asset.glyphs[glyph.key.glyph];
        const GlyphRect rect = glyph_rect(record, glyph.key);
        GlyphInstance out = glyph;
        int32_t carry[2] = {0, 0};
        uint8_t* offsets[2] = {&out.key.subpixel_x, &out.key.subpixel_y};
        for (int axis = 0; axis < 2; ++axis) {
            const uint32_t grid = kSubpixelSteps / steps;
            const uint32_t rounded = (*offsets[axis] + grid / 2) / grid * grid;
            carry[axis] = rounded >= kSubpixelSteps ? 1 : 0;
            *offsets[axis] = static_cast<uint8_t>(rounded % kSubpixelSteps);
        }
        if (out.key == glyph.key) return glyph;
        const GlyphRect moved = glyph_rect(record, out.key);
        out.x = glyph.x - rect.x + carry[0] + moved.x;
        out.y = glyph.y - rect.y + carry[1] + moved.y;
        out.width = moved.width;
        out.height = moved.height;
        return out;
    }

    // One draw()n instance: at the frame's subpixel steps, then culled, acquired whole, or kept
    // for acquire_clipped() with its visible part.
    void request(const GlyphInstance& asked, const VkRect2D* visible, uint32_t steps) {
        const GlyphInstance glyph = coarsened(asked, std::min(kLevelSteps[level], steps));
        if (glyph.key != asked.key) ++stats.coarsened_glyphs;
        if (!visible) {
            acquire(glyph, TexelRect{0, 0, glyph.width, glyph.height});
            return;
        }
        if (glyph.width == 0 || glyph.height == 0) return;
        // The visible texels of the glyph's rect.
        const int64_t vx0 = visible->offset.x, vy0 = visible->offset.y;
        const int64_t vx1 = vx0 + visible->extent.width, vy1 = vy0 + visible->extent.height;
        const int64_t x0 = std::max<int64_t>(vx0 - glyph.x, 0), y0 = std::max<int64_t>(vy0 - glyph.y, 0);
        const int64_t x1 = std::min<int64_t>(vx1 - glyph.x, glyph.width);
        const int64_t y1 = std::min<int64_t>(vy1 - glyph.y, glyph.height);
        if (x0 >= x1 || y0 >= y1) {
            ++stats.culled_glyphs;
            return;
        }
        const TexelRect part{static_cast<uint32_t>(x0), static_cast<uint32_t>(y0), static_cast<uint32_t>(x1 - x0),
                             static_cast<uint32_t>(y1 - y0)};
        if (part.width == glyph.width && part.height == glyph.height) {
            acquire(glyph, part);
        } else {
            ++stats.clipped_glyphs;
            clipped.push_back({glyph, part});
        }
    }

    // After the frame's draws: where the atlas had no room for some glyph, the frame starts over
    // with every glyph at the next coarser subpixel steps (a quarter pixel, then a whole one), as
    // long as there is a coarser one; the steps stay coarse until the atlas has been mostly empty
    // for a while. A visible glyph is dropped only when even whole-pixel positions do not fit.
    void settle_requests() {
        acquire_clipped();
        while (atlas_full > 0) {
            if (can_grow()) {
                atlas.grow();  // record() makes the larger image and copies the old one into it
                ++stats.atlas_grown;
            } else if (level + 1 < kLevelSteps.size()) {
                if (just_refined) calm_needed = std::min(calm_needed * 2, kMaxCalmFrames);  // it did not fit
                just_refined = false;
                ++level;
                calm_frames = 0;
            } else {
                break;
            }
            atlas.begin_frame();
            pending.clear();
            clipped.clear();
            // The requests count again; what draw() counted before them stays.
            const uint32_t moving = stats.moving_glyphs, grown = stats.atlas_grown;
            stats = {};
            stats.moving_glyphs = moving;
            stats.atlas_grown = grown;
            stats.skipped_glyphs = unplaceable;
            atlas_full = 0;
            for (const Request& r : requests) request(r.glyph, r.has_visible ? &r.visible : nullptr, r.steps);
            acquire_clipped();
        }
        stats.subpixel_steps = kLevelSteps[level];
        stats.atlas_width = atlas.config().width;
        stats.atlas_height = atlas.config().height;
        just_refined = false;
        const AtlasStats now = atlas.stats();
        if (level > 0 && atlas_full == 0 && now.pinned_cells < now.usable_cells / 4 && ++calm_frames >= calm_needed) {
            --level;  // from the next frame on
            calm_frames = 0;
            just_refined = true;
        }
    }

    // `glyph` with its pen moved by (dx, dy) pixels: its key's subpixel offsets, rect and position
    // follow on each axis that moves. False when the new pen is not finite or out of range.
    bool moved(GlyphInstance& glyph, double dx, double dy) const {
        if (dx == 0.0 && dy == 0.0) return true;
        const auto slot = font_slot.find(glyph.key.font);
        if (slot == font_slot.end()) return true;  // acquire() counts it
        const FontAsset& asset = fonts[slot->second].font->asset();
        if (glyph.key.glyph >= asset.glyphs.size()) return true;
        const GlyphRecord& record = asset.glyphs[glyph.key.glyph];
        const GlyphRect old_rect = glyph_rect(record, glyph.key);
        const double pens[2] = {static_cast<double>(glyph.pen_x) + dx, static_cast<double>(glyph.pen_y) + dy};
        int32_t whole[2] = {glyph.x - old_rect.x, glyph.y - old_rect.y};
        uint8_t* offsets[2] = {&glyph.key.subpixel_x, &glyph.key.subpixel_y};
        const double deltas[2] = {dx, dy};
        for (int axis = 0; axis < 2; ++axis) {
            if (deltas[axis] == 0.0) continue;
            constexpr double kMaxPen = 16777216.0;  // 2^24 px
            if (!(std::abs(pens[axis]) <= kMaxPen)) return false;
            double base = std::floor(pens[axis]);
            double step = std::round((pens[axis] - base) * kSubpixelSteps);
            if (step >= kSubpixelSteps) {
                base += 1.0;
                step = 0.0;
            }
            whole[axis] = static_cast<int32_t>(base);
            *offsets[axis] = static_cast<uint8_t>(step);
        }
        const GlyphRect rect = glyph_rect(record, glyph.key);
        glyph.x = whole[0] + rect.x;
        glyph.y = whole[1] + rect.y;
        glyph.width = rect.width;
        glyph.height = rect.height;
        glyph.pen_x = static_cast<float>(pens[0]);
        glyph.pen_y = static_cast<float>(pens[1]);
        return true;
    }

    // Whether the named draw whose first glyph's pen is (x, y) this frame moved lately.
    bool moving(uint64_t id, double x, double y) {
        auto [it, added] = motions.try_emplace(id, Motion{x, y, 0, frames_begun});
        Motion& m = it->second;
        if (added) {
            undo.motions.emplace_back(id, std::nullopt);
        } else if (m.seen != frames_begun) {  // its first draw this frame
            undo.motions.emplace_back(id, m);
        }
        if (!added && (m.pen_x != x || m.pen_y != y)) {
            m.moved = frames_begun;
            m.pen_x = x;
            m.pen_y = y;
        }
        m.seen = frames_begun;
        return m.moved != 0 && frames_begun - m.moved < kMotionSettleFrames;
    }

    // Whether the atlas may double within the budget and the device's image size.
    bool can_grow() const {
        const uint64_t width = uint64_t{atlas.config().width} * 2, height = uint64_t{atlas.config().height} * 2;
        return width <= std::min<uint64_t>(max_image_side, kAtlasMaxSize) &&
               height <= std::min<uint64_t>(max_image_side, kAtlasMaxSize) &&
               width * height * sizeof(uint16_t) * 4 <= atlas_budget;
    }

    // Acquires the glyphs drawn in part, each glyph once for the bounding box of its parts.
    void acquire_clipped() {
        if (clipped.empty()) return;
        clipped_parts.clear();
        for (const Clipped& c : clipped) {
            auto [it, added] = clipped_parts.try_emplace(c.glyph.key, c.part);
            if (added) continue;
            TexelRect& box = it->second;
            const uint32_t x1 = std::max(box.x + box.width, c.part.x + c.part.width);
            const uint32_t y1 = std::max(box.y + box.height, c.part.y + c.part.height);
            box.x = std::min(box.x, c.part.x);
            box.y = std::min(box.y, c.part.y);
            box.width = x1 - box.x;
            box.height = y1 - box.y;
        }
        for (const Clipped& c : clipped) acquire(c.glyph, clipped_parts.at(c.glyph.key), &c.part);
        clipped.clear();
    }
    ~State();
    Status make_buffer(VkDeviceSize size, VkBufferUsageFlags usage, bool host_visible, const char* what,
                       GpuBuffer& out);
    // `items` and its staging buffers for `capacity` items and the workgroups of an atlas of
    // `atlas_texels`; the ones they replace are retired at frame `retire_at`. On failure nothing
    // changes.
    Status make_item_buffers(uint32_t capacity, uint64_t atlas_texels, uint64_t retire_at);
    void free_buffer(GpuBuffer& buffer);
    Status create_objects();
    void write_descriptors(VkDescriptorSet set);
    Status place_font(GpuFont& font);
    void apply_removals();
    Status grow_image(VkCommandBuffer command_buffer, uint64_t this_frame);
    // record()'s phases, in order.
    void collect_drawn();
    void release_finished(uint64_t this_frame);
    bool record_font_uploads(VkCommandBuffer command_buffer, uint64_t this_frame);
    Status prepare_atlas_image(VkCommandBuffer command_buffer, uint64_t this_frame);
    uint32_t build_work_items(std::span<const RasterWork> work);
    void record_item_upload(VkCommandBuffer command_buffer, uint64_t this_frame, bool fonts_uploaded);
    void record_raster_dispatch(VkCommandBuffer command_buffer, uint64_t this_frame, uint32_t workgroups);
    Status make_atlas_image(const AtlasConfig& config, vk::DeviceImage& out) {
        return vk::create_image(ref, kAtlasFormat, config.width, config.height,
                                VK_IMAGE_USAGE_STORAGE_BIT | VK_IMAGE_USAGE_SAMPLED_BIT |
                                    VK_IMAGE_USAGE_TRANSFER_SRC_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT,
                                "atlas", out);
    }
};

Renderer::State::~State() = default;

Status Renderer::State::make_buffer(VkDeviceSize size, VkBufferUsageFlags usage, bool host_visible, const char* what,
                                    GpuBuffer& out) {
    return vk::create_buffer(ref, size, usage, host_visible, what, out);
}

void Renderer::State::free_buffer(GpuBuffer& buffer) {
    buffer.reset();
}

Status Renderer::State::make_item_buffers(uint32_t capacity, uint64_t atlas_texels, uint64_t retire_at) {
    // Items cover disjoint parts of the atlas, so a dispatch has at most a workgroup per 64 atlas
    // texels plus one partial workgroup per item.
    const uint64_t workgroups = atlas_texels / gpu::kRasterWorkgroupSize + capacity;
    if (workgroups > UINT32_MAX) return Error{ErrorCode::invalid_argument, "renderer: the atlas is too large"};
    // The table starts at an offset every device accepts for a storage buffer (at most 256).
    const VkDeviceSize offset = (VkDeviceSize{capacity} * sizeof(gpu::RasterItem) + 255) / 256 * 256;
    const VkDeviceSize bytes = offset + workgroups * sizeof(uint32_t);
    GpuBuffer device_items;
    if (Status s = make_buffer(bytes, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT, false,
                               "work items", device_items);
        !s) {
        return s;
    }
    std::vector<GpuBuffer> staging(frames_in_flight);
    for (GpuBuffer& slot : staging) {
        if (Status s = make_buffer(bytes, VK_BUFFER_USAGE_TRANSFER_SRC_BIT, true, "work item staging", slot); !s) {
            return s;
        }
    }
    if (items.buffer) retired.push_back({std::move(items), retire_at});
    for (GpuBuffer& old : item_staging) retired.push_back({std::move(old), retire_at});
    items = std::move(device_items);
    item_staging = std::move(staging);
    item_capacity = capacity;
    workgroup_capacity = static_cast<uint32_t>(workgroups);
    table_offset = offset;
    return {};
}

Status Renderer::State::create_objects() {
    // The atlas image.
    const AtlasConfig& config = atlas.config();
    if (Status s = make_atlas_image(config, atlas_image); !s) return s;
    image_width = config.width;
    image_height = config.height;

    // Work items: an entry takes at least one cell, so a frame never has more items than cells.
    if (Status s = make_item_buffers(atlas.stats().usable_cells, uint64_t{config.width} * config.height, 0); !s) {
        return s;
    }
    if (Status s = make_buffer(16, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, false, "empty font slot", dummy); !s) return s;

    // The pipeline.
    Result<VkShaderModule> module = vk::create_embedded_shader(ref, "raster.comp");
    if (!module) return module.error();
    shader = objects.keep(ref, *module);
    const VkDescriptorSetLayoutBinding bindings[] = {
        {gpu::kRasterBindAtlas, VK_DESCRIPTOR_TYPE_STORAGE_IMAGE, 1, VK_SHADER_STAGE_COMPUTE_BIT, nullptr},
        {gpu::kRasterBindItems, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1, VK_SHADER_STAGE_COMPUTE_BIT, nullptr},
        {gpu::kRasterBindPoints, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, kRendererFontPages, VK_SHADER_STAGE_COMPUTE_BIT,
         nullptr},
        {gpu::kRasterBindBands, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, kRendererFontPages, VK_SHADER_STAGE_COMPUTE_BIT,
         nullptr},
        {gpu::kRasterBindWorkgroupItems, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1, VK_SHADER_STAGE_COMPUTE_BIT, nullptr},
    };
    // One descriptor set per frame in flight: a set is rewritten only when its last use is done.
    if (Status s =
            vk::create_descriptor_sets(ref, bindings, VK_SHADER_STAGE_COMPUTE_BIT, sizeof(gpu::RasterPushConstants),
                                       frames_in_flight, "renderer", descriptors);
        !s) {
        return s;
    }
    Result<VkPipeline> made =
        vk::create_compute_pipeline(ref, shader, descriptors.pipeline_layout, nullptr, "raster.comp");
    if (!made) return made.error();
    pipeline = objects.keep(ref, *made);
    return {};
}

void Renderer::State::write_descriptors(VkDescriptorSet set) {
    VkDescriptorImageInfo image{VK_NULL_HANDLE, atlas_image.view, VK_IMAGE_LAYOUT_GENERAL};
    VkDescriptorBufferInfo item_info{items.buffer, 0, table_offset};
    VkDescriptorBufferInfo table_info{items.buffer, table_offset, VK_WHOLE_SIZE};
    std::array<VkDescriptorBufferInfo, kRendererFontPages> point_infos{}, band_infos{};
    for (uint32_t page = 0; page < kRendererFontPages; ++page) {
        const bool used = page < pages.size();
        point_infos[page] = {used ? pages[page].points.buffer : dummy.buffer, 0, VK_WHOLE_SIZE};
        band_infos[page] = {used ? pages[page].bands.buffer : dummy.buffer, 0, VK_WHOLE_SIZE};
    }
    VkWriteDescriptorSet writes[5]{};
    for (VkWriteDescriptorSet& write : writes) {
        write.sType = VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET;
        write.dstSet = set;
        write.descriptorType = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
        write.descriptorCount = 1;
    }
    writes[0].dstBinding = gpu::kRasterBindAtlas;
    writes[0].descriptorType = VK_DESCRIPTOR_TYPE_STORAGE_IMAGE;
    writes[0].pImageInfo = &image;
    writes[1].dstBinding = gpu::kRasterBindItems;
    writes[1].pBufferInfo = &item_info;
    writes[2].dstBinding = gpu::kRasterBindPoints;
    writes[2].descriptorCount = kRendererFontPages;
    writes[2].pBufferInfo = point_infos.data();
    writes[3].dstBinding = gpu::kRasterBindBands;
    writes[3].descriptorCount = kRendererFontPages;
    writes[3].pBufferInfo = band_infos.data();
    writes[4].dstBinding = gpu::kRasterBindWorkgroupItems;
    writes[4].pBufferInfo = &table_info;
    fn.vkUpdateDescriptorSets(device, 5, writes, 0, nullptr);
}

Result<Renderer> Renderer::create(const RendererCreateInfo& info) {
    if (!info.instance || !info.device || !info.physical_device) {
        return Error{ErrorCode::invalid_argument, "renderer: an instance, a physical device and a device are required"};
    }
    if (info.frames_in_flight < 1 || info.frames_in_flight > 8) {
        return Error{ErrorCode::invalid_argument, "renderer: frames_in_flight must be 1 to 8"};
    }
    if (info.atlas.max_samples > kMaxRendererSamples) {
        return Error{ErrorCode::invalid_argument, "renderer: max_samples " + std::to_string(info.atlas.max_samples) +
                                                      " is above the " + std::to_string(kMaxRendererSamples) +
                                                      " the 16-bit accumulators hold"};
    }
    if (info.sample_kind != SampleKind::rows && info.sample_kind != SampleKind::points) {
        return Error{ErrorCode::invalid_argument, "renderer: sample_kind " +
                                                      std::to_string(static_cast<uint32_t>(info.sample_kind)) +
                                                      " is neither rows (0) nor points (1)"};
    }
    SubpixelLayout layout = info.layout;
    if (layout.name.empty() && layout == SubpixelLayout{}) layout = *subpixel_preset("rgb");
    if (Status s = validate_subpixel_layout(layout); !s) return s.error();
    auto atlas = GlyphAtlas::create(info.atlas);
    if (!atlas) return atlas.error();

    vk::Functions fn;
    if (Status s = vk::load_functions(info.get_instance_proc_addr, info.instance, info.device, fn); !s) {
        return Error{s.error().code, "renderer: " + s.error().message};
    }
    VkPhysicalDeviceProperties properties{};
    fn.vkGetPhysicalDeviceProperties(info.physical_device, &properties);
    if (properties.apiVersion < VK_API_VERSION_1_2) {
        return Error{ErrorCode::vulkan, std::string("renderer: ") + properties.deviceName + " offers Vulkan " +
                                            vk::version_string(properties.apiVersion) + "; crisp needs 1.2"};
    }
    Result<vk::DeviceFeatures> enabled = vk::read_enabled_features(info.enabled_features, "renderer");
    if (!enabled) return enabled.error();
    if (!enabled->features2.features.shaderStorageBufferArrayDynamicIndexing) {
        return Error{ErrorCode::vulkan,
                     "renderer: the device was created without shaderStorageBufferArrayDynamicIndexing (enable it; "
                     "add_crisp_features() does)"};
    }
    const uint32_t buffers_needed = 2 + 2 * kRendererFontPages;
    if (properties.limits.maxPerStageDescriptorStorageBuffers < buffers_needed) {
        return Error{ErrorCode::vulkan, "renderer: the device offers " +
                                            std::to_string(properties.limits.maxPerStageDescriptorStorageBuffers) +
                                            " storage buffers per shader stage (maxPerStageDescriptorStorageBuffers); "
                                            "crisp needs " +
                                            std::to_string(buffers_needed)};
    }
    VkFormatProperties format{};
    fn.vkGetPhysicalDeviceFormatProperties(info.physical_device, kAtlasFormat, &format);
    if (!(format.optimalTilingFeatures & VK_FORMAT_FEATURE_STORAGE_IMAGE_BIT)) {
        return Error{ErrorCode::vulkan, "renderer: the device lacks storage images of R16G16B16A16_UINT"};
    }

    auto state = std::make_unique<State>(std::move(*atlas));
    state->device = info.device;
    state->physical_device = info.physical_device;
    state->allocator = info.allocator;
    state->frames_in_flight = info.frames_in_flight;
    state->shared_row_roots = info.shared_row_roots;
    state->sample_kind = info.sample_kind;
    state->max_storage_buffer_range = properties.limits.maxStorageBufferRange;
    state->max_image_side = properties.limits.maxImageDimension2D;
    state->atlas_budget = info.atlas_memory_budget;
    state->fn = fn;
    state->ref = vk::make_device_ref(state->fn, info.physical_device, info.device, info.allocator, info.pipeline_cache);
    state->arena =
        std::make_unique<vk::MemoryArena>(state->fn, info.device, info.allocator, state->ref.memory_properties);
    state->ref.arena = state->arena.get();
    if (enabled->pipeline_executable_info) state->ref.statistics = &state->shader_statistics;
    state->layout = std::move(layout);
    if (Status s = state->create_objects(); !s) return s.error();
    return Renderer(std::move(state));
}

Renderer::Renderer(std::unique_ptr<State> state) : state_(std::move(state)) {}
Renderer::Renderer(Renderer&&) noexcept = default;
Renderer& Renderer::operator=(Renderer&&) noexcept = default;
Renderer::~Renderer() = default;

// The atlas grew (GlyphAtlas::grow): a larger image takes the old one's texels at its top-left,
// and the old one is freed once the frames that read it are done. The work items grow with it.
Status Renderer::State::grow_image(VkCommandBuffer command_buffer, uint64_t this_frame) {
    const AtlasConfig& config = atlas.config();
    vk::DeviceImage grown;
    if (Status s = make_atlas_image(config, grown); !s) return s;
    const uint32_t cells = atlas.stats().usable_cells;
    const uint64_t texels = uint64_t{config.width} * config.height;
    if (cells > item_capacity || texels / gpu::kRasterWorkgroupSize + cells > workgroup_capacity) {
        if (Status s = make_item_buffers(cells, texels, this_frame); !s) {
            grown.reset();
            return s;
        }
    }
    if (atlas_initialized) {
        // Earlier frames' writes (and the compositor's reads) before the copy; the copy before
        // this frame's dispatch and every later read.
        vk::image_barrier(fn, command_buffer, atlas_image.image, VK_IMAGE_LAYOUT_GENERAL,
                          VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL,
                          VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_FRAGMENT_SHADER_BIT,
                          VK_ACCESS_SHADER_WRITE_BIT, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_READ_BIT);
        vk::image_barrier(fn, command_buffer, grown.image, VK_IMAGE_LAYOUT_UNDEFINED,
                          VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, VK_PIPELINE_STAGE_TOP_OF_PIPE_BIT, 0,
                          VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_WRITE_BIT);
        VkImageCopy region{};
        region.srcSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
        region.dstSubresource = region.srcSubresource;
        region.extent = {image_width, image_height, 1};
        fn.vkCmdCopyImage(command_buffer, atlas_image.image, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, grown.image,
                          VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 1, &region);
        vk::image_barrier(fn, command_buffer, grown.image, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL,
                          VK_IMAGE_LAYOUT_GENERAL, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_WRITE_BIT,
                          VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, vk::kShaderAccess);
    }
    undo.grew_image = true;
    undo.old_image = atlas_image.image;
    undo.old_width = image_width;
    undo.old_height = image_height;
    retired_images.push_back({std::move(atlas_image), this_frame});
    atlas_image = std::move(grown);
    image_width = config.width;
    image_height = config.height;
    return {};
}

// Finds `font` its ranges in a page with room, or in a new page.
Status Renderer::State::place_font(GpuFont& font) {
    for (uint32_t i = 0; i < pages.size(); ++i) {
        FontPage& page = pages[i];
        const auto points_at = take_range(page.used_points, page.points.size, font.points_bytes, sizeof(Point));
        if (!points_at) continue;
        const auto bands_at = take_range(page.used_bands, page.bands.size, font.bands_bytes, sizeof(uint32_t));
        if (!bands_at) {
            give_range(page.used_points, *points_at, font.points_bytes);
            continue;
        }
        font.page = i;
        font.points_at = *points_at;
        font.bands_at = *bands_at;
        return {};
    }
    if (pages.size() >= kRendererFontPages) {
        return Error{ErrorCode::invalid_argument,
                     "renderer: the font does not fit the " + std::to_string(kRendererFontPages) +
                         " font pages, which the fonts added before fill; remove one first"};
    }
    const auto capacity = [&](VkDeviceSize need, VkDeviceSize least) {
        return std::max(need, std::min(std::max(2 * need, least), max_storage_buffer_range));
    };
    FontPage page;
    const VkBufferUsageFlags usage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT;
    Status status = make_buffer(capacity(font.points_bytes, kMinPagePoints), usage, false, "font points", page.points);
    if (status) status = make_buffer(capacity(font.bands_bytes, kMinPageBands), usage, false, "font bands", page.bands);
    if (!status) {
        free_buffer(page.points);
        free_buffer(page.bands);
        return status;
    }
    pages.push_back(std::move(page));
    return place_font(font);
}

Status Renderer::add_font(const Font& font) {
    State& s = *state_;
    if (s.font_slot.count(font.id()) &&
        std::find(s.removals.begin(), s.removals.end(), font.id()) == s.removals.end()) {
        return Error{ErrorCode::invalid_argument,
                     "renderer: a font with id " + std::to_string(font.id()) + " was added already"};
    }
    if (s.font_slot.count(font.id())) {
        return Error{ErrorCode::invalid_argument, "renderer: the font with id " + std::to_string(font.id()) +
                                                      " is removed at the next begin_frame(); add it after that"};
    }
    const FontAsset& asset = font.asset();
    GpuFont gpu;
    gpu.font = &font;
    gpu.points_bytes = asset.points.size() * sizeof(Point);
    gpu.bands_bytes = asset.band_words.size() * sizeof(uint32_t);
    if (std::max(gpu.points_bytes, gpu.bands_bytes) > s.max_storage_buffer_range) {
        return Error{ErrorCode::vulkan,
                     "renderer: the font's " +
                         std::string(gpu.points_bytes > gpu.bands_bytes ? "curve points" : "band bitsets") + " (" +
                         std::to_string(std::max(gpu.points_bytes, gpu.bands_bytes)) +
                         " bytes) pass the device's maxStorageBufferRange of " +
                         std::to_string(s.max_storage_buffer_range)};
    }
    if (Status placed = s.place_font(gpu); !placed) return placed;
    if (Status made = s.make_buffer(gpu.points_bytes + gpu.bands_bytes, VK_BUFFER_USAGE_TRANSFER_SRC_BIT, true,
                                    "font staging", gpu.staging);
        !made) {
        give_range(s.pages[gpu.page].used_points, gpu.points_at, gpu.points_bytes);
        give_range(s.pages[gpu.page].used_bands, gpu.bands_at, gpu.bands_bytes);
        return made;
    }
    auto* bytes = static_cast<std::byte*>(gpu.staging.mapped);
    if (gpu.points_bytes) std::memcpy(bytes, asset.points.data(), gpu.points_bytes);
    if (gpu.bands_bytes) std::memcpy(bytes + gpu.points_bytes, asset.band_words.data(), gpu.bands_bytes);
    // A removed font's place is taken again before the list grows.
    const auto free_place = std::find_if(s.fonts.begin(), s.fonts.end(), [](const GpuFont& f) { return !f.font; });
    const auto index = static_cast<uint32_t>(free_place - s.fonts.begin());
    if (free_place == s.fonts.end()) {
        s.fonts.push_back(std::move(gpu));
    } else {
        *free_place = std::move(gpu);
    }
    s.font_slot[font.id()] = index;
    return {};
}

Status Renderer::remove_font(FontId id) {
    State& s = *state_;
    if (!s.font_slot.count(id) || std::find(s.removals.begin(), s.removals.end(), id) != s.removals.end()) {
        return Error{ErrorCode::invalid_argument, "renderer: no font with id " + std::to_string(id) + " to remove"};
    }
    s.removals.push_back(id);
    return {};
}

// The fonts remove_font() named leave: their atlas entries go, their staging buffers and page
// ranges are freed once the frames that may read them are done, and their ids are free.
void Renderer::State::apply_removals() {
    for (FontId id : removals) {
        const auto slot = font_slot.find(id);
        if (slot == font_slot.end()) continue;
        GpuFont& font = fonts[slot->second];
        atlas.evict_font(id);
        if (font.staging.buffer) retired.push_back({std::move(font.staging), frame});
        retired_ranges.push_back(
            {font.page, {font.points_at, font.points_bytes}, {font.bands_at, font.bands_bytes}, frame});
        font = GpuFont{};
        font_slot.erase(slot);
    }
    removals.clear();
}

Status Renderer::set_subpixel_layout(const SubpixelLayout& layout) {
    if (Status s = validate_subpixel_layout(layout); !s) return s;
    state_->layout = layout;
    state_->atlas.invalidate_samples();
    return {};
}

const SubpixelLayout& Renderer::subpixel_layout() const {
    return state_->layout;
}

SampleKind Renderer::sample_kind() const {
    return state_->sample_kind;
}

void Renderer::abandon_frame() {
    State& s = *state_;
    if (!s.undo.recorded) return;
    s.undo.recorded = false;
    s.atlas.abandon_frame();
    if (s.undo.grew_image) {
        // The copy into the larger image never ran: the old image comes back, and the next
        // record() grows it again. (The larger image was only in the dropped commands.)
        const auto old = std::find_if(s.retired_images.begin(), s.retired_images.end(),
                                      [&](const State::RetiredImage& r) { return r.image.image == s.undo.old_image; });
        if (old != s.retired_images.end()) {
            s.atlas_image = std::move(old->image);  // frees the larger image
            s.retired_images.erase(old);
        }
        s.image_width = s.undo.old_width;
        s.image_height = s.undo.old_height;
        s.undo.grew_image = false;
    }
    s.atlas_initialized = s.undo.atlas_was_initialized;
    // Motion and the subpixel-step level go back to what they were, as if the frame never began.
    for (auto it = s.undo.motions.rbegin(); it != s.undo.motions.rend(); ++it) {
        if (it->second) {
            s.motions[it->first] = *it->second;
        } else {
            s.motions.erase(it->first);
        }
    }
    s.undo.motions.clear();
    --s.frames_begun;
    s.level = s.undo.level;
    s.calm_frames = s.undo.calm_frames;
    s.calm_needed = s.undo.calm_needed;
    s.just_refined = s.undo.just_refined;
    // The fonts' uploads go back to waiting, with their staging buffers.
    for (uint32_t index : s.undo.uploaded_fonts) {
        GpuFont& font = s.fonts[index];
        const auto retired = std::find_if(s.retired.begin(), s.retired.end(), [&](const Retired& r) {
            return r.frame == s.frame - 1 && r.buffer.buffer == font.retired_staging;
        });
        if (retired == s.retired.end()) continue;
        font.staging = std::move(retired->buffer);
        font.uploaded = false;
        s.retired.erase(retired);
    }
    --s.frame;  // an abandoned frame does not count towards frames_in_flight
    s.drawn.clear();
    s.converged = false;
}

void Renderer::begin_frame() {
    State& s = *state_;
    ++s.frames_begun;
    if (s.frames_begun % State::kForgetMotionFrames == 0) {
        std::erase_if(s.motions,
                      [&](const auto& m) { return s.frames_begun - m.second.seen > State::kForgetMotionFrames; });
    }
    s.undo.recorded = false;
    s.undo.motions.clear();
    s.undo.level = s.level;
    s.undo.calm_frames = s.calm_frames;
    s.undo.calm_needed = s.calm_needed;
    s.undo.just_refined = s.just_refined;
    s.atlas.begin_frame();  // unpins last frame's glyphs, so that removed fonts' entries can go
    s.apply_removals();
    s.pending.clear();
    s.clipped.clear();
    s.requests.clear();
    s.atlas_full = 0;
    s.unplaceable = 0;
    s.drawn.clear();
    s.stats = {};
    s.converged = true;
}

void Renderer::draw(std::span<const GlyphInstance> glyphs) {
    State& s = *state_;
    for (const GlyphInstance& glyph : glyphs) {
        s.requests.push_back({glyph, false, {}, kSubpixelSteps});
        s.request(glyph, nullptr, kSubpixelSteps);
    }
}

void Renderer::draw(std::span<const GlyphInstance> glyphs, const VkRect2D& visible) {
    State& s = *state_;
    for (const GlyphInstance& glyph : glyphs) {
        s.requests.push_back({glyph, true, visible, kSubpixelSteps});
        s.request(glyph, &visible, kSubpixelSteps);
    }
}

void Renderer::draw(std::span<const GlyphInstance> glyphs, const DrawOptions& options) {
    State& s = *state_;
    if (glyphs.empty()) return;
    const double dx = static_cast<double>(options.offset_x), dy = static_cast<double>(options.offset_y);
    if (!std::isfinite(dx) || !std::isfinite(dy)) {
        const auto count = static_cast<uint32_t>(std::min<size_t>(glyphs.size(), UINT32_MAX));
        s.stats.skipped_glyphs += count;
        s.unplaceable += count;
        return;
    }
    float color[4] = {};
    if (options.color) {
        for (int c = 0; c < 4; ++c) {
            const float v = (*options.color)[static_cast<size_t>(c)];
            color[c] = v == v ? std::clamp(v, 0.0f, 1.0f) : 0.0f;
            if (c < 3) color[c] = srgb_to_linear(color[c]);
        }
    }
    uint32_t steps = kSubpixelSteps;
    if (options.id != 0) {
        const GlyphInstance& first = glyphs.front();
        if (s.moving(options.id, static_cast<double>(first.pen_x) + dx, static_cast<double>(first.pen_y) + dy)) {
            steps = kMovingSubpixelSteps;
            s.stats.moving_glyphs += static_cast<uint32_t>(std::min<size_t>(glyphs.size(), UINT32_MAX));
        }
    }
    const VkRect2D* visible = options.visible ? &*options.visible : nullptr;
    for (const GlyphInstance& asked : glyphs) {
        GlyphInstance glyph = asked;
        if (!s.moved(glyph, dx, dy)) {
            ++s.stats.skipped_glyphs;
            ++s.unplaceable;
            continue;
        }
        if (options.color) std::copy(std::begin(color), std::end(color), std::begin(glyph.color));
        if (options.depth) glyph.depth = *options.depth;
        s.requests.push_back({glyph, visible != nullptr, visible ? *visible : VkRect2D{}, steps});
        s.request(glyph, visible, steps);
    }
}

// The glyphs this frame draws: those whose texels hold samples once the frame's work has run.
void Renderer::State::collect_drawn() {
    for (Pending& p : pending) {
        DrawnGlyph& d = p.glyph;
        const AtlasEntry* entry = atlas.entry(p.entry);
        d.samples = entry ? entry->samples : 0;
        if (entry && entry->samples < atlas.config().max_samples) converged = false;
        if (d.samples > 0) {
            drawn.push_back(d);
            ++stats.drawn_glyphs;
        } else {
            ++stats.skipped_glyphs;
        }
    }
}

// Frees the buffers, images and font ranges the GPU is done with (frames_in_flight frames old).
void Renderer::State::release_finished(uint64_t this_frame) {
    const auto done = [&](uint64_t retired_at) { return retired_at + frames_in_flight <= this_frame; };
    std::erase_if(retired, [&](Retired& r) {
        if (!done(r.frame)) return false;
        free_buffer(r.buffer);
        return true;
    });
    std::erase_if(retired_images, [&](RetiredImage& r) {
        if (!done(r.frame)) return false;
        r.image.reset();
        return true;
    });
    std::erase_if(retired_ranges, [&](const RetiredRanges& r) {
        if (!done(r.frame)) return false;
        give_range(pages[r.page].used_points, r.points.offset, r.points.size);
        give_range(pages[r.page].used_bands, r.bands.offset, r.bands.size);
        return true;
    });
}

// Copies every font added since the last frame from its staging buffer into its page; the staging
// buffer is retired. True when something was copied.
bool Renderer::State::record_font_uploads(VkCommandBuffer command_buffer, uint64_t this_frame) {
    bool uploaded = false;
    for (GpuFont& font : fonts) {
        if (font.uploaded || !font.font) continue;
        undo.uploaded_fonts.push_back(static_cast<uint32_t>(&font - fonts.data()));
        const FontPage& page = pages[font.page];
        if (font.points_bytes) {
            const VkBufferCopy copy{0, font.points_at, font.points_bytes};
            fn.vkCmdCopyBuffer(command_buffer, font.staging.buffer, page.points.buffer, 1, &copy);
        }
        if (font.bands_bytes) {
            const VkBufferCopy copy{font.points_bytes, font.bands_at, font.bands_bytes};
            fn.vkCmdCopyBuffer(command_buffer, font.staging.buffer, page.bands.buffer, 1, &copy);
        }
        stats.upload_bytes += font.points_bytes + font.bands_bytes;
        font.uploaded = true;
        font.retired_staging = font.staging.buffer;
        retired.push_back({std::move(font.staging), this_frame});
        uploaded = true;
    }
    return uploaded;
}

// The atlas image at the atlas's size (grown where the atlas grew) and in GENERAL.
Status Renderer::State::prepare_atlas_image(VkCommandBuffer command_buffer, uint64_t this_frame) {
    undo.grew_image = false;
    if (atlas.config().width != image_width || atlas.config().height != image_height) {
        if (Status grown = grow_image(command_buffer, this_frame); !grown) return grown;
    }
    if (!atlas_initialized) {
        vk::image_barrier(fn, command_buffer, atlas_image.image, VK_IMAGE_LAYOUT_UNDEFINED, VK_IMAGE_LAYOUT_GENERAL,
                          VK_PIPELINE_STAGE_TOP_OF_PIPE_BIT, 0, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT,
                          vk::kShaderAccess);
        atlas_initialized = true;
    }
    return {};
}

// The rasterizer's work items for `work` into item_data; returns the workgroups they take.
uint32_t Renderer::State::build_work_items(std::span<const RasterWork> work) {
    item_data.clear();
    workgroup_items.clear();
    uint32_t workgroups = 0;
    for (const RasterWork& w : work) {
        const auto slot = font_slot.find(w.key.font);
        if (slot == font_slot.end() || w.sample_count == 0) continue;
        const GpuFont& font = fonts[slot->second];
        const GlyphRecord& glyph = font.font->asset().glyphs[w.key.glyph];
        const GlyphRect rect = glyph_rect(glyph, w.key);
        const TexelToEm map = texel_to_em(rect, w.key);
        gpu::RasterItem item{};
        item.atlas_x = w.x;
        item.atlas_y = w.y;
        item.width = w.width;
        item.height = w.height;
        item.offset_x = map.offset_x;
        item.offset_y = map.offset_y;
        item.scale_x = map.scale_x;
        item.scale_y = map.scale_y;
        item.bbox_min_y = glyph.bbox_min_y;
        item.bbox_max_y = glyph.bbox_max_y;
        item.point_offset = static_cast<uint32_t>(font.points_at / sizeof(Point)) + glyph.point_offset;
        item.band_offset = static_cast<uint32_t>(font.bands_at / sizeof(uint32_t)) + glyph.band_offset;
        item.band_count = glyph.band_count;
        item.band_words = glyph.band_words;
        item.font = font.page;
        item.first_sample = w.first_sample;
        item.sample_count = w.sample_count;
        item.part_x = w.part_x;
        item.part_y = w.part_y;
        item.first_texel = w.first_texel;
        item.texel_count = w.texel_count;
        item.first_workgroup = workgroups;
        const uint32_t own = (w.texel_count + gpu::kRasterWorkgroupSize - 1) / gpu::kRasterWorkgroupSize;
        workgroups += own;
        workgroup_items.insert(workgroup_items.end(), own, static_cast<uint32_t>(item_data.size()));
        item_data.push_back(item);
    }
    stats.work_items = static_cast<uint32_t>(item_data.size());
    stats.workgroups = workgroups;
    stats.samples = atlas.stats().frame.samples;
    stats.curve_tests = atlas.stats().frame.curve_tests;
    return workgroups;
}

// The work list into the items buffer: written into this frame's staging buffer (the frame that
// last used it is done: the caller waits for frame N - frames_in_flight before recording frame N)
// and copied. vkCmdUpdateBuffer, which carries the bytes in the command buffer, took 0.1-0.2 ms
// of every frame on an H200 for the 1.1 MB of a new 4K screen; with the copy, a frame whose shader
// does nothing takes 0.03 ms (docs/results/h200-row-kernel.md). A barrier first keeps last frame's reads before the
// copy, one after makes it (and the fonts' copies) visible to the rasterizer.
void Renderer::State::record_item_upload(VkCommandBuffer command_buffer, uint64_t this_frame, bool fonts_uploaded) {
    if (!item_data.empty()) {
        vk::memory_barrier(fn, command_buffer, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_TRANSFER_BIT,
                           VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_TRANSFER_WRITE_BIT, VK_PIPELINE_STAGE_TRANSFER_BIT,
                           VK_ACCESS_TRANSFER_WRITE_BIT);
        // Items are parts of disjoint atlas entries: make_item_buffers() sized both for every atlas texel.
        assert(item_data.size() <= item_capacity && workgroup_items.size() <= workgroup_capacity);
        const GpuBuffer& staging = item_staging[this_frame % frames_in_flight];
        const VkDeviceSize item_bytes = item_data.size() * sizeof(gpu::RasterItem);
        const VkDeviceSize table_bytes = workgroup_items.size() * sizeof(uint32_t);
        auto* bytes = static_cast<std::byte*>(staging.mapped);
        std::memcpy(bytes, item_data.data(), item_bytes);
        std::memcpy(bytes + table_offset, workgroup_items.data(), table_bytes);
        const VkBufferCopy copies[2] = {{0, 0, item_bytes}, {table_offset, table_offset, table_bytes}};
        fn.vkCmdCopyBuffer(command_buffer, staging.buffer, items.buffer, 2, copies);
        stats.upload_bytes += item_bytes + table_bytes;
    }
    if (fonts_uploaded || !item_data.empty()) {
        vk::memory_barrier(fn, command_buffer, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_WRITE_BIT,
                           VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_ACCESS_SHADER_READ_BIT);
    }
}

// The rasterizer's dispatch over `workgroups`, between barriers against last frame's readers of
// the atlas (composite shaders, copies) and for this frame's.
void Renderer::State::record_raster_dispatch(VkCommandBuffer command_buffer, uint64_t this_frame, uint32_t workgroups) {
    constexpr VkPipelineStageFlags kReaders =
        VK_PIPELINE_STAGE_FRAGMENT_SHADER_BIT | VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_TRANSFER_BIT;
    vk::memory_barrier(fn, command_buffer, kReaders, VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_TRANSFER_READ_BIT,
                       VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, vk::kShaderAccess);
    const VkDescriptorSet set = descriptors.sets[this_frame % frames_in_flight];
    write_descriptors(set);
    fn.vkCmdBindPipeline(command_buffer, VK_PIPELINE_BIND_POINT_COMPUTE, pipeline);
    fn.vkCmdBindDescriptorSets(command_buffer, VK_PIPELINE_BIND_POINT_COMPUTE, descriptors.pipeline_layout, 0, 1, &set,
                               0, nullptr);
    gpu::RasterPushConstants push{};
    for (size_t c = 0; c < 3; ++c) {
        const SampleRect& r = layout.channels[c];
        push.channel_rects[c] = {r.x0, r.y0, r.x1, r.y1};
    }
    push.item_count = static_cast<uint32_t>(item_data.size());
    push.workgroup_count = workgroups;
    push.shared_rows = shared_row_roots && shares_sample_rows(layout) ? 1u : 0u;
    push.sample_kind = sample_kind == SampleKind::points ? gpu::kRasterSamplePoints : gpu::kRasterSampleRows;
    fn.vkCmdPushConstants(command_buffer, descriptors.pipeline_layout, VK_SHADER_STAGE_COMPUTE_BIT, 0, sizeof push,
                          &push);
    const uint32_t width = std::min(workgroups, gpu::kRasterDispatchWidth);
    const uint32_t height = (workgroups + gpu::kRasterDispatchWidth - 1) / gpu::kRasterDispatchWidth;
    fn.vkCmdDispatch(command_buffer, width, height, 1);
    vk::memory_barrier(fn, command_buffer, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_ACCESS_SHADER_WRITE_BIT, kReaders,
                       VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_TRANSFER_READ_BIT);
}

Status Renderer::record(VkCommandBuffer command_buffer) {
    State& s = *state_;
    s.settle_requests();
    const std::span<const RasterWork> work = s.atlas.schedule();
    s.collect_drawn();

    s.undo.recorded = true;
    s.undo.atlas_was_initialized = s.atlas_initialized;
    s.undo.uploaded_fonts.clear();
    const uint64_t frame = s.frame++;
    s.release_finished(frame);
    const bool fonts_uploaded = s.record_font_uploads(command_buffer, frame);
    if (Status prepared = s.prepare_atlas_image(command_buffer, frame); !prepared) return prepared;
    const uint32_t workgroups = s.build_work_items(work);
    s.record_item_upload(command_buffer, frame, fonts_uploaded);
    if (!s.item_data.empty()) s.record_raster_dispatch(command_buffer, frame, workgroups);
    return {};
}

void Renderer::record_atlas_readback(VkCommandBuffer command_buffer, VkBuffer buffer) const {
    const State& s = *state_;
    const vk::Functions& fn = s.fn;
    const VkImage image = s.atlas_image.image;
    vk::image_barrier(fn, command_buffer, image,
                      s.atlas_initialized ? VK_IMAGE_LAYOUT_GENERAL : VK_IMAGE_LAYOUT_UNDEFINED,
                      VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT,
                      VK_ACCESS_SHADER_WRITE_BIT, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_READ_BIT);
    VkBufferImageCopy copy{};
    copy.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
    copy.imageExtent = {s.atlas.config().width, s.atlas.config().height, 1};
    fn.vkCmdCopyImageToBuffer(command_buffer, image, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, buffer, 1, &copy);
    vk::image_barrier(fn, command_buffer, image, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, VK_IMAGE_LAYOUT_GENERAL,
                      VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_READ_BIT, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT,
                      vk::kShaderAccess);
    vk::memory_barrier(fn, command_buffer, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_WRITE_BIT,
                       VK_PIPELINE_STAGE_HOST_BIT, VK_ACCESS_HOST_READ_BIT);
}

std::span<const DrawnGlyph> Renderer::drawn() const {
    return state_->drawn;
}
DrawnFrame Renderer::drawn_frame() const {
    return DrawnFrame{drawn(), atlas_view()};
}
bool Renderer::converged() const {
    return state_->converged;
}
const RendererStats& Renderer::stats() const {
    return state_->stats;
}
const std::vector<ShaderStatistic>& Renderer::shader_statistics() const {
    return state_->shader_statistics;
}
DeviceMemoryUse Renderer::device_memory() const {
    const State& s = *state_;
    DeviceMemoryUse use{s.arena->block_count(), s.arena->block_bytes()};
    for (const vk::DeviceImage* image : {&s.atlas_image}) {
        use.allocations += image->memory != VK_NULL_HANDLE ? 1 : 0;
        use.bytes += image->memory_size;
    }
    for (const State::RetiredImage& r : s.retired_images) {
        ++use.allocations;
        use.bytes += r.image.memory_size;
    }
    return use;
}
const GlyphAtlas& Renderer::atlas() const {
    return state_->atlas;
}
VkImage Renderer::atlas_image() const {
    return state_->atlas_image.image;
}
VkImageView Renderer::atlas_view() const {
    return state_->atlas_image.view;
}

}  // namespace crisp
