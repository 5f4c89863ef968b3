#include "report.hpp"

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string_view>

namespace engine {
namespace {

const char* format_name(VkFormat format) {
    switch (format) {
        case VK_FORMAT_B8G8R8A8_SRGB:
            return "B8G8R8A8_SRGB";
        case VK_FORMAT_R8G8B8A8_SRGB:
            return "R8G8B8A8_SRGB";
        case VK_FORMAT_A8B8G8R8_SRGB_PACK32:
            return "A8B8G8R8_SRGB_PACK32";
        default:
            return "other";
    }
}

// Box names are the example's own ASCII constants: no escaping is needed.
void write_box(std::ostream& out, const TextBox& box) {
    out << "    {\"name\": \"" << box.name << "\", \"x\": " << box.x << ", \"y\": " << box.y
        << ", \"width\": " << box.width << ", \"height\": " << box.height;
    if (box.name.rfind("label:", 0) == 0) {
        out << ", \"hovered\": " << (box.hovered ? "true" : "false") << ", \"anchor\": [" << box.anchor_x << ", "
            << box.anchor_y << "]";
    }
    if (box.name == "spinner") out << ", \"angle\": " << box.angle;
    if (box.name == "sign") {
        out << ", \"quad\": [";
        for (size_t i = 0; i < box.quad.size(); ++i)
            out << (i ? ", [" : "[") << box.quad[i][0] << ", " << box.quad[i][1] << "]";
        out << "]";
    }
    out << "}";
}

// The field's text is UTF-8 the user typed: quotes, backslashes and control characters escaped.
void write_string(std::ostream& out, std::string_view text) {
    out << '"';
    for (const char c : text) {
        const auto byte = static_cast<unsigned char>(c);
        if (c == '"' || c == '\\') {
            out << '\\' << c;
        } else if (byte < 0x20) {
            char escaped[8];
            std::snprintf(escaped, sizeof(escaped), "\\u%04x", byte);
            out << escaped;
        } else {
            out << c;
        }
    }
    out << '"';
}

void write_rect(std::ostream& out, const FieldRect& rect) {
    out << "{\"x\": " << rect.x << ", \"y\": " << rect.y << ", \"width\": " << rect.width
        << ", \"height\": " << rect.height << "}";
}

void write_field(std::ostream& out, const FieldReport& field) {
    const uint32_t begin = std::min(field.anchor, field.caret), end = std::max(field.anchor, field.caret);
    out << "  \"field\": {\n    \"text\": ";
    write_string(out, field.text);
    out << ",\n    \"bytes\": " << field.text.size() << ", \"focused\": " << (field.focused ? "true" : "false")
        << ", \"caret\": " << field.caret << ", \"caret_upstream\": " << (field.caret_upstream ? "true" : "false")
        << ", \"anchor\": " << field.anchor << ", \"selection\": [" << begin << ", " << end
        << "],\n    \"caret_visible\": " << (field.caret_visible ? "true" : "false") << ", \"box\": ";
    write_rect(out, field.box);
    out << ", \"caret_rect\": ";
    write_rect(out, field.caret_rect);
    out << ",\n    \"text_x\": " << field.text_x << ", \"baseline_y\": " << field.baseline_y
        << ", \"selection_rects\": [";
    for (size_t i = 0; i < field.selection_rects.size(); ++i) {
        out << (i ? ", " : "");
        write_rect(out, field.selection_rects[i]);
    }
    out << "]\n  },\n";
}

}  // namespace

crisp::Status write_report(const std::string& path, const RunReport& report, uint32_t validation_messages) {
    std::ostringstream out;
    out << "{\n  \"presented\": " << report.presented << ",\n  \"dropped\": " << report.dropped
        << ",\n  \"out_of_date\": " << report.out_of_date << ",\n  \"recreations\": " << report.recreations
        << ",\n  \"minimized_polls\": " << report.minimized_polls << ",\n  \"resizes\": " << report.resizes
        << ",\n  \"width\": " << report.extent.width << ",\n  \"height\": " << report.extent.height
        << ",\n  \"swapchain_format\": \"" << format_name(report.swapchain_format)
        << "\",\n  \"validation_messages\": " << validation_messages
        << ",\n  \"glyphs\": {\"drawn\": " << report.glyphs.drawn << ", \"moving\": " << report.glyphs.moving
        << ", \"transformed\": " << report.glyphs.transformed << ", \"projective\": " << report.glyphs.projective
        << "},\n";
    write_field(out, report.field);
    out << "  \"text\": [\n";
    for (size_t i = 0; i < report.boxes.size(); ++i) {
        write_box(out, report.boxes[i]);
        out << (i + 1 < report.boxes.size() ? ",\n" : "\n");
    }
    out << "  ]\n}\n";
    const std::string temporary = path + ".partial";
    {
        std::ofstream file(temporary, std::ios::binary);
        file << out.str();
        if (!file.flush()) return crisp::Error{crisp::ErrorCode::io, path + ": cannot write " + temporary};
    }
    std::error_code error;
    std::filesystem::rename(temporary, path, error);
    if (error) return crisp::Error{crisp::ErrorCode::io, path + ": " + error.message()};
    return {};
}

}  // namespace engine
