#include "core/util/settings.hpp"

#include <cmath>
#include <sstream>
#include "core/util/format.hpp"
#include "core/util/input_file.hpp"
#include "core/util/json_document.hpp"
#include "core/util/rng.hpp"

namespace gilab {

Settings::Settings(nlohmann::json values, std::string context)
    : values_(std::move(values)), context_(std::move(context)) {
    if (values_.is_null()) values_ = nlohmann::json::object();
    if (!values_.is_object()) throw Error(context_, "settings must be a JSON object, got " + values_.dump());
}

Settings Settings::from_file(const std::string& file) {
    const std::string text = read_input_file(file);
    check_text_encoding(text, file, "settings JSON");
    return Settings(parse_json_document(text, file), file);
}

void Settings::set_from_string(const std::string& assignment) {
    auto eq = assignment.find('=');
    if (eq == std::string::npos || eq == 0)
        throw Error(context_, "setting '" + assignment + "' is not of the form key=value");
    // Settings are JSON, whose strings are UTF-8; a stray byte would fail later, when
    // the settings are hashed or written into an output's metadata.
    try {
        (void)nlohmann::json(assignment).dump();
    } catch (const nlohmann::json::type_error&) {
        throw Error(context_, "setting " + nlohmann::json(assignment).dump(-1, ' ', false, nlohmann::json::error_handler_t::replace) +
                                  " is not valid UTF-8 text");
    }
    std::string key = assignment.substr(0, eq);
    std::string text = assignment.substr(eq + 1);
    auto parsed = nlohmann::json::parse(text, nullptr, /*allow_exceptions=*/false);
    values_[key] = parsed.is_discarded() ? nlohmann::json(text) : parsed;
}

void Settings::check_number(const std::string& key, long double lo, long double hi, bool integral) const {
    const nlohmann::json& v = values_.at(key);
    if (!v.is_number()) throw Error(context_, "setting '" + key + "' has the wrong type: " + v.dump() + " (expected a number)");
    long double x = 0;
    if (v.is_number_unsigned()) x = (long double)v.get<uint64_t>();
    else if (v.is_number_integer()) x = (long double)v.get<int64_t>();
    else {
        const double d = v.get<double>();
        if (!std::isfinite(d)) throw Error(context_, "setting '" + key + "' is not a finite number: " + v.dump());
        if (integral && d != std::floor(d))
            throw Error(context_, "setting '" + key + "' must be a whole number, got " + v.dump());
        x = (long double)d;
    }
    if (x < lo || x > hi) {
        const std::string range = "[" + number_as_given(double(lo)) + ", " + number_as_given(double(hi)) + "]";
        throw Error(context_, "setting '" + key + "' = " + v.dump() + " is out of range " + range);
    }
}

void Settings::report_unused(const std::string& reader) const {
    std::vector<std::string> unused;
    for (auto it = values_.begin(); it != values_.end(); ++it)
        if (!read_.count(it.key())) unused.push_back(it.key());
    if (unused.empty()) return;
    std::ostringstream msg;
    msg << (unused.size() == 1 ? "unknown setting " : "unknown settings ");
    for (size_t i = 0; i < unused.size(); ++i) msg << (i ? ", '" : "'") << unused[i] << "'";
    msg << " (misspelt, or not used by " << reader << ")";
    throw Error(context_, msg.str());
}

std::string Settings::hash() const {
    // nlohmann::json objects are ordered by key, so dump() is canonical.
    std::string text = values_.dump();
    uint64_t h = 0xcbf29ce484222325ull;
    for (unsigned char c : text) h = (h ^ c) * 0x100000001b3ull;
    std::ostringstream out;
    out << std::hex << mix64(h);
    return out.str();
}

}  // namespace gilab
