#pragma once
// A dictionary of settings (from JSON or CLI "key=value" pairs) that remembers which keys
// were read, so misspelt or unsupported keys are reported instead of silently ignored.
#include <limits>
#include <set>
#include <string>
#include <type_traits>
#include <nlohmann/json.hpp>
#include "core/util/error.hpp"

namespace gilab {

class Settings {
public:
    Settings() : values_(nlohmann::json::object()) {}
    explicit Settings(nlohmann::json values, std::string context = "settings");
    // A settings file (a JSON object); errors name the file, the line and the key.
    static Settings from_file(const std::string& file);

    // Parses "key=value"; value is read as JSON if it parses (numbers, true/false,
    // arrays), else as a string.
    void set_from_string(const std::string& assignment);
    template <typename T>
    void set(const std::string& key, const T& value) { values_[key] = value; }

    bool has(const std::string& key) const { return values_.contains(key); }

    template <typename T>
    T get(const std::string& key, const T& fallback) const {
        read_.insert(key);
        if (!values_.contains(key)) return fallback;
        return convert<T>(key);
    }
    template <typename T>
    T require(const std::string& key) const {
        read_.insert(key);
        if (!values_.contains(key)) throw Error(context_, "missing setting '" + key + "'");
        return convert<T>(key);
    }

    // Whether get or require has asked for `key` (present or not).
    bool was_read(const std::string& key) const { return read_.count(key) != 0; }
    // Throws Error listing every key that was never read, as not used by `reader`.
    void report_unused(const std::string& reader = "this technique") const;
    const nlohmann::json& json() const { return values_; }
    const std::string& context() const { return context_; }
    // Stable hash of the settings (for provenance: identical settings ⇒ identical hash).
    std::string hash() const;

private:
    template <typename T>
    T convert(const std::string& key) const {
        // A number must be finite and fit the type it is read as (1e19 read as a 64-bit
        // integer would wrap); integers must be whole. Checked before the conversion.
        if constexpr (std::is_arithmetic_v<T> && !std::is_same_v<T, bool>)
            check_number(key, (long double)std::numeric_limits<T>::lowest(), (long double)std::numeric_limits<T>::max(),
                         std::is_integral_v<T>);
        try {
            return values_.at(key).get<T>();
        } catch (const nlohmann::json::exception&) {
            throw Error(context_, "setting '" + key + "' has the wrong type: " + values_.at(key).dump());
        }
    }
    // Throws Error naming the key unless its value is a finite number in [lo, hi] (and
    // whole when `integral`).
    void check_number(const std::string& key, long double lo, long double hi, bool integral) const;

    nlohmann::json values_;
    std::string context_ = "settings";
    mutable std::set<std::string> read_;
};

}  // namespace gilab
