#include "export.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace crisp::editor {
namespace {

constexpr std::string_view kFormNames[] = {"fontconfig", "freetype"};
constexpr const char* kChannelNames[] = {"red", "green", "blue"};
// How far from a third a stripe's edge may be and still be fontconfig's stripe: half an edit step.
constexpr float kThirdTolerance = 1.0f / 192.0f;

// One axis of the layout: each rectangle's span along it (x for side by side, y for stacked).
struct Span {
    float lo = 0.0f, hi = 0.0f;
    float centre() const { return (lo + hi) * 0.5f; }
};

std::array<Span, 3> spans(const SubpixelLayout& layout, bool along_x) {
    std::array<Span, 3> out;
    for (size_t c = 0; c < 3; ++c) {
        const SampleRect& r = layout.channels[c];
        out[c] = along_x ? Span{r.x0, r.x1} : Span{r.y0, r.y1};
    }
    return out;
}

// Channels are stripes along an axis when their centres differ along it, no two overlap along it
// by half the narrower one or more, and across it they share some rows (or columns).
bool stripes(const SubpixelLayout& layout, bool along_x) {
    const std::array<Span, 3> along = spans(layout, along_x);
    const std::array<Span, 3> across = spans(layout, !along_x);
    for (size_t a = 0; a < 3; ++a) {
        for (size_t b = a + 1; b < 3; ++b) {
            if (along[a].centre() == along[b].centre()) return false;
            const float overlap = std::min(along[a].hi, along[b].hi) - std::max(along[a].lo, along[b].lo);
            const float narrower = std::min(along[a].hi - along[a].lo, along[b].hi - along[b].lo);
            if (overlap >= narrower * 0.5f) return false;
        }
    }
    float shared_lo = across[0].lo, shared_hi = across[0].hi;
    for (const Span& span : across) {
        shared_lo = std::max(shared_lo, span.lo);
        shared_hi = std::min(shared_hi, span.hi);
    }
    return shared_lo < shared_hi;
}

// The channels' order along the axis, first to last, as "red, blue, green".
std::array<int, 3> order(const SubpixelLayout& layout, bool along_x) {
    const std::array<Span, 3> along = spans(layout, along_x);
    std::array<int, 3> channels = {0, 1, 2};
    std::sort(channels.begin(), channels.end(), [&](int a, int b) {
        return along[static_cast<size_t>(a)].centre() < along[static_cast<size_t>(b)].centre();
    });
    return channels;
}

// What fontconfig's stripe constants mean, and the layout may differ from: three stripes of a
// third each across the whole pixel.
void note_stripe_shape(const SubpixelLayout& layout, bool along_x, const std::array<int, 3>& channels,
                       std::vector<std::string>& notes) {
    const std::array<Span, 3> along = spans(layout, along_x);
    const std::array<Span, 3> across = spans(layout, !along_x);
    bool thirds = true, whole = true;
    for (size_t i = 0; i < 3; ++i) {
        const Span& span = along[static_cast<size_t>(channels[i])];
        thirds = thirds && std::fabs(span.lo - static_cast<float>(i) / 3.0f) <= kThirdTolerance &&
                 std::fabs(span.hi - static_cast<float>(i + 1) / 3.0f) <= kThirdTolerance;
        whole = whole && across[i].lo == 0.0f && across[i].hi == 1.0f;
    }
    const char* stripe = along_x ? "width" : "height";
    const char* length = along_x ? "height" : "width";
    if (!thirds) {
        notes.push_back(std::string("the stripes' ") + stripe + "s and positions are not expressed: fontconfig's " +
                        "constant means three equal stripes of a third of a pixel");
    }
    if (!whole) {
        notes.push_back(std::string("per-channel ") + length + "s and offsets are not expressed: fontconfig's " +
                        "constant means stripes the whole " + length + " of the pixel");
    }
}

void note_contrast(const SubpixelLayout& layout, const char* why, std::vector<std::string>& notes) {
    if (!layout.contrast) return;
    const TextContrast& contrast = *layout.contrast;
    char values[160];
    std::snprintf(values, sizeof values, "mode %s, gamma %g, contrast %g, stem darkening %g",
                  contrast.mode == ContrastMode::linear ? "linear" : "corrected", static_cast<double>(contrast.gamma),
                  static_cast<double>(contrast.contrast), static_cast<double>(contrast.stem_darkening));
    notes.push_back(std::string("the contrast settings (") + values + ") are not expressed: " + why);
}

// A layout's name as comment text: a file's name is anything, and "--" would end an XML comment,
// "*/" a C one.
std::string comment_safe(std::string_view name) {
    std::string out;
    for (const char c : name.substr(0, 64)) {
        const bool word = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '.' ||
                          c == '_' || c == ' ';
        const bool single_dash = c == '-' && (out.empty() || out.back() != '-');
        out += word || single_dash ? c : '_';
    }
    return out.empty() ? std::string("(unnamed)") : out;
}

// The notes go into the comments as they are: they are the editor's own sentences, with no "--"
// or "*/" and no part of a file's name.
std::string fontconfig_text(const SubpixelLayout& layout, const std::string& rgba,
                            const std::vector<std::string>& notes) {
    std::string out =
        "<?xml version=\"1.0\"?>\n<!DOCTYPE fontconfig SYSTEM \"urn:fontconfig:fonts.dtd\">\n<fontconfig>\n";
    out += "  <!-- crisp subpixel layout \"" + comment_safe(layout.name) + "\", exported by crisp-layout-editor -->\n";
    for (const std::string& note : notes) out += "  <!-- Not expressed: " + note + " -->\n";
    out += "  <match target=\"font\">\n";
    out += "    <edit name=\"rgba\" mode=\"assign\"><const>" + rgba + "</const></edit>\n";
    const char* filter = rgba == "none" ? "lcdnone" : "lcddefault";
    out += std::string("    <edit name=\"lcdfilter\" mode=\"assign\"><const>") + filter + "</const></edit>\n";
    out += "  </match>\n</fontconfig>\n";
    return out;
}

std::string freetype_text(const SubpixelLayout& layout, const std::array<std::array<long, 2>, 3>& positions,
                          const std::vector<std::string>& notes) {
    std::string out =
        "/* crisp subpixel layout \"" + comment_safe(layout.name) +
        "\", exported by crisp-layout-editor: the red, green and blue\n"
        "   sample positions for FT_Library_SetLcdGeometry, in 1/64 pixel from the pixel centre, y up. */\n";
    for (const std::string& note : notes) out += "/* Not expressed: " + note + " */\n";
    char line[128];
    std::snprintf(line, sizeof line, "FT_Vector sub[3] = {{%ld, %ld}, {%ld, %ld}, {%ld, %ld}};\n", positions[0][0],
                  positions[0][1], positions[1][0], positions[1][1], positions[2][0], positions[2][1]);
    return out + line;
}

}  // namespace

