#include <crisp/result.hpp>

namespace crisp {

const char* error_code_name(ErrorCode code) {
    switch (code) {
        case ErrorCode::invalid_argument:
            return "invalid_argument";
        case ErrorCode::io:
            return "io";
        case ErrorCode::font_unreadable:
            return "font_unreadable";
        case ErrorCode::font_unsupported:
            return "font_unsupported";
        case ErrorCode::glyph_failed:
            return "glyph_failed";
        case ErrorCode::asset_invalid:
            return "asset_invalid";
        case ErrorCode::asset_version:
            return "asset_version";
        case ErrorCode::device_lost:
            return "device_lost";
        case ErrorCode::vulkan:
            return "vulkan";
    }
    return "unknown";
}

}  // namespace crisp
