#include "atlas/morton.hpp"

#include <crisp/atlas.hpp>

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <initializer_list>
#include <map>
#include <numeric>
#include <random>
#include <set>
#include <span>
#include <utility>
#include <vector>

namespace crisp {
namespace {

constexpr uint64_t kUnlimited = ~uint64_t{0};

GlyphKey key_of(uint32_t glyph, uint32_t font = 1) {
    GlyphKey key;
    key.font = font;
    key.glyph = glyph;
    key.size_x = key.size_y = 13 * kSizeOne;
    return key;
}

GlyphAtlas make_atlas(AtlasConfig config) {
    Result<GlyphAtlas> atlas = GlyphAtlas::create(config);
    EXPECT_TRUE(atlas.ok()) << (atlas.ok() ? "" : atlas.error().message);
    return std::move(atlas).value();
}

GlyphAtlas make_atlas(uint32_t width, uint32_t height, uint64_t budget = kUnlimited) {
    AtlasConfig config;
    config.width = width;
    config.height = height;
    config.frame_budget = budget;
    return make_atlas(config);
}

// The block a rect should take, in cells, computed here from the rule in the header.
struct Block {
    uint32_t width = 0;
    uint32_t height = 0;
};
Block block_of(uint32_t width, uint32_t height) {
    auto cells = [](uint32_t texels) {
        uint32_t count = 1;
        while (count * kAtlasCellSize < texels) count *= 2;
        return count;
    };
    Block block;
    block.height = std::max(cells(width), cells(height));
    block.width = std::max(cells(width), block.height / 2);
    return block;
}

uint32_t random_below(std::mt19937& rng, uint32_t bound) {
    return static_cast<uint32_t>(rng() % bound);
}

// Samples scheduled for `id` in a work list (0 if absent).
uint32_t samples_for(std::span<const RasterWork> work, uint32_t id) {
    for (const RasterWork& item : work)
        if (item.entry == id) return item.sample_count;
    return 0;
}

TEST(AtlasMorton, RoundTripsAndTransposes) {
    for (uint32_t y = 0; y < 1024; y += 3) {
        for (uint32_t x = 0; x < 1024; ++x) {
            ASSERT_EQ(morton_decode(morton_encode({x, y})), (CellCoord{x, y}));
            ASSERT_EQ(n_order_decode(n_order_encode({x, y})), (CellCoord{x, y}));
        }
    }
    for (uint32_t i = 0; i < (1u << 20); i += 7) {
        ASSERT_EQ(morton_encode(morton_decode(i)), i);
        ASSERT_EQ(n_order_encode(n_order_decode(i)), i);
    }
    // Z-order puts 2k + 1 right of 2k; N-order puts it below.
    EXPECT_EQ(morton_decode(1), (CellCoord{1, 0}));
    for (uint32_t k = 0; k < 50000; ++k) {
        const CellCoord top = n_order_decode(2 * k);
        ASSERT_EQ(n_order_decode(2 * k + 1), (CellCoord{top.x, top.y + 1})) << k;
        ASSERT_EQ(top.y % 2, 0u);
    }
    // An aligned run of 8 is a 2x4 column, of 16 a 4x4 square.
    for (uint32_t run : {8u, 16u}) {
        const uint32_t base = 5 * run;
        const CellCoord origin = n_order_decode(base);
        uint32_t max_x = 0, max_y = 0;
        for (uint32_t i = base; i < base + run; ++i) {
            const CellCoord cell = n_order_decode(i);
            ASSERT_GE(cell.x, origin.x);
            ASSERT_GE(cell.y, origin.y);
            max_x = std::max(max_x, cell.x - origin.x);
            max_y = std::max(max_y, cell.y - origin.y);
        }
        EXPECT_EQ(max_x + 1, run == 8 ? 2u : 4u);
        EXPECT_EQ(max_y + 1, 4u);
    }
}

TEST(Atlas, RejectsInvalidConfigs) {
    auto rejected = [](AtlasConfig config) {
        const Result<GlyphAtlas> atlas = GlyphAtlas::create(config);
        if (atlas.ok()) return false;
        EXPECT_EQ(atlas.error().code, ErrorCode::invalid_argument);
        EXPECT_FALSE(atlas.error().message.empty());
        return true;
    };
    for (uint32_t size : {0u, 1u, 8u, 15u, 17u, 48u, 100u, 2047u, 32768u, 0x80000000u}) {
        AtlasConfig wide;
        wide.width = size;
        EXPECT_TRUE(rejected(wide)) << size;
        AtlasConfig tall;
        tall.height = size;
        EXPECT_TRUE(rejected(tall)) << size;
    }
    AtlasConfig config;
    config.max_samples = 0;
    EXPECT_TRUE(rejected(config));
    config.max_samples = kAtlasMaxSamples + 1;
    EXPECT_TRUE(rejected(config));
    config = {};
    config.steady = 0;
    EXPECT_TRUE(rejected(config));
    config.steady = config.max_samples + 1;
    EXPECT_TRUE(rejected(config));
    config = {};
    config.ramp = {8, 0, 2};
    EXPECT_TRUE(rejected(config));
    config.ramp = {config.max_samples + 1};
    EXPECT_TRUE(rejected(config));
    config = {};
    config.frame_budget = 0;
    EXPECT_TRUE(rejected(config));

    for (auto [width, height] : {std::pair{16u, 16u}, {16384u, 16u}, {64u, 4096u}, {16384u, 16384u}}) {
        config = {};
        config.width = width;
        config.height = height;
        const Result<GlyphAtlas> atlas = GlyphAtlas::create(config);
        ASSERT_TRUE(atlas.ok()) << width << "x" << height;
        EXPECT_EQ(atlas->stats().usable_cells, (width / 16) * (height / 16));
        EXPECT_EQ(atlas->stats().used_cells, 0u);
    }
    config = {};
    config.ramp = {};
    EXPECT_TRUE(GlyphAtlas::create(config).ok());
}

TEST(Atlas, BlockShapes) {
    GlyphAtlas atlas = make_atlas(2048, 2048);
    struct Case {
        uint32_t width, height, block_width, block_height;
    };
    const Case cases[] = {
        {1, 1, 16, 16},   {16, 16, 16, 16},  {17, 16, 32, 32},         {10, 30, 16, 32},
        {30, 10, 32, 32}, {25, 29, 32, 32},  {17, 40, 32, 64},         {40, 17, 64, 64},
        {16, 33, 32, 64}, {5, 100, 64, 128}, {2048, 2048, 2048, 2048},
    };
    uint32_t glyph = 0;
    for (const Case& c : cases) {
        atlas.begin_frame();
        const AtlasLookup lookup = atlas.acquire(key_of(glyph++), c.width, c.height, 1);
        ASSERT_EQ(lookup.status, AtlasStatus::placed) << c.width << "x" << c.height;
        const AtlasEntry* entry = atlas.entry(lookup.entry);
        ASSERT_NE(entry, nullptr);
        EXPECT_EQ(entry->block_width, c.block_width) << c.width << "x" << c.height;
        EXPECT_EQ(entry->block_height, c.block_height) << c.width << "x" << c.height;
        EXPECT_EQ(entry->width, c.width);
        EXPECT_EQ(entry->height, c.height);
        EXPECT_EQ(lookup.x % c.block_width, 0u);
        EXPECT_EQ(lookup.y % c.block_height, 0u);
        // What atlas_block() promises for sizing an atlas ahead is what the atlas takes.
        const AtlasBlock block = atlas_block(c.width, c.height);
        EXPECT_EQ(block.cells_x * kAtlasCellSize, c.block_width) << c.width << "x" << c.height;
        EXPECT_EQ(block.cells_y * kAtlasCellSize, c.block_height) << c.width << "x" << c.height;
        // Start each case from an empty atlas: the last case needs all of it.
        atlas = make_atlas(2048, 2048);
    }
}

TEST(Atlas, BlockOfAnySizeIsDefined) {
    EXPECT_EQ(atlas_block(0, 0).cells_x, 1u);
    EXPECT_EQ(atlas_block(0, 0).cells_y, 1u);
    const AtlasBlock huge = atlas_block(UINT32_MAX, 1);  // (2^32 - 1) / 16 rounds up to 2^28 cells
    EXPECT_EQ(huge.cells_x, 1u << 28);
    EXPECT_EQ(huge.cells_y, 1u << 28);
}

TEST(Atlas, TallGlyphsShareASquareSideBySide) {
    GlyphAtlas atlas = make_atlas(256, 256);
    const AtlasLookup l = atlas.acquire(key_of('l'), 10, 30, 1);
    const AtlasLookup one = atlas.acquire(key_of('1'), 9, 28, 1);
    const AtlasLookup j = atlas.acquire(key_of('j'), 8, 31, 1);
    ASSERT_EQ(l.status, AtlasStatus::placed);
    ASSERT_EQ(one.status, AtlasStatus::placed);
    ASSERT_EQ(j.status, AtlasStatus::placed);
    // Two columns of 1x2 cells fill the first 2x2 square, the next starts the second square.
    EXPECT_EQ(std::pair(l.x, l.y), std::pair(0u, 0u));
    EXPECT_EQ(std::pair(one.x, one.y), std::pair(16u, 0u));
    EXPECT_EQ(std::pair(j.x, j.y), std::pair(0u, 32u));
    EXPECT_EQ(atlas.stats().used_cells, 6u);
}

TEST(Atlas, EmptyRectNeedsNoCells) {
    GlyphAtlas atlas = make_atlas(256, 256);
    for (auto [width, height] : {std::pair{0u, 0u}, {0u, 12u}, {12u, 0u}}) {
        const AtlasLookup lookup = atlas.acquire(key_of(' '), width, height, 0);
        EXPECT_EQ(lookup.status, AtlasStatus::empty);
        EXPECT_EQ(lookup.entry, kNoAtlasEntry);
    }
    const AtlasStats stats = atlas.stats();
    EXPECT_EQ(stats.used_cells, 0u);
    EXPECT_EQ(stats.resident_glyphs, 0u);
    EXPECT_EQ(stats.total.allocations, 0u);
    EXPECT_TRUE(atlas.schedule().empty());
}

TEST(Atlas, HitsReturnTheSameEntry) {
    GlyphAtlas atlas = make_atlas(256, 256);
    const AtlasLookup first = atlas.acquire(key_of('e'), 12, 14, 100);
    const AtlasLookup again = atlas.acquire(key_of('e'), 12, 14, 100);
    EXPECT_EQ(first.entry, again.entry);
    EXPECT_EQ(std::pair(first.x, first.y), std::pair(again.x, again.y));
    atlas.begin_frame();
    const AtlasLookup later = atlas.acquire(key_of('e'), 12, 14, 100);
    EXPECT_EQ(first.entry, later.entry);
    const AtlasStats stats = atlas.stats();
    EXPECT_EQ(stats.total.allocations, 1u);
    EXPECT_EQ(stats.total.hits, 2u);
    EXPECT_EQ(stats.pinned_glyphs, 1u);
    EXPECT_EQ(atlas.find(key_of('e')), first.entry);
    EXPECT_EQ(atlas.find(key_of('f')), kNoAtlasEntry);
    EXPECT_EQ(atlas.entry(kNoAtlasEntry), nullptr);
    EXPECT_EQ(atlas.entry(12345), nullptr);
}

TEST(Atlas, TooLargeIsReportedAndNeverAllocated) {
    GlyphAtlas atlas = make_atlas(256, 256);
    EXPECT_EQ(atlas.acquire(key_of(1), 257, 10, 1).status, AtlasStatus::too_large);
    EXPECT_EQ(atlas.acquire(key_of(2), 10, 257, 1).status, AtlasStatus::too_large);
    EXPECT_EQ(atlas.acquire(key_of(3), 0xFFFFFFFFu, 0xFFFFFFFFu, 1).status, AtlasStatus::too_large);
    // 100 x 200 rounds to 8 x 16 cells: a 1:2 column exactly as tall as the atlas.
    EXPECT_EQ(atlas.acquire(key_of(4), 100, 200, 1).status, AtlasStatus::placed);
    // 100 x 300 rounds to 8 x 32 cells, taller than the atlas.
    EXPECT_EQ(atlas.acquire(key_of(5), 100, 300, 1).status, AtlasStatus::too_large);
    AtlasStats stats = atlas.stats();
    EXPECT_EQ(stats.frame.failed_too_large, 4u);
    EXPECT_EQ(stats.total.failed_too_large, 4u);
    EXPECT_EQ(stats.resident_glyphs, 1u);
    EXPECT_EQ(atlas.find(key_of(1)), kNoAtlasEntry);

    // The whole atlas is the largest block.
    atlas.begin_frame();
    EXPECT_EQ(atlas.acquire(key_of(6), 256, 256, 1).status, AtlasStatus::placed);
    stats = atlas.stats();
    EXPECT_EQ(stats.frame.failed_too_large, 0u);
    EXPECT_EQ(stats.total.failed_too_large, 4u);
    EXPECT_EQ(stats.used_cells, stats.usable_cells);

    // Blocks are never wider than tall: in a wide atlas, the height limits the glyph.
    GlyphAtlas wide = make_atlas(512, 128);
    EXPECT_EQ(wide.acquire(key_of(7), 200, 100, 1).status, AtlasStatus::too_large);
    EXPECT_EQ(wide.acquire(key_of(8), 128, 128, 1).status, AtlasStatus::placed);
    GlyphAtlas strip = make_atlas(512, 16);
    EXPECT_EQ(strip.acquire(key_of('l'), 10, 30, 1).status, AtlasStatus::too_large);
    EXPECT_EQ(strip.acquire(key_of('o'), 14, 14, 1).status, AtlasStatus::placed);
}

TEST(Atlas, NonSquareAtlasFillsExactlyItsCells) {
    for (auto [width, height] : {std::pair{256u, 64u}, {64u, 256u}, {1024u, 16u}, {16u, 1024u}}) {
        GlyphAtlas atlas = make_atlas(width, height);
        const uint32_t usable = (width / 16) * (height / 16);
        std::vector<uint8_t> taken(usable, 0);
        for (uint32_t i = 0; i < usable; ++i) {
            const AtlasLookup lookup = atlas.acquire(key_of(i), 16, 16, 1);
            ASSERT_EQ(lookup.status, AtlasStatus::placed) << width << "x" << height << " glyph " << i;
            ASSERT_LT(lookup.x, width);
            ASSERT_LT(lookup.y, height);
            uint8_t& cell = taken[(lookup.y / 16) * (width / 16) + lookup.x / 16];
            ASSERT_EQ(cell, 0) << "cell given twice";
            cell = 1;
        }
        EXPECT_EQ(atlas.acquire(key_of(usable), 16, 16, 1).status, AtlasStatus::atlas_full);
        EXPECT_FLOAT_EQ(atlas.stats().occupancy, 1.0f);
    }
}

TEST(Atlas, EvictsLeastRecentlyUsedAndNeverPinned) {
    GlyphAtlas atlas = make_atlas(64, 64);  // 16 cells
    std::vector<AtlasLookup> first(16);
    for (uint32_t i = 0; i < 16; ++i) first[i] = atlas.acquire(key_of(i), 16, 16, 1);
    atlas.begin_frame();
    atlas.acquire(key_of(0), 16, 16, 1);
    atlas.acquire(key_of(1), 16, 16, 1);
    atlas.begin_frame();
    atlas.acquire(key_of(2), 16, 16, 1);  // pinned now, so 3 is the least recently used

    const AtlasLookup n0 = atlas.acquire(key_of(100), 16, 16, 1);
    ASSERT_EQ(n0.status, AtlasStatus::placed);
    EXPECT_EQ(atlas.find(key_of(3)), kNoAtlasEntry);
    EXPECT_EQ(std::pair(n0.x, n0.y), std::pair(first[3].x, first[3].y));  // freed cells are reused
    const AtlasLookup n1 = atlas.acquire(key_of(101), 16, 16, 1);
    ASSERT_EQ(n1.status, AtlasStatus::placed);
    EXPECT_EQ(atlas.find(key_of(4)), kNoAtlasEntry);
    EXPECT_NE(atlas.find(key_of(5)), kNoAtlasEntry);
    EXPECT_EQ(atlas.stats().frame.evictions, 2u);

    // 12 more evict 5..15 (last used in frame 0), then 0 (frame 1, acquired before 1).
    for (uint32_t i = 2; i < 14; ++i) ASSERT_EQ(atlas.acquire(key_of(100 + i), 16, 16, 1).status, AtlasStatus::placed);
    for (uint32_t i = 3; i < 16; ++i) EXPECT_EQ(atlas.find(key_of(i)), kNoAtlasEntry) << i;
    EXPECT_EQ(atlas.find(key_of(0)), kNoAtlasEntry);
    EXPECT_NE(atlas.find(key_of(1)), kNoAtlasEntry);
    EXPECT_NE(atlas.find(key_of(2)), kNoAtlasEntry);
    ASSERT_EQ(atlas.acquire(key_of(114), 16, 16, 1).status, AtlasStatus::placed);
    EXPECT_EQ(atlas.find(key_of(1)), kNoAtlasEntry);

    // Everything is pinned now: the next one fails and no pinned glyph moves.
    EXPECT_EQ(atlas.acquire(key_of(115), 16, 16, 1).status, AtlasStatus::atlas_full);
    EXPECT_EQ(std::pair(atlas.entry(atlas.find(key_of(2)))->x, atlas.entry(atlas.find(key_of(2)))->y),
              std::pair(first[2].x, first[2].y));
    for (uint32_t i = 0; i < 15; ++i) EXPECT_NE(atlas.find(key_of(100 + i)), kNoAtlasEntry) << i;
    EXPECT_EQ(atlas.stats().frame.evictions, 15u);
    EXPECT_EQ(atlas.stats().total.evictions, 15u);
}

TEST(Atlas, FullAtlasFailsGracefully) {
    GlyphAtlas atlas = make_atlas(128, 128);  // 64 cells
    std::vector<AtlasLookup> placed;
    uint32_t failed = 0;
    for (uint32_t i = 0; i < 80; ++i) {
        const AtlasLookup lookup = atlas.acquire(key_of(i), 16, 16, 10);
        if (lookup.status == AtlasStatus::placed)
            placed.push_back(lookup);
        else {
            EXPECT_EQ(lookup.status, AtlasStatus::atlas_full);
            ++failed;
        }
    }
    EXPECT_EQ(placed.size(), 64u);
    EXPECT_EQ(failed, 16u);
    EXPECT_EQ(atlas.stats().frame.failed_full, 16u);
    const std::span<const RasterWork> work = atlas.schedule();
    EXPECT_EQ(work.size(), 64u);
    for (const AtlasLookup& lookup : placed) {
        const AtlasEntry* entry = atlas.entry(lookup.entry);
        ASSERT_NE(entry, nullptr);
        EXPECT_EQ(std::pair(entry->x, entry->y), std::pair(lookup.x, lookup.y));
        EXPECT_EQ(entry->samples, 8u);
    }

    // Next frame the failed glyphs get room from the glyphs no longer drawn.
    atlas.begin_frame();
    for (uint32_t i = 64; i < 80; ++i) EXPECT_EQ(atlas.acquire(key_of(i), 16, 16, 10).status, AtlasStatus::placed);
    EXPECT_EQ(atlas.stats().frame.failed_full, 0u);
    EXPECT_EQ(atlas.stats().total.failed_full, 16u);
    EXPECT_EQ(atlas.stats().frame.evictions, 16u);

    // One pinned glyph blocks a glyph needing the whole atlas: it fails without evicting anyone.
    atlas.begin_frame();
    atlas.acquire(key_of(70), 16, 16, 10);
    EXPECT_EQ(atlas.acquire(key_of(1000), 128, 128, 10).status, AtlasStatus::atlas_full);
    EXPECT_EQ(atlas.stats().frame.evictions, 0u);
    EXPECT_EQ(atlas.stats().resident_glyphs, 64u);
    // Without it, every other glyph is evicted to make room.
    atlas.begin_frame();
    EXPECT_EQ(atlas.acquire(key_of(1000), 128, 128, 10).status, AtlasStatus::placed);
    EXPECT_EQ(atlas.stats().frame.evictions, 64u);
    EXPECT_EQ(atlas.stats().resident_glyphs, 1u);
}

// A pool of glyphs of random sizes, drawn in random subsets over many frames, checked after each
// acquire against a reference built here: cells of resident blocks never overlap and stay inside
// the atlas, blocks are aligned and of the right shape, a new glyph takes the first free block in
// N-order when there is one, else evicts exactly the least recently used unpinned glyphs, and
// fails only when the pinned glyphs leave no block.
class AtlasRandomized : public testing::TestWithParam<std::pair<uint32_t, uint32_t>> {};

TEST_P(AtlasRandomized, NeverOverlapsAndEvictsLeastRecentlyUsed) {
    const uint32_t atlas_width = GetParam().first, atlas_height = GetParam().second;
    const uint32_t cells_x = atlas_width / 16, cells_y = atlas_height / 16;
    GlyphAtlas atlas = make_atlas(atlas_width, atlas_height, 5000);
    std::mt19937 rng(1234 + atlas_width);

    struct Glyph {
        uint32_t width = 0, height = 0;
        bool resident = false;
        uint64_t last_frame = 0, last_order = 0;  // reference LRU rank
    };
    std::vector<Glyph> pool(500);
    for (Glyph& glyph : pool) {
        const uint32_t kind = random_below(rng, 100);
        const uint32_t limit = kind < 70 ? 16 : kind < 90 ? 64 : kind < 98 ? 200 : 600;
        glyph.width = 1 + random_below(rng, limit);
        glyph.height = 1 + random_below(rng, limit);
    }

    // Returns the grid of cells owned by resident entries (1) or pinned ones (2), checking the
    // entries on the way.
    auto build_grid = [&](std::vector<uint8_t>& grid) {
        grid.assign(size_t{cells_x} * cells_y, 0);
        uint32_t used = 0;
        for (uint32_t id = 0; id < atlas.entry_capacity(); ++id) {
            const AtlasEntry* entry = atlas.entry(id);
            if (!entry) continue;
            const Block block = block_of(entry->width, entry->height);
            EXPECT_EQ(entry->block_width, block.width * 16);
            EXPECT_EQ(entry->block_height, block.height * 16);
            EXPECT_EQ(entry->x % entry->block_width, 0u);
            EXPECT_EQ(entry->y % entry->block_height, 0u);
            EXPECT_LE(entry->x + entry->block_width, atlas_width);
            EXPECT_LE(entry->y + entry->block_height, atlas_height);
            EXPECT_EQ(atlas.find(entry->key), id);
            const bool pinned = entry->last_used_frame == atlas.frame();
            for (uint32_t y = entry->y / 16; y < (entry->y + entry->block_height) / 16 && y < cells_y; ++y) {
                for (uint32_t x = entry->x / 16; x < (entry->x + entry->block_width) / 16 && x < cells_x; ++x) {
                    uint8_t& cell = grid[size_t{y} * cells_x + x];
                    EXPECT_EQ(cell, 0) << "cell " << x << "," << y << " owned twice";
                    cell = pinned ? 2 : 1;
                    ++used;
                }
            }
        }
        EXPECT_EQ(atlas.stats().used_cells, used);
    };
    // The lowest N-order index of an aligned block whose cells are all below `level`, or none.
    auto first_block = [&](const std::vector<uint8_t>& grid, Block block, uint8_t level) {
        uint32_t best = kNoAtlasEntry;
        for (uint32_t y = 0; y + block.height <= cells_y; y += block.height) {
            for (uint32_t x = 0; x + block.width <= cells_x; x += block.width) {
                bool free = true;
                for (uint32_t v = y; v < y + block.height && free; ++v)
                    for (uint32_t u = x; u < x + block.width && free; ++u) free = grid[size_t{v} * cells_x + u] < level;
                if (free) best = std::min(best, n_order_encode({x, y}));
            }
        }
        return best;
    };

    std::vector<uint8_t> grid;
    uint64_t order = 0;
    uint64_t full = 0, too_large = 0;
    for (uint32_t frame = 0; frame < 300; ++frame) {
        atlas.begin_frame();
        std::vector<std::pair<uint32_t, uint32_t>> placed;  // (glyph, entry) acquired this frame
        const uint32_t count = 5 + random_below(rng, 40);
        for (uint32_t n = 0; n < count; ++n) {
            const uint32_t index = random_below(rng, 500);
            Glyph& glyph = pool[index];
            const GlyphKey key = key_of(index);
            const bool was_resident = atlas.find(key) != kNoAtlasEntry;
            ASSERT_EQ(was_resident, glyph.resident);
            const Block block = block_of(glyph.width, glyph.height);
            const bool fits = block.width <= cells_x && block.height <= cells_y;
            uint32_t expect_free = kNoAtlasEntry, expect_unpinned = kNoAtlasEntry;
            if (!was_resident && fits) {
                build_grid(grid);
                expect_free = first_block(grid, block, 1);
                expect_unpinned = first_block(grid, block, 2);
            }
            const uint64_t evictions_before = atlas.stats().total.evictions;

            const AtlasLookup lookup = atlas.acquire(key, glyph.width, glyph.height, 1 + glyph.width * glyph.height);
            const uint64_t evictions = atlas.stats().total.evictions - evictions_before;

            if (!fits) {
                ASSERT_EQ(lookup.status, AtlasStatus::too_large);
                ++too_large;
                continue;
            }
            if (was_resident) {
                ASSERT_EQ(lookup.status, AtlasStatus::placed);
                ASSERT_EQ(evictions, 0u);
            } else if (expect_free != kNoAtlasEntry) {
                ASSERT_EQ(lookup.status, AtlasStatus::placed);
                ASSERT_EQ(evictions, 0u);
                ASSERT_EQ(n_order_encode({lookup.x / 16, lookup.y / 16}), expect_free);
            } else if (expect_unpinned != kNoAtlasEntry) {
                ASSERT_EQ(lookup.status, AtlasStatus::placed);
                ASSERT_GT(evictions, 0u);
            } else {
                ASSERT_EQ(lookup.status, AtlasStatus::atlas_full);
                ASSERT_EQ(evictions, 0u);
                ++full;
                continue;
            }

            // The evicted glyphs are the `evictions` least recently used unpinned ones.
            std::vector<std::pair<std::pair<uint64_t, uint64_t>, uint32_t>> unpinned;
            for (uint32_t i = 0; i < pool.size(); ++i)
                if (pool[i].resident && pool[i].last_frame != atlas.frame() && i != index)
                    unpinned.push_back({{pool[i].last_frame, pool[i].last_order}, i});
            std::sort(unpinned.begin(), unpinned.end());
            ASSERT_LE(evictions, unpinned.size());
            for (size_t k = 0; k < unpinned.size(); ++k) {
                const uint32_t i = unpinned[k].second;
                const bool expect_evicted = k < evictions;
                ASSERT_EQ(atlas.find(key_of(i)) == kNoAtlasEntry, expect_evicted) << "glyph " << i;
                if (expect_evicted) pool[i].resident = false;
            }
            if (glyph.last_frame != atlas.frame() || !glyph.resident) glyph.last_order = order++;
            glyph.resident = true;
            glyph.last_frame = atlas.frame();
            placed.push_back({index, lookup.entry});
        }
        build_grid(grid);
        const std::span<const RasterWork> work = atlas.schedule();
        uint64_t tests = 0;
        for (const RasterWork& item : work) {
            const AtlasEntry* entry = atlas.entry(item.entry);
            ASSERT_NE(entry, nullptr);
            const uint64_t cost = 1 + uint64_t{entry->width} * entry->height;
            const uint64_t texels = uint64_t{item.width} * item.height;
            if (item.texel_count == texels)
                EXPECT_EQ(item.curve_tests, item.sample_count * cost);
            else  // a piece of a split sample
                EXPECT_EQ(item.curve_tests, item.texel_count * ((cost + texels - 1) / texels));
            EXPECT_LE(uint64_t{item.first_texel} + item.texel_count, texels);
            tests += item.curve_tests;
        }
        if (atlas.stats().frame.budget_overruns == 0)
            EXPECT_LE(tests, 5000u);
        else
            EXPECT_EQ(work.size(), 1u);
        // Pinned glyphs were never moved or evicted during the frame.
        for (auto [index, id] : placed) {
            const AtlasEntry* entry = atlas.entry(id);
            ASSERT_NE(entry, nullptr);
            ASSERT_EQ(entry->key, key_of(index));
        }
    }
    const AtlasStats stats = atlas.stats();
    EXPECT_GT(stats.total.evictions, 100u);  // the test exercised eviction
    EXPECT_EQ(stats.total.failed_full, full);
    EXPECT_EQ(stats.total.failed_too_large, too_large);
    EXPECT_GT(stats.occupancy, 0.5f);
}

INSTANTIATE_TEST_SUITE_P(Sizes, AtlasRandomized,
                         testing::Values(std::pair{512u, 512u}, std::pair{1024u, 256u}, std::pair{128u, 512u},
                                         std::pair{256u, 256u}));

TEST(AtlasSchedule, RampThenSteadyStopsAtMax) {
    GlyphAtlas atlas = make_atlas(256, 256);
    std::vector<uint32_t> per_frame;
    uint32_t expected_first = 0;
    for (uint32_t frame = 0; frame < 600; ++frame) {
        atlas.begin_frame();
        const AtlasLookup lookup = atlas.acquire(key_of('a'), 12, 14, 200);
        const std::span<const RasterWork> work = atlas.schedule();
        if (work.empty()) {
            per_frame.push_back(0);
            continue;
        }
        ASSERT_EQ(work.size(), 1u);
        EXPECT_EQ(work[0].entry, lookup.entry);
        EXPECT_EQ(work[0].key, key_of('a'));
        EXPECT_EQ(std::pair(work[0].x, work[0].y), std::pair(lookup.x, lookup.y));
        EXPECT_EQ(std::pair(work[0].width, work[0].height), std::pair(12u, 14u));
        EXPECT_EQ(work[0].first_sample, expected_first);  // indices continue across frames
        expected_first += work[0].sample_count;
        per_frame.push_back(work[0].sample_count);
        EXPECT_EQ(atlas.stats().frame.curve_tests, uint64_t{work[0].sample_count} * 200);
    }
    EXPECT_EQ(per_frame[0], 8u);
    EXPECT_EQ(per_frame[1], 4u);
    EXPECT_EQ(per_frame[2], 2u);
    for (size_t i = 3; i < 501; ++i) ASSERT_EQ(per_frame[i], 1u) << i;
    for (size_t i = 501; i < per_frame.size(); ++i) ASSERT_EQ(per_frame[i], 0u) << i;
    EXPECT_EQ(atlas.entry(atlas.find(key_of('a')))->samples, 512u);
    EXPECT_EQ(atlas.stats().total.samples, 512u);
    EXPECT_EQ(atlas.stats().refining_glyphs, 0u);
}

TEST(AtlasSchedule, ConfiguredRampClampsAtMax) {
    AtlasConfig config;
    config.ramp = {16, 8};
    config.steady = 3;
    config.max_samples = 100;
    GlyphAtlas atlas = make_atlas(config);
    std::vector<uint32_t> per_frame;
    for (uint32_t frame = 0; frame < 40; ++frame) {
        atlas.begin_frame();
        atlas.acquire(key_of('a'), 12, 14, 1);
        const std::span<const RasterWork> work = atlas.schedule();
        per_frame.push_back(work.empty() ? 0 : work[0].sample_count);
    }
    // 16 + 8 + 25 * 3 = 99, then the last 1.
    EXPECT_EQ(per_frame[0], 16u);
    EXPECT_EQ(per_frame[1], 8u);
    for (size_t i = 2; i < 27; ++i) EXPECT_EQ(per_frame[i], 3u) << i;
    EXPECT_EQ(per_frame[27], 1u);
    EXPECT_EQ(per_frame[28], 0u);
}

TEST(AtlasSchedule, OnlyPinnedGlyphsGetSamples) {
    GlyphAtlas atlas = make_atlas(256, 256);
    const uint32_t id = atlas.acquire(key_of('a'), 12, 14, 1).entry;
    EXPECT_EQ(samples_for(atlas.schedule(), id), 8u);
    atlas.begin_frame();
    atlas.acquire(key_of('b'), 12, 14, 1);
    EXPECT_EQ(samples_for(atlas.schedule(), id), 0u);
    atlas.begin_frame();
    atlas.acquire(key_of('a'), 12, 14, 1);
    EXPECT_EQ(samples_for(atlas.schedule(), id), 4u);
    EXPECT_EQ(atlas.entry(id)->samples, 12u);
}

TEST(AtlasSchedule, ScheduleOncePerFrame) {
    GlyphAtlas atlas = make_atlas(256, 256);
    const uint32_t a = atlas.acquire(key_of('a'), 12, 14, 1).entry;
    EXPECT_EQ(atlas.schedule().size(), 1u);
    const uint32_t b = atlas.acquire(key_of('b'), 12, 14, 1).entry;  // after schedule: waits
    const std::span<const RasterWork> again = atlas.schedule();
    ASSERT_EQ(again.size(), 1u);
    EXPECT_EQ(again[0].entry, a);
    EXPECT_EQ(atlas.entry(a)->samples, 8u);
    EXPECT_EQ(atlas.entry(b)->samples, 0u);
    atlas.begin_frame();
    atlas.acquire(key_of('a'), 12, 14, 1);
    atlas.acquire(key_of('b'), 12, 14, 1);
    const std::span<const RasterWork> next = atlas.schedule();
    EXPECT_EQ(samples_for(next, a), 4u);
    EXPECT_EQ(samples_for(next, b), 8u);
}

TEST(AtlasSchedule, InvalidateRestartsTheRamp) {
    GlyphAtlas atlas = make_atlas(256, 256);
    uint32_t id = 0;
    for (int frame = 0; frame < 3; ++frame) {
        atlas.begin_frame();
        id = atlas.acquire(key_of('a'), 12, 14, 1).entry;
        atlas.schedule();
    }
    EXPECT_EQ(atlas.entry(id)->samples, 14u);
    atlas.invalidate_samples();
    EXPECT_EQ(atlas.entry(id)->samples, 0u);
    const uint32_t expected[] = {8, 4, 2, 1};
    uint32_t first = 0;
    for (uint32_t count : expected) {
        atlas.begin_frame();
        EXPECT_EQ(atlas.acquire(key_of('a'), 12, 14, 1).entry, id);
        const std::span<const RasterWork> work = atlas.schedule();
        ASSERT_EQ(work.size(), 1u);
        EXPECT_EQ(work[0].first_sample, first);  // 0 first: the rasterizer clears the rect
        EXPECT_EQ(work[0].sample_count, count);
        first += count;
    }
}

TEST(AtlasSchedule, NewGlyphsFirstAndShortChangedOnesCatchUp) {
    GlyphAtlas atlas = make_atlas(256, 256, 10);  // 10 samples of these glyphs per frame
    const auto frame = [&](std::initializer_list<uint32_t> glyphs) {
        atlas.begin_frame();
        std::vector<uint32_t> ids;
        for (uint32_t glyph : glyphs) ids.push_back(atlas.acquire(key_of(glyph), 12, 14, 1).entry);
        const std::span<const RasterWork> work = atlas.schedule();
        std::vector<uint32_t> counts;
        for (uint32_t id : ids) counts.push_back(samples_for(work, id));
        EXPECT_LE(atlas.stats().frame.curve_tests, 10u);
        return counts;
    };
    // 8 each does not fit: 4 each does (the largest power of two), and 2 to spare buy no more.
    EXPECT_EQ(frame({'a', 'b'}), (std::vector<uint32_t>{4, 4}));
    // The new glyph goes first although acquired last; a is cut short and b waits.
    EXPECT_EQ(frame({'a', 'b', 'c'}), (std::vector<uint32_t>{2, 0, 8}));
    // a wants 14 - 6; b, cut short in its first frame, wants 12 - 4 and gets what is left.
    EXPECT_EQ(frame({'a', 'b', 'c'}), (std::vector<uint32_t>{8, 2, 0}));
    // b's turn comes first now: it wants 14 - 6, then c its 12 - 8 and gets what is left.
    EXPECT_EQ(frame({'a', 'b', 'c'}), (std::vector<uint32_t>{0, 8, 2}));
}

TEST(AtlasSchedule, ZeroCostGlyphsIgnoreTheBudget) {
    GlyphAtlas atlas = make_atlas(256, 256, 10);
    const uint32_t free_glyph = atlas.acquire(key_of('-'), 12, 3, 0).entry;
    const uint32_t paid = atlas.acquire(key_of('a'), 12, 14, 3).entry;
    const std::span<const RasterWork> work = atlas.schedule();
    EXPECT_EQ(samples_for(work, free_glyph), 8u);
    // 3 would fit (9 of 10 curve tests); a new glyph's first frame takes a power of two.
    EXPECT_EQ(samples_for(work, paid), 2u);
    EXPECT_EQ(atlas.stats().frame.curve_tests, 6u);
}

// New text whose first ramp step does not fit the budget shows whole: every new glyph gets the
// largest power of two of samples that fits for all, and those first in acquire order whose full
// step still fits the rest get it.
TEST(AtlasSchedule, NewTextShowsWholeInItsFirstFrameWithAPowerOfTwoOfSamples) {
    constexpr uint64_t kCost = 10;
    for (const uint64_t budget : {uint64_t{800}, uint64_t{500}, uint64_t{270}, uint64_t{45}}) {
        GlyphAtlas atlas = make_atlas(256, 256, budget);
        std::vector<uint32_t> entries;
        for (uint32_t g = 0; g < 10; ++g) entries.push_back(atlas.acquire(key_of('a' + g), 10, 12, kCost).entry);
        const std::span<const RasterWork> work = atlas.schedule();
        std::vector<uint32_t> got;
        for (uint32_t e : entries) got.push_back(samples_for(work, e));
        EXPECT_LE(atlas.stats().frame.curve_tests, budget);
        const std::vector<uint32_t> expected =
            budget == 800   ? std::vector<uint32_t>(10, 8)                          // the whole step fits
            : budget == 500 ? std::vector<uint32_t>{8, 8, 4, 4, 4, 4, 4, 4, 4, 4}   // 4 each, 100 to spare
            : budget == 270 ? std::vector<uint32_t>{8, 2, 2, 2, 2, 2, 2, 2, 2, 2}   // 2 each, 70 to spare
                            : std::vector<uint32_t>{1, 1, 1, 1, 0, 0, 0, 0, 0, 0};  // not one each: strict turns
        EXPECT_EQ(got, expected) << "budget " << budget;
    }
}

TEST(AtlasSchedule, BudgetNeverExceededAndNoGlyphStarves) {
    constexpr uint64_t kBudget = 2000;
    constexpr uint32_t kGlyphs = 100;
    constexpr uint64_t kMaxCost = 200;
    GlyphAtlas atlas = make_atlas(1024, 1024, kBudget);
    std::mt19937 rng(7);
    std::vector<uint64_t> cost(kGlyphs);
    for (uint64_t& c : cost) c = 20 + random_below(rng, kMaxCost - 19);
    const uint64_t cost_sum = std::accumulate(cost.begin(), cost.end(), uint64_t{0});
    std::vector<uint32_t> last_progress(kGlyphs, 0), samples(kGlyphs, 0), served_frames(kGlyphs, 0);
    uint32_t frame = 0, all_started = 0, all_steady = 0, max_gap = 0, max_steady_gap = 0;
    for (; frame < 20000; ++frame) {
        atlas.begin_frame();
        std::map<uint32_t, uint32_t> glyph_of_entry;
        for (uint32_t i = 0; i < kGlyphs; ++i) {
            // A different acquire order each frame must not matter.
            const uint32_t glyph = (i * 37 + frame) % kGlyphs;
            const AtlasLookup lookup = atlas.acquire(key_of(glyph), 20, 20, cost[glyph]);
            ASSERT_EQ(lookup.status, AtlasStatus::placed);
            glyph_of_entry[lookup.entry] = glyph;
        }
        // While the glyphs short of 512 want more than the budget, every frame spends all but
        // less than what the next glyph in turn costs.
        uint64_t demand = 0;
        for (uint32_t i = 0; i < kGlyphs; ++i)
            if (samples[i] < 512) demand += cost[i];
        uint64_t tests = 0;
        for (const RasterWork& item : atlas.schedule()) {
            const uint32_t glyph = glyph_of_entry.at(item.entry);
            ASSERT_EQ(item.first_sample, samples[glyph]);
            ASSERT_GT(item.sample_count, 0u);
            samples[glyph] += item.sample_count;
            tests += item.sample_count * cost[glyph];
            last_progress[glyph] = frame;
            ++served_frames[glyph];
        }
        ASSERT_LE(tests, kBudget) << "frame " << frame;
        ASSERT_EQ(atlas.stats().frame.curve_tests, tests);
        if (demand >= kBudget) {
            ASSERT_GT(tests, kBudget - kMaxCost) << "frame " << frame;
        }
        if (all_started == 0 && std::all_of(samples.begin(), samples.end(), [](uint32_t s) { return s > 0; }))
            all_started = frame;
        // Past the three ramp frames every glyph wants one sample per frame.
        if (all_steady == 0 &&
            std::all_of(served_frames.begin(), served_frames.end(), [](uint32_t n) { return n >= 3; }))
            all_steady = frame;
        for (uint32_t i = 0; i < kGlyphs; ++i) {
            ASSERT_LE(samples[i], 512u);
            if (samples[i] == 512) continue;
            if (all_started) max_gap = std::max(max_gap, frame - std::max(last_progress[i], all_started));
            if (all_steady) max_steady_gap = std::max(max_steady_gap, frame - std::max(last_progress[i], all_steady));
        }
        if (std::all_of(samples.begin(), samples.end(), [](uint32_t s) { return s == 512; })) break;
    }
    EXPECT_LT(frame, 20000u) << "not every glyph reached 512 samples";
    for (uint32_t s : samples) EXPECT_EQ(s, 512u);
    // Each frame spends more than kBudget - kMaxCost, and glyphs take turns: a glyph waits at
    // most one round over the others, which costs each other glyph's share (at most 14 samples
    // while ramping, catch-up included; 1 once steady) times its cost.
    const auto round_frames = [&](uint64_t share) {
        return static_cast<uint32_t>(share * cost_sum / (kBudget - kMaxCost) + 2);
    };
    EXPECT_GT(all_started, 0u);
    EXPECT_GT(all_steady, all_started);
    EXPECT_LE(max_gap, round_frames(14));
    EXPECT_LE(max_steady_gap, round_frames(1));
    EXPECT_EQ(atlas.stats().total.budget_overruns, 0u);
}

TEST(AtlasSchedule, GlyphsDearerThanTheBudgetAreSplitIntoPieces) {
    constexpr uint64_t kBudget = 100;
    GlyphAtlas atlas = make_atlas(256, 256, kBudget);
    // Three 20 x 20 glyphs whose one sample costs 10 to 12 budgets (3 curve tests per texel),
    // and one cheap glyph.
    const uint64_t costs[4] = {1000, 1100, 1200, 10};
    std::vector<uint32_t> samples(4, 0), texels_done(4, 0);
    uint32_t cheap_frames_served = 0;
    for (uint32_t frame = 0; frame < 300; ++frame) {
        atlas.begin_frame();
        std::vector<uint32_t> ids;
        for (uint32_t i = 0; i < 4; ++i) ids.push_back(atlas.acquire(key_of(i), 20, 20, costs[i]).entry);
        uint64_t tests = 0;
        bool cheap_served = false;
        for (const RasterWork& item : atlas.schedule()) {
            const auto i = static_cast<size_t>(std::find(ids.begin(), ids.end(), item.entry) - ids.begin());
            ASSERT_LT(i, 4u);
            ASSERT_EQ(item.first_sample, samples[i]);
            tests += item.curve_tests;
            if (i == 3) {
                EXPECT_EQ(item.texel_count, 400u);
                EXPECT_EQ(item.curve_tests, item.sample_count * costs[3]);
                samples[i] += item.sample_count;
                cheap_served = true;
                continue;
            }
            // A piece of one sample that starts where the last one stopped.
            EXPECT_EQ(item.sample_count, 1u);
            EXPECT_EQ(item.first_texel, texels_done[i]);
            EXPECT_GT(item.texel_count, 0u);
            EXPECT_EQ(item.curve_tests, item.texel_count * ((costs[i] + 399) / 400));
            texels_done[i] += item.texel_count;
            ASSERT_LE(texels_done[i], 400u);
            if (texels_done[i] == 400) {
                texels_done[i] = 0;
                ++samples[i];
            }
        }
        // The budget holds and is spent but for less than a texel's worth or the cheap glyph's.
        EXPECT_LE(tests, kBudget) << "frame " << frame;
        EXPECT_EQ(atlas.stats().frame.curve_tests, tests);
        EXPECT_GT(tests, kBudget - costs[3]) << "frame " << frame;
        for (uint32_t i = 0; i < 4; ++i) EXPECT_EQ(atlas.entry(ids[i])->samples, samples[i]);
        // Split glyphs never take more than half while the cheap one waits: it is served
        // every frame until it is done.
        if (samples[3] < 512 || cheap_served) {
            EXPECT_TRUE(cheap_served) << "frame " << frame;
            ++cheap_frames_served;
        }
    }
    EXPECT_EQ(atlas.stats().total.budget_overruns, 0u);
    EXPECT_EQ(cheap_frames_served, 300u);
    // Every split glyph progresses: 300 frames pay for about 300 * 100 tests, less what the
    // cheap glyph takes; each sample of a split glyph costs 1200 to 1200.
    for (uint32_t i = 0; i < 3; ++i) EXPECT_GE(samples[i], 3u) << "glyph " << i;
    EXPECT_GT(atlas.stats().total.split_pieces, 300u);
}

TEST(AtlasSchedule, ATexelDearerThanTheBudgetIsForcedAlone) {
    AtlasConfig config;
    config.width = config.height = 256;
    config.frame_budget = 2;
    config.max_samples = 4;
    config.ramp = {2};
    GlyphAtlas atlas = make_atlas(config);
    // 3 curve tests per texel of one sample and a budget of 2: the dear glyph can only ever get a
    // texel as an overrun, in a frame it has to itself (once the cheap glyph holds its 4 samples).
    uint32_t dear_texels = 0, alone_frames = 0;
    for (uint32_t frame = 0; frame < 20; ++frame) {
        atlas.begin_frame();
        const uint32_t dear = atlas.acquire(key_of(1), 4, 4, 48).entry;
        const uint32_t cheap = atlas.acquire(key_of(2), 4, 4, 1).entry;
        const std::span<const RasterWork> work = atlas.schedule();
        const uint64_t overruns = atlas.stats().frame.budget_overruns;
        if (samples_for(work, cheap) > 0) {
            EXPECT_EQ(samples_for(work, dear), 0u);
            EXPECT_EQ(overruns, 0u);
            EXPECT_LE(atlas.stats().frame.curve_tests, 2u);
            continue;
        }
        ++alone_frames;
        ASSERT_EQ(work.size(), 1u);
        EXPECT_EQ(work[0].entry, dear);
        EXPECT_EQ(work[0].texel_count, 1u);
        EXPECT_EQ(work[0].first_texel, dear_texels % 16);
        EXPECT_EQ(overruns, 1u);
        ++dear_texels;
        EXPECT_EQ(atlas.entry(dear)->samples, dear_texels / 16);
    }
    EXPECT_GE(alone_frames, 17u);
    EXPECT_EQ(atlas.stats().total.budget_overruns, alone_frames);
    EXPECT_EQ(atlas.entry(atlas.find(key_of(1)))->samples, 1u);  // 16 texels made one whole sample
}

TEST(Atlas, VisiblePartsAreHeldWithAMarginAndReplacedWhenLeft) {
    GlyphAtlas atlas = make_atlas(256, 256);
    // A 2000 x 1000 glyph rect is far too large for the atlas; 100 x 50 of it is visible.
    const TexelRect visible{900, 400, 100, 50};
    AtlasLookup lookup = atlas.acquire(key_of(1), 2000, 1000, 2000000, visible);
    ASSERT_EQ(lookup.status, AtlasStatus::placed);
    EXPECT_EQ(lookup.width, 2000u);
    EXPECT_EQ(lookup.height, 1000u);
    const uint32_t m = kAtlasPartMargin;
    EXPECT_EQ(lookup.part.x, 900 - m);
    EXPECT_EQ(lookup.part.y, 400 - m);
    EXPECT_EQ(lookup.part.width, 100 + 2 * m);
    EXPECT_EQ(lookup.part.height, 50 + 2 * m);
    const AtlasEntry* entry = atlas.entry(lookup.entry);
    ASSERT_NE(entry, nullptr);
    EXPECT_EQ(entry->block_width, 256u);   // the part's block (9 x 6 cells, rounded up); the
    EXPECT_EQ(entry->block_height, 256u);  // rect's would be 2048 x 2048
    // Its cost is the part's share of the rect's: 132 x 82 of 2000 x 1000 texels, rounded up.
    EXPECT_EQ(entry->curve_tests_per_sample, (2000000ull * 132 * 82 + 1999999) / 2000000);
    const std::span<const RasterWork> work = atlas.schedule();
    ASSERT_EQ(work.size(), 1u);
    EXPECT_EQ(work[0].part_x, 900 - m);
    EXPECT_EQ(work[0].part_y, 400 - m);
    EXPECT_EQ(work[0].width, 132u);
    EXPECT_EQ(work[0].texel_count, 132u * 82u);

    // Scrolled within the margin: a hit that keeps the samples.
    atlas.begin_frame();
    lookup = atlas.acquire(key_of(1), 2000, 1000, 0, TexelRect{890, 395, 100, 50});
    EXPECT_EQ(atlas.stats().frame.hits, 1u);
    EXPECT_EQ(atlas.entry(lookup.entry)->samples, 8u);
    // Asked again in the same frame for a part it does not hold: pinned entries never move.
    lookup = atlas.acquire(key_of(1), 2000, 1000, 0, TexelRect{0, 0, 10, 10});
    EXPECT_EQ(lookup.part.x, 900 - m);
    EXPECT_EQ(atlas.stats().frame.parts_replaced, 0u);

    // Next frame, scrolled past the margin: placed anew with the new part and no samples.
    atlas.begin_frame();
    lookup = atlas.acquire(key_of(1), 2000, 1000, 2000000, TexelRect{0, 0, 10, 10});
    ASSERT_EQ(lookup.status, AtlasStatus::placed);
    EXPECT_EQ(lookup.part.x, 0u);
    EXPECT_EQ(lookup.part.width, 10 + m);
    EXPECT_EQ(atlas.entry(lookup.entry)->samples, 0u);
    EXPECT_EQ(atlas.stats().frame.parts_replaced, 1u);
    // The whole rect asked for while a part is held: too large for this atlas, and the part is gone.
    atlas.begin_frame();
    EXPECT_EQ(atlas.acquire(key_of(1), 2000, 1000, 2000000).status, AtlasStatus::too_large);
    EXPECT_EQ(atlas.find(key_of(1)), kNoAtlasEntry);
    // Nothing visible: nothing placed.
    EXPECT_EQ(atlas.acquire(key_of(2), 20, 20, 1, TexelRect{20, 0, 5, 5}).status, AtlasStatus::empty);
    // A visible part within the margin of the rect's edges is the whole rect.
    lookup = atlas.acquire(key_of(3), 20, 20, 1, TexelRect{2, 3, 10, 10});
    EXPECT_EQ(lookup.part.x, 0u);
    EXPECT_EQ(lookup.part.width, 20u);
    EXPECT_EQ(lookup.part.height, 20u);
    EXPECT_EQ(atlas.entry(lookup.entry)->curve_tests_per_sample, 1u);
}

TEST(Atlas, IsAMovableValue) {
    GlyphAtlas atlas = make_atlas(256, 256);
    const uint32_t id = atlas.acquire(key_of('a'), 12, 14, 1).entry;
    GlyphAtlas moved = std::move(atlas);
    EXPECT_EQ(moved.find(key_of('a')), id);
    EXPECT_EQ(moved.schedule().size(), 1u);
    GlyphAtlas copy = moved;
    copy.begin_frame();
    copy.acquire(key_of('b'), 12, 14, 1);
    EXPECT_EQ(copy.stats().resident_glyphs, 2u);
    EXPECT_EQ(moved.stats().resident_glyphs, 1u);
}

// Copy assignment takes the other atlas's whole state (its size too); afterwards neither sees the
// other's changes, and each schedule() is its own.
TEST(Atlas, CopyAssignmentIsDeep) {
    GlyphAtlas atlas = make_atlas(256, 256);
    GlyphAtlas copy = make_atlas(64, 64);
    const uint32_t id = atlas.acquire(key_of('a'), 12, 14, 1).entry;
    copy = atlas;
    EXPECT_EQ(copy.config().width, 256u);
    EXPECT_EQ(copy.find(key_of('a')), id);
    const std::span<const RasterWork> work = copy.schedule();
    ASSERT_EQ(work.size(), 1u);
    EXPECT_GT(copy.entry(id)->samples, 0u);
    EXPECT_EQ(atlas.entry(id)->samples, 0u);
    atlas.begin_frame();
    atlas.acquire(key_of('b'), 12, 14, 1);
    EXPECT_EQ(copy.find(key_of('b')), kNoAtlasEntry);
    EXPECT_EQ(copy.schedule().data(), work.data());
    EXPECT_EQ(copy.frame(), atlas.frame() - 1);
}

TEST(Atlas, StatusNames) {
    EXPECT_STREQ(atlas_status_name(AtlasStatus::placed), "placed");
    EXPECT_STREQ(atlas_status_name(AtlasStatus::empty), "empty");
    EXPECT_STREQ(atlas_status_name(AtlasStatus::atlas_full), "atlas_full");
    EXPECT_STREQ(atlas_status_name(AtlasStatus::too_large), "too_large");
}

// grow() doubles the atlas and keeps every entry where it was; the new three quarters are free
// (square, wide and tiny atlases, whose index spaces have cells outside the atlas).
TEST(Atlas, GrowingKeepsEveryEntryInPlace) {
    for (auto [width, height] : {std::pair{64u, 64u}, {128u, 32u}, {16u, 16u}}) {
        SCOPED_TRACE(std::to_string(width) + "x" + std::to_string(height));
        GlyphAtlas atlas = make_atlas(width, height);
        std::vector<AtlasLookup> placed;
        uint32_t glyph = 0;
        for (;; ++glyph) {
            const AtlasLookup lookup = atlas.acquire(key_of(glyph), 14, 14, 100);  // one cell each
            if (lookup.status != AtlasStatus::placed) {
                EXPECT_EQ(lookup.status, AtlasStatus::atlas_full);
                break;
            }
            placed.push_back(lookup);
        }
        const uint32_t cells = atlas.stats().usable_cells;
        EXPECT_EQ(placed.size(), cells);
        ASSERT_TRUE(atlas.grow());
        EXPECT_EQ(atlas.config().width, 2 * width);
        EXPECT_EQ(atlas.config().height, 2 * height);
        EXPECT_EQ(atlas.stats().usable_cells, 4 * cells);
        EXPECT_EQ(atlas.stats().used_cells, cells);
        EXPECT_EQ(atlas.stats().pinned_cells, cells);  // still pinned this frame
        for (const AtlasLookup& before : placed) {
            const AtlasEntry* entry = atlas.entry(before.entry);
            ASSERT_NE(entry, nullptr);
            EXPECT_EQ(entry->x, before.x);
            EXPECT_EQ(entry->y, before.y);
        }
        // Three times as many again fit, in the new cells only, never overlapping.
        std::set<std::pair<uint32_t, uint32_t>> taken;
        for (const AtlasLookup& p : placed) taken.insert({p.x, p.y});
        for (uint32_t more = 0; more < 3 * cells; ++more) {
            const AtlasLookup lookup = atlas.acquire(key_of(glyph + more), 14, 14, 100);
            ASSERT_EQ(lookup.status, AtlasStatus::placed) << more;
            EXPECT_LT(lookup.x, 2 * width);
            EXPECT_LT(lookup.y, 2 * height);
            EXPECT_TRUE(taken.insert({lookup.x, lookup.y}).second) << "overlap at " << lookup.x << "," << lookup.y;
        }
        EXPECT_EQ(atlas.acquire(key_of(glyph + 3 * cells), 14, 14, 100).status, AtlasStatus::atlas_full);
    }
    GlyphAtlas largest = make_atlas(kAtlasMaxSize, kAtlasMaxSize / 2);
    EXPECT_FALSE(largest.grow());
    EXPECT_EQ(largest.config().width, kAtlasMaxSize);
}

}  // namespace
}  // namespace crisp
