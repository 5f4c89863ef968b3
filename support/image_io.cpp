#include "image_io.hpp"

#include "core/file_io.hpp"
#include "core/limits.hpp"

#include <png.h>

#include <bit>
#include <cmath>
#include <csetjmp>
#include <cstdio>
#include <cstring>
#include <memory>
#include <new>
#include <string>
#include <string_view>

namespace crisp {

namespace {

Status check_image(uint32_t width, uint32_t height, uint32_t channels, size_t floats) {
    if (width == 0 || height == 0 || width > kMaxImageDimension || height > kMaxImageDimension) {
        return Error{ErrorCode::invalid_argument, "image size " + std::to_string(width) + "x" + std::to_string(height) +
                                                      " is outside 1.." + std::to_string(kMaxImageDimension)};
    }
    const size_t expected = size_t{width} * height * channels;
    if (floats != expected) {
        return Error{ErrorCode::invalid_argument, "image of " + std::to_string(width) + "x" + std::to_string(height) +
                                                      "x" + std::to_string(channels) + " needs " +
                                                      std::to_string(expected) + " floats, got " +
                                                      std::to_string(floats)};
    }
    return {};
}

// ---- PNG

struct PngSink {
    std::vector<std::byte>* bytes = nullptr;
    bool out_of_memory = false;
};

struct PngErrorText {
    char text[256] = {};
};

void png_write_bytes(png_structp png, png_bytep data, size_t length) {
    auto* sink = static_cast<PngSink*>(png_get_io_ptr(png));
    if (sink->out_of_memory) return;
    // An exception must not unwind through libpng (C code): remember the failure instead.
    try {
        const auto* first = reinterpret_cast<const std::byte*>(data);
        sink->bytes->insert(sink->bytes->end(), first, first + length);
    } catch (const std::bad_alloc&) {
        sink->out_of_memory = true;
    }
}

void png_flush_bytes(png_structp) {}

[[noreturn]] void png_on_error(png_structp png, png_const_charp message) {
    auto* error = static_cast<PngErrorText*>(png_get_error_ptr(png));
    std::snprintf(error->text, sizeof error->text, "%s", message);
    png_longjmp(png, 1);
}

void png_on_warning(png_structp, png_const_charp) {}

// libpng reports errors by longjmp to these. Only trivially destructible objects live in their
// frames and in libpng's, so jumping over them skips no destructor.
bool png_begin(png_structp png, png_infop info, uint32_t width, uint32_t height, int color_type) {
    if (setjmp(png_jmpbuf(png))) return false;
    png_set_IHDR(png, info, width, height, 8, color_type, PNG_INTERLACE_NONE, PNG_COMPRESSION_TYPE_DEFAULT,
                 PNG_FILTER_TYPE_DEFAULT);
    png_set_sRGB_gAMA_and_cHRM(png, info, PNG_sRGB_INTENT_PERCEPTUAL);
    png_write_info(png, info);
    return true;
}

bool png_rows(png_structp png, png_bytepp rows, uint32_t count) {
    if (setjmp(png_jmpbuf(png))) return false;
    png_write_rows(png, rows, count);
    return true;
}

bool png_end(png_structp png, png_infop info) {
    if (setjmp(png_jmpbuf(png))) return false;
    png_write_end(png, info);
    return true;
}

uint8_t unit_to_byte(double value) {
    if (!(value > 0.0)) return 0;  // NaN too
    if (value >= 1.0) return 255;
    return static_cast<uint8_t>(std::lround(value * 255.0));
}

// ---- PFM

void append_text(std::vector<std::byte>& out, std::string_view text) {
    for (const char c : text) out.push_back(static_cast<std::byte>(c));
}

void append_float_le(std::vector<std::byte>& out, float value) {
    const auto bits = std::bit_cast<uint32_t>(value);
    for (int shift = 0; shift < 32; shift += 8) out.push_back(static_cast<std::byte>((bits >> shift) & 0xFFu));
}

float read_float(const std::byte* p, bool little_endian) {
    uint32_t bits = 0;
    for (int i = 0; i < 4; ++i) {
        const auto byte = static_cast<uint32_t>(p[little_endian ? i : 3 - i]);
        bits |= byte << (8 * i);
    }
    return std::bit_cast<float>(bits);
}

bool is_pfm_space(std::byte b) {
    const auto c = static_cast<char>(b);
    return c == ' ' || c == '\t' || c == '\n' || c == '\r' || c == '\v' || c == '\f';
}

// A header field: skips whitespace, then takes non-whitespace bytes (at most 64).
bool next_field(std::span<const std::byte> bytes, size_t& at, std::string& field) {
    while (at < bytes.size() && is_pfm_space(bytes[at])) ++at;
    field.clear();
    while (at < bytes.size() && !is_pfm_space(bytes[at])) {
        if (field.size() >= 64) return false;
        field += static_cast<char>(bytes[at++]);
    }
    return !field.empty();
}

bool parse_dimension(const std::string& field, uint32_t& value) {
    if (field.empty() || field.size() > 9) return false;
    uint32_t v = 0;
    for (const char c : field) {
        if (c < '0' || c > '9') return false;
        v = v * 10 + static_cast<uint32_t>(c - '0');
    }
    value = v;
    return true;
}

Error pfm_error(const std::string& message) {
    return Error{ErrorCode::invalid_argument, "not a valid PFM image: " + message};
}

}  // namespace

double linear_to_srgb(double linear) {
    if (!(linear > 0.0)) return 0.0;
    if (linear >= 1.0) return 1.0;
    if (linear <= 0.0031308) return 12.92 * linear;
    return 1.055 * std::pow(linear, 1.0 / 2.4) - 0.055;
}

uint8_t linear_to_srgb8(float linear) {
    return unit_to_byte(linear_to_srgb(static_cast<double>(linear)));
}

struct PngRowEncoder::State {
    uint32_t width = 0;
    uint32_t height = 0;
    uint32_t channels = 0;
    uint32_t rows_done = 0;
    bool failed = false;
    std::vector<std::byte> bytes;
    PngSink sink{&bytes};
    PngErrorText error;
    png_structp png = nullptr;
    png_infop info = nullptr;
    std::vector<png_byte> texels;  // the rows of one add_rows() call, encoded
    std::vector<png_bytep> rows;

