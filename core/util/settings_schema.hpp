#pragma once
// A technique's settings declared once: every key with its type, default, range or
// choices, unit and a one-line description, and whether it is the quality knob that an
// equal-time comparison turns. The table drives the parser (defaults, type and range
// checks, unknown keys), `gilab list settings TECHNIQUE`, the Python help and the
// README's settings tables, so none of them keeps a copy of its own. Mitsuba 3's
// per-plugin parameter tables are the model.
//
//   SettingsSchema s("path", "Path tracer");
//   s.integer("spp", 16).at_least(1).unit("samples per pixel").doc("...").quality_knob(1, 1 << 20);
//   int spp = s.get<int>(settings, "spp");   // the default, or the checked value given
#include <cstdint>
#include <limits>
#include <optional>
#include <string>
#include <type_traits>
#include <vector>
#include <nlohmann/json.hpp>
#include "core/util/settings.hpp"

namespace gilab {

enum class SettingType { Integer, Number, Boolean, Choice, Text };
const char* to_string(SettingType type);  // "integer", "number", "boolean", "choice", "text"

// The range an equal-time comparison may search for a quality knob.
struct KnobRange {
    double low = 1, high = 1;
};

struct SettingSpec {
    std::string key;
    SettingType type = SettingType::Integer;
    // The default as a JSON value; null when it is derived from the scene or from other
    // settings, and then `derived_default` says how.
    nlohmann::json default_value;
    std::string derived_default;
    // Integers and numbers: the accepted range (inclusive unless marked exclusive).
    double low = -std::numeric_limits<double>::infinity();
    double high = std::numeric_limits<double>::infinity();
    bool low_exclusive = false, high_exclusive = false;
    std::vector<std::string> choices;  // Choice
    // Choice: what JSON true and false stand for (settings files older than the choice).
    std::optional<std::pair<std::string, std::string>> boolean_aliases;
    std::string unit;
    std::string description;
    std::optional<KnobRange> knob;  // the quality knob of equal-time comparisons

    // "16", "hash_grid", "derived: 3 % of ..." as a person reads it.
    std::string default_text() const;
    // "≥ 1", "(0, 1)", "radius | knn", "" when anything of the type goes.
    std::string range_text() const;
};

class SettingsSchema {
public:
    // A fluent builder for the spec just added (valid until the next key is added).
    class Entry {
    public:
        explicit Entry(SettingSpec& spec) : spec_(spec) {}
        Entry& at_least(double low) { spec_.low = low; return *this; }
        Entry& at_most(double high) { spec_.high = high; return *this; }
        Entry& range(double low, double high) { spec_.low = low; spec_.high = high; return *this; }
        Entry& above(double low) { spec_.low = low; spec_.low_exclusive = true; return *this; }
        Entry& below(double high) { spec_.high = high; spec_.high_exclusive = true; return *this; }
        Entry& unit(std::string unit) { spec_.unit = std::move(unit); return *this; }
        Entry& doc(std::string text) { spec_.description = std::move(text); return *this; }
        Entry& derived(std::string how) { spec_.default_value = nullptr; spec_.derived_default = std::move(how); return *this; }
        Entry& quality_knob(double low, double high) { spec_.knob = KnobRange{low, high}; return *this; }
        Entry& booleans_mean(std::string if_true, std::string if_false) {
            spec_.boolean_aliases = std::make_pair(std::move(if_true), std::move(if_false));
            return *this;
        }

    private:
        SettingSpec& spec_;
    };

    SettingsSchema(std::string technique, std::string title) : technique_(std::move(technique)), title_(std::move(title)) {}

    Entry integer(const std::string& key, int64_t default_value);
    Entry number(const std::string& key, double default_value);
    Entry boolean(const std::string& key, bool default_value);
    Entry choice(const std::string& key, const std::string& default_value, std::vector<std::string> choices);
    Entry text(const std::string& key, const std::string& default_value);

    const std::string& technique() const { return technique_; }
    const std::string& title() const { return title_; }
    const std::vector<SettingSpec>& specs() const { return specs_; }
    // The spec of `key`; throws std::logic_error for a key the schema does not declare
    // (a parser asking for an undeclared key is a bug, not bad input).
    const SettingSpec& spec(const std::string& key) const;
    bool declares(const std::string& key) const;
    // The one quality knob, or null when the technique has none.
    const SettingSpec* quality_knob() const;

    // Throws Error naming every given key the schema does not declare, with the nearest
    // declared key when one is close, and where to find the list.
    void check_known(const Settings& settings) const;
    // check_known, and every given value checked for type, range and choices (what a
    // parser checks key by key; the checks that join keys stay the parser's).
    void check_values(const Settings& settings) const;

    // The value of `key`: the default when the setting is not given, else the given value
    // checked for type, range and choices (Error naming the setting otherwise). Marks the
    // key read. A key with a derived default must be read with get_given.
    template <typename T>
    T get(const Settings& settings, const std::string& key) const {
        const SettingSpec& s = spec(key);
        if (!settings.has(key)) {
            (void)settings.get<nlohmann::json>(key, nullptr);  // marks it read
            return default_of<T>(s);
        }
        return given<T>(settings, s);
    }
    // The given value (checked as in get), or nothing when the setting is not given.
    template <typename T>
    std::optional<T> get_given(const Settings& settings, const std::string& key) const {
        const SettingSpec& s = spec(key);
        if (!settings.has(key)) {
            (void)settings.get<nlohmann::json>(key, nullptr);
            return std::nullopt;
        }
        return given<T>(settings, s);
    }

    // A table a person can read: key, type, default, range, description.
    std::string table_text() const;
    // The same as a Markdown table (the README's settings sections are these).
    std::string table_markdown() const;

private:
    Entry add(SettingSpec spec);
    template <typename T>
    static T default_of(const SettingSpec& s) {
        if (s.default_value.is_null())
            throw std::logic_error("setting '" + s.key + "' has a derived default: read it with get_given");
        return s.default_value.get<T>();
    }
    template <typename T>
    T given(const Settings& settings, const SettingSpec& s) const {
        // The declared range first (its message says what the setting takes), then that
        // the number fits T (1e10 read as an int is refused by Settings::get), then, for a
        // float, the range again on the value as stored (1e-50 is > 0 but 0 as a float).
        nlohmann::json value = checked(settings, s);
        if constexpr (std::is_arithmetic_v<T> && !std::is_same_v<T, bool>) {
            const T narrowed = settings.get<T>(s.key, T{});
            if constexpr (std::is_floating_point_v<T>) check_range(settings, s, double(narrowed));
            return narrowed;
        } else {
            return value.template get<T>();
        }
    }
    // Throws Error naming the setting unless `value` lies in its declared range.
    void check_range(const Settings& settings, const SettingSpec& spec, double value) const;
    // The given value, checked against the spec; a Choice given as a boolean is mapped
    // through its aliases.
    nlohmann::json checked(const Settings& settings, const SettingSpec& spec) const;

    std::string technique_, title_;
    std::vector<SettingSpec> specs_;
};

}  // namespace gilab
