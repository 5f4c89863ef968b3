// Fuzzes the subpixel layout JSON reader (and with it the JSON parser the scene reader shares).
#include <crisp/subpixel.hpp>

#include <cstdint>
#include <string_view>

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    const std::string_view text(reinterpret_cast<const char*>(data), size);
    auto layout = crisp::parse_subpixel_layout(text);
    if (layout) {
        // What parses must be valid and survive a round trip.
        if (!crisp::validate_subpixel_layout(*layout)) __builtin_trap();
        auto again = crisp::parse_subpixel_layout(crisp::subpixel_layout_to_json(*layout));
        if (!again || !(*again == *layout)) __builtin_trap();
    }
    return 0;
}
