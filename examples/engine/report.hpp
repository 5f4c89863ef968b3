// --report: what a run did and where its text went, as JSON, for people and for the example's test.
#pragma once

#include "app.hpp"

#include <crisp/result.hpp>

#include <cstdint>
#include <string>

namespace engine {

// Written to a temporary file and renamed into place. Errors: crisp::ErrorCode::io.
crisp::Status write_report(const std::string& path, const RunReport& report, uint32_t validation_messages);

}  // namespace engine