std::span<const std::string_view> export_form_names() {
    return kFormNames;
}

std::optional<ExportForm> export_form(std::string_view name) {
    if (name == kFormNames[0]) return ExportForm::fontconfig;
    if (name == kFormNames[1]) return ExportForm::freetype;
    return std::nullopt;
}

std::string fontconfig_rgba(const SubpixelLayout& layout, std::vector<std::string>& notes) {
    const auto& c = layout.channels;
    if (c[0] == c[1] && c[1] == c[2]) return "none";
    for (const bool along_x : {true, false}) {
        if (!stripes(layout, along_x)) continue;
        const std::array<int, 3> channels = order(layout, along_x);
        const std::string prefix = along_x ? "" : "v";
        if (channels == std::array<int, 3>{0, 1, 2} || channels == std::array<int, 3>{2, 1, 0}) {
            note_stripe_shape(layout, along_x, channels, notes);
            return prefix + (channels[0] == 0 ? "rgb" : "bgr");
        }
        notes.push_back(std::string("the channels run ") + kChannelNames[channels[0]] + ", " +
                        kChannelNames[channels[1]] + ", " + kChannelNames[channels[2]] +
                        (along_x ? " left to right" : " top to bottom") + ": fontconfig's rgba has only " + prefix +
                        "rgb and " + prefix + "bgr, so none (grayscale anti-aliasing) avoids wrongly coloured fringes");
        return "none";
    }
    notes.push_back(
        "the channels are neither side by side nor stacked (a triangle or other two-dimensional arrangement, as "
        "qd-oled and pentile): fontconfig's rgba cannot express it, so none (grayscale anti-aliasing) avoids wrongly "
        "coloured fringes");
    return "none";
}

std::array<std::array<long, 2>, 3> freetype_lcd_geometry(const SubpixelLayout& layout) {
    std::array<std::array<long, 2>, 3> positions{};
    for (size_t c = 0; c < 3; ++c) {
        const SampleRect& r = layout.channels[c];
        const float x = (r.x0 + r.x1) * 0.5f - 0.5f;
        const float y = 0.5f - (r.y0 + r.y1) * 0.5f;
        positions[c] = {std::lround(x * 64.0f), std::lround(y * 64.0f)};
    }
    return positions;
}

Exported export_layout(const SubpixelLayout& layout, ExportForm form) {
    Exported out;
    if (form == ExportForm::fontconfig) {
        const std::string rgba = fontconfig_rgba(layout, out.notes);
        note_contrast(layout, "fontconfig has no such settings", out.notes);
        out.text = fontconfig_text(layout, rgba, out.notes);
        return out;
    }
    const std::array<std::array<long, 2>, 3> positions = freetype_lcd_geometry(layout);
    bool whole_pixels = true;
    for (const SampleRect& r : layout.channels)
        whole_pixels = whole_pixels && r.x1 - r.x0 == 1.0f && r.y1 - r.y0 == 1.0f;
    if (!whole_pixels) {
        out.notes.push_back(
            "the rectangles' sizes are not expressed: FreeType's Harmony rendering covers a whole pixel for each "
            "channel, moved to its position");
    }
    note_contrast(layout, "FreeType renders coverage, and how it is blended is its user's", out.notes);
    out.text = freetype_text(layout, positions, out.notes);
    return out;
}

}  // namespace crisp::editor
