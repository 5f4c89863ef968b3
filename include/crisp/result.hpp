// crisp: error values.
//
// Anything that can fail because of its input (a font file, an asset, a layout file, text, sizes,
// a missing Vulkan feature, a full atlas) returns a Result<T>: either the value, or an Error with
// a code a program can branch on, a message a person can act on and, where a Vulkan call failed,
// the VkResult it returned. No exception crosses the public API; programmer errors (broken
// preconditions) assert.
#pragma once

#include <crisp/export.hpp>

#include <vulkan/vulkan.h>

#include <cassert>
#include <string>
#include <utility>
#include <variant>

namespace crisp {

enum class ErrorCode {
    invalid_argument,  // a parameter is out of its documented range
    io,                // a file could not be opened, read, written or renamed
    font_unreadable,   // the font bytes could not be parsed at all
    font_unsupported,  // the font parsed but crisp cannot use it (no outlines, bitmap only, ...)
    glyph_failed,      // one or more glyphs could not be converted
    asset_invalid,     // an asset failed validation; the message names the fault
    asset_version,     // an asset of a version this build does not read
    vulkan,            // a Vulkan call failed, or a required version, feature or extension is missing
    // A Vulkan call returned VK_ERROR_DEVICE_LOST. Nothing made on the device works again: wait
    // for nothing more, destroy crisp's objects (their destructors only destroy and free, which
    // a lost device allows), then the device, and make new ones (docs/integration.md).
    device_lost,
};

// Short stable name of a code ("asset_invalid"), for logs and JSON.
CRISP_API const char* error_code_name(ErrorCode code);

struct Error {
    ErrorCode code = ErrorCode::invalid_argument;
    std::string message;
    // What the failed Vulkan call returned (VK_ERROR_OUT_OF_DEVICE_MEMORY, ...) where one caused
    // the error, for a program that handles some results itself; VK_ERROR_DEVICE_LOST with every
    // ErrorCode::device_lost. VK_SUCCESS where no Vulkan call failed: every other code, and
    // ErrorCode::vulkan for a missing version, feature, extension, limit or memory type.
    VkResult vk_result = VK_SUCCESS;
};

// Either a T or an Error. Reading the value of a failed Result (or the error of a successful
// one) is a programmer error and asserts.
template <class T>
class [[nodiscard]] Result {
public:
    Result(T value) : state_(std::in_place_index<0>, std::move(value)) {}
    Result(Error error) : state_(std::in_place_index<1>, std::move(error)) {}

    bool ok() const { return state_.index() == 0; }
    explicit operator bool() const { return ok(); }

    T& value() & {
        assert(ok());
        return std::get<0>(state_);
    }
    const T& value() const& {
        assert(ok());
        return std::get<0>(state_);
    }
    T&& value() && {
        assert(ok());
        return std::get<0>(std::move(state_));
    }
    T* operator->() { return &value(); }
    const T* operator->() const { return &value(); }
    T& operator*() & { return value(); }
    const T& operator*() const& { return value(); }

    const Error& error() const {
        assert(!ok());
        return std::get<1>(state_);
    }

private:
    std::variant<T, Error> state_;
};

// Result of an operation that produces nothing but can fail.
class [[nodiscard]] Status {
public:
    Status() = default;
    Status(Error error) : error_(std::move(error)), failed_(true) {}

    bool ok() const { return !failed_; }
    explicit operator bool() const { return ok(); }
    const Error& error() const {
        assert(failed_);
        return error_;
    }

private:
    Error error_;
    bool failed_ = false;
};

}  // namespace crisp