    ~State() {
        if (png != nullptr) png_destroy_write_struct(&png, info != nullptr ? &info : nullptr);
    }
    Error libpng_error() {
        failed = true;
        if (sink.out_of_memory) return Error{ErrorCode::io, "libpng: out of memory while encoding"};
        return Error{ErrorCode::io, std::string("libpng: ") + error.text};
    }
};

PngRowEncoder::PngRowEncoder(std::unique_ptr<State> state) : state_(std::move(state)) {}
PngRowEncoder::PngRowEncoder(PngRowEncoder&&) noexcept = default;
PngRowEncoder& PngRowEncoder::operator=(PngRowEncoder&&) noexcept = default;
PngRowEncoder::~PngRowEncoder() = default;

Result<PngRowEncoder> PngRowEncoder::create(uint32_t width, uint32_t height, uint32_t channels) {
    if (channels != 3 && channels != 4) {
        return Error{ErrorCode::invalid_argument, "a PNG needs 3 or 4 channels, not " + std::to_string(channels)};
    }
    if (Status status = check_image(width, height, channels, size_t{width} * height * channels); !status)
        return status.error();
    auto state = std::make_unique<State>();
    state->width = width;
    state->height = height;
    state->channels = channels;
    state->png = png_create_write_struct(PNG_LIBPNG_VER_STRING, &state->error, png_on_error, png_on_warning);
    if (state->png == nullptr) return Error{ErrorCode::io, "libpng: cannot create a PNG writer"};
    state->info = png_create_info_struct(state->png);
    if (state->info == nullptr) return Error{ErrorCode::io, "libpng: cannot create a PNG writer"};
    png_set_write_fn(state->png, &state->sink, png_write_bytes, png_flush_bytes);
    if (!png_begin(state->png, state->info, width, height,
                   channels == 4 ? PNG_COLOR_TYPE_RGB_ALPHA : PNG_COLOR_TYPE_RGB)) {
        return state->libpng_error();
    }
    return PngRowEncoder(std::move(state));
}

Status PngRowEncoder::add_rows(std::span<const float> pixels) {
    State& s = *state_;
    if (s.failed) return Error{ErrorCode::invalid_argument, "the PNG encoder failed before"};
    const size_t row_floats = size_t{s.width} * s.channels;
    if (pixels.size() % row_floats != 0 || pixels.size() / row_floats > s.height - s.rows_done) {
        return Error{ErrorCode::invalid_argument, std::to_string(pixels.size()) + " floats are not whole rows of " +
                                                      std::to_string(row_floats) + " within the " +
                                                      std::to_string(s.height - s.rows_done) + " rows left"};
    }
    const auto count = static_cast<uint32_t>(pixels.size() / row_floats);
    if (count == 0) return {};
    s.texels.resize(pixels.size());
    for (size_t i = 0; i < pixels.size(); ++i) {
        const bool alpha = s.channels == 4 && i % 4 == 3;
        s.texels[i] = alpha ? unit_to_byte(static_cast<double>(pixels[i])) : linear_to_srgb8(pixels[i]);
    }
    s.rows.resize(count);
    for (size_t y = 0; y < count; ++y) s.rows[y] = s.texels.data() + y * row_floats;
    if (!png_rows(s.png, s.rows.data(), count) || s.sink.out_of_memory) return s.libpng_error();
    s.rows_done += count;
    return {};
}

Result<std::vector<std::byte>> PngRowEncoder::finish() {
    State& s = *state_;
    if (s.failed) return Error{ErrorCode::invalid_argument, "the PNG encoder failed before"};
    if (s.rows_done != s.height) {
        return Error{ErrorCode::invalid_argument,
                     "the PNG has " + std::to_string(s.rows_done) + " of its " + std::to_string(s.height) + " rows"};
    }
    if (!png_end(s.png, s.info) || s.sink.out_of_memory) return s.libpng_error();
    s.failed = true;  // finished: nothing more to add
    return std::move(s.bytes);
}

Result<std::vector<std::byte>> encode_png_srgb8(uint32_t width, uint32_t height, uint32_t channels,
                                                std::span<const float> pixels) {
    if (channels != 3 && channels != 4) {
        return Error{ErrorCode::invalid_argument, "a PNG needs 3 or 4 channels, not " + std::to_string(channels)};
    }
    if (Status status = check_image(width, height, channels, pixels.size()); !status) return status.error();
    Result<PngRowEncoder> encoder = PngRowEncoder::create(width, height, channels);
    if (!encoder) return encoder.error();
    if (Status status = encoder->add_rows(pixels); !status) return status.error();
    return encoder->finish();
}

Status write_png_srgb8(const std::filesystem::path& path, uint32_t width, uint32_t height, uint32_t channels,
                       std::span<const float> pixels) {
    Result<std::vector<std::byte>> bytes = encode_png_srgb8(width, height, channels, pixels);
    if (!bytes) return Error{bytes.error().code, path.string() + ": " + bytes.error().message};
    return write_file_atomically(path, *bytes);
}

std::string pfm_header(uint32_t width, uint32_t height) {
    return "PF\n" + std::to_string(width) + " " + std::to_string(height) + "\n-1.0\n";
}

void append_pfm_rows(std::vector<std::byte>& out, uint32_t width, std::span<const float> rgb) {
    const size_t row_floats = size_t{width} * 3;
    if (row_floats == 0) return;
    out.reserve(out.size() + rgb.size() * 4);
    for (size_t row = rgb.size() / row_floats; row-- > 0;) {
        for (const float value : rgb.subspan(row * row_floats, row_floats)) append_float_le(out, value);
    }
}

Result<std::vector<std::byte>> encode_pfm(uint32_t width, uint32_t height, std::span<const float> rgb) {
    if (Status status = check_image(width, height, 3, rgb.size()); !status) return status.error();
    std::vector<std::byte> bytes;
    append_text(bytes, pfm_header(width, height));
    append_pfm_rows(bytes, width, rgb);
    return bytes;
}

Status write_pfm(const std::filesystem::path& path, uint32_t width, uint32_t height, std::span<const float> rgb) {
    Result<std::vector<std::byte>> bytes = encode_pfm(width, height, rgb);
    if (!bytes) return Error{bytes.error().code, path.string() + ": " + bytes.error().message};
    return write_file_atomically(path, *bytes);
}

Result<PfmImage> parse_pfm(std::span<const std::byte> bytes) {
    size_t at = 0;
    std::string field;
    if (!next_field(bytes, at, field) || (field != "PF" && field != "Pf")) {
        return pfm_error("it does not start with PF or Pf");
    }
    const uint32_t channels = field == "PF" ? 3 : 1;
    PfmImage image;
    if (!next_field(bytes, at, field) || !parse_dimension(field, image.width)) return pfm_error("bad width");
    if (!next_field(bytes, at, field) || !parse_dimension(field, image.height)) return pfm_error("bad height");
    if (image.width == 0 || image.height == 0 || image.width > kMaxImageDimension ||
        image.height > kMaxImageDimension) {
        return pfm_error("size " + std::to_string(image.width) + "x" + std::to_string(image.height) +
                         " is outside 1.." + std::to_string(kMaxImageDimension));
    }
    if (!next_field(bytes, at, field)) return pfm_error("no scale");
    char* end = nullptr;
    const double scale = std::strtod(field.c_str(), &end);
    if (end != field.c_str() + field.size() || !std::isfinite(scale) || scale == 0.0) {
        return pfm_error("bad scale '" + field + "'");
    }
    if (at >= bytes.size()) return pfm_error("the header has no end");
    ++at;  // the single whitespace character that ends the header
    const bool little_endian = scale < 0.0;

    const size_t pixels = size_t{image.width} * image.height;
    const size_t data_bytes = pixels * channels * 4;
    if (bytes.size() - at != data_bytes) {
        return pfm_error("a " + std::to_string(image.width) + "x" + std::to_string(image.height) + " image holds " +
                         std::to_string(data_bytes) + " bytes of data, the file " + std::to_string(bytes.size() - at));
    }
    image.rgb.resize(pixels * 3);
    const std::byte* data = bytes.data() + at;
    for (size_t file_row = 0; file_row < image.height; ++file_row) {
        const size_t row = image.height - 1 - file_row;  // the file's first row is the bottom one
        for (size_t x = 0; x < image.width; ++x) {
            float* out = &image.rgb[(row * image.width + x) * 3];
            const std::byte* in = data + (file_row * image.width + x) * channels * 4;
            for (uint32_t c = 0; c < 3; ++c) out[c] = read_float(in + (channels == 3 ? c : 0) * 4, little_endian);
        }
    }
    return image;
}

Result<PfmImage> read_pfm(const std::filesystem::path& path) {
    Result<std::vector<std::byte>> bytes = read_file(path, limits::kImageFileBytes);
    if (!bytes) return bytes.error();
    Result<PfmImage> image = parse_pfm(*bytes);
    if (!image) return Error{image.error().code, path.string() + ": " + image.error().message};
    return image;
}

}  // namespace crisp
