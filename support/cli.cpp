#include "cli.hpp"

#include "core/utf8.hpp"

#include <algorithm>
#include <cstdio>
#include <cstdlib>

namespace crisp::cli {

std::string printable(std::string_view text, size_t max) {
    return crisp::printable(text, max);
}

std::string printable_path(std::string_view path) {
    return crisp::printable(path, kPrintablePath);
}

std::vector<std::string_view> split(std::string_view text, char separator) {
    std::vector<std::string_view> parts;
    for (;;) {
        const size_t end = text.find(separator);
        parts.push_back(text.substr(0, end));
        if (end == std::string_view::npos) return parts;
        text.remove_prefix(end + 1);
    }
}

CommandLine::CommandLine(std::string program, std::string synopsis)
    : program_(std::move(program)), synopsis_(std::move(synopsis)) {}

CommandLine& CommandLine::on_usage_error(int exit_code, std::string hint, bool full_help) {
    usage_exit_code_ = exit_code;
    hint_ = std::move(hint);
    full_help_on_error_ = full_help;
    return *this;
}

CommandLine& CommandLine::section(std::string heading) {
    entries_.push_back({"", "", std::move(heading), nullptr});
    return *this;
}

CommandLine& CommandLine::epilogue(std::string text) {
    epilogue_ = std::move(text);
    return *this;
}

CommandLine& CommandLine::option(std::string names, std::string value_name, std::string help, Apply apply) {
    entries_.push_back({std::move(names), std::move(value_name), std::move(help), std::move(apply)});
    return *this;
}

CommandLine& CommandLine::flag(std::string names, std::string help, bool& target, bool value) {
    return flag(std::move(names), std::move(help), [&target, value] { target = value; });
}

CommandLine& CommandLine::flag(std::string names, std::string help, std::function<void()> apply) {
    return option(std::move(names), "", std::move(help), [apply = std::move(apply)](std::string_view) -> Status {
        apply();
        return {};
    });
}

CommandLine& CommandLine::text(std::string names, std::string value_name, std::string help, std::string& target) {
    return option(std::move(names), std::move(value_name), std::move(help), [&target](std::string_view value) {
        target = value;
        return Status{};
    });
}

CommandLine& CommandLine::text(std::string names, std::string value_name, std::string help,
                               std::optional<std::string>& target) {
    return option(std::move(names), std::move(value_name), std::move(help), [&target](std::string_view value) {
        target = std::string(value);
        return Status{};
    });
}

CommandLine& CommandLine::repeated(std::string names, std::string value_name, std::string help,
                                   std::vector<std::string>& target) {
    return option(std::move(names), std::move(value_name), std::move(help), [&target](std::string_view value) {
        target.emplace_back(value);
        return Status{};
    });
}

CommandLine& CommandLine::codepoints(std::string names, std::string value_name, std::string help,
                                     std::vector<uint32_t>& target) {
    return option(std::move(names), std::move(value_name), std::move(help), [&target](std::string_view value) {
        const std::vector<uint32_t> decoded = decode_utf8(value);
        target.insert(target.end(), decoded.begin(), decoded.end());
        return Status{};
    });
}

CommandLine& CommandLine::choice(std::string names, std::string value_name, std::string help, std::string& target,
                                 std::vector<std::string> values) {
    return choice<std::string>(std::move(names), std::move(value_name), std::move(help), target, std::move(values),
                               [](const std::string& value) { return value; });
}

CommandLine& CommandLine::positional(Apply apply) {
    positional_ = std::move(apply);
    return *this;
}

std::string CommandLine::last_name(std::string_view names) {
    const size_t comma = names.rfind(',');
    std::string_view name = comma == std::string_view::npos ? names : names.substr(comma + 1);
    while (!name.empty() && name.front() == ' ') name.remove_prefix(1);
    return std::string(name);
}

std::string CommandLine::not_one_of(std::string_view option, const std::vector<std::string>& names,
                                    std::string_view text) {
    std::string list;
    for (size_t i = 0; i < names.size(); ++i) {
        list += i == 0 ? "" : i + 1 == names.size() ? " or " : ", ";
        list += names[i];
    }
    return std::string(option) + " takes " + list + ", not '" + printable(text) + "'";
}

std::string CommandLine::range_message(std::string_view option, double low, double high, bool low_open,
                                       const char* unit) {
    char range[96];
    if (low_open) {
        std::snprintf(range, sizeof range, "(%.7g, %.7g]", low, high);
    } else {
        std::snprintf(range, sizeof range, "%.7g..%.7g", low, high);
    }
    return std::string(option) + " must be in " + range + unit;
}

CommandLine::Entry* CommandLine::find(std::string_view name) {
    return const_cast<Entry*>(std::as_const(*this).find(name));
}

const CommandLine::Entry* CommandLine::find(std::string_view name) const {
    for (const Entry& entry : entries_) {
        if (entry.names.empty()) continue;
        for (std::string_view candidate : split(entry.names, ',')) {
            while (!candidate.empty() && candidate.front() == ' ') candidate.remove_prefix(1);
            if (candidate == name) return &entry;
        }
    }
    return nullptr;
}

void CommandLine::parse(int argc, char** argv) {
    for (int i = 1; i < argc; ++i) {
        const std::string_view arg = argv[i];
        if (arg == "-h" || arg == "--help") {
            std::fputs(help().c_str(), stdout);
            std::exit(0);
        }
        Status applied;
        if (arg.size() > 1 && arg.front() == '-') {
            Entry* entry = find(arg);
            if (!entry) fail("unknown option '" + printable(arg) + "'");
            if (!entry->value_name.empty() && i + 1 >= argc) {
                fail(std::string(arg) + " needs a value (" + entry->value_name + ")");
            }
            entry->given = true;
            applied = entry->apply(entry->value_name.empty() ? std::string_view() : std::string_view(argv[++i]));
        } else if (positional_) {
            applied = positional_(arg);
        } else {
            fail("unexpected argument '" + printable(arg) + "'");
        }
        if (!applied) fail(applied.error().message);
    }
}

bool CommandLine::given(std::string_view name) const {
    const Entry* entry = find(name);
    return entry && entry->given;
}

void CommandLine::fail(const std::string& message) const {
    std::fprintf(stderr, "%s: %s%s\n", program_.c_str(), message.c_str(), full_help_on_error_ ? "" : hint_.c_str());
    if (full_help_on_error_) std::fputs(help().c_str(), stderr);
    std::exit(usage_exit_code_);
}

std::string CommandLine::help() const {
    auto head = [](const Entry& entry) {
        return entry.value_name.empty() ? entry.names : entry.names + " " + entry.value_name;
    };
    const std::string help_head = "-h, --help";
    size_t column = help_head.size();
    for (const Entry& entry : entries_) {
        if (!entry.names.empty()) column = std::max(column, head(entry).size());
    }
    column += 2;
    std::string out = synopsis_;
    auto line = [&](const std::string& left, std::string_view text) {
        out += "  " + left + std::string(column - left.size(), ' ');
        for (const char c : text) {
            out += c;
            if (c == '\n') out += std::string(column + 2, ' ');
        }
        out += '\n';
    };
    for (size_t i = 0; i < entries_.size(); ++i) {
        const Entry& entry = entries_[i];
        if (!entry.names.empty()) {
            line(head(entry), entry.help);
        } else {
            out += (i == 0 ? "" : "\n") + entry.help + "\n";
        }
    }
    line(help_head, "this text");
    return out + epilogue_;
}

}  // namespace crisp::cli
