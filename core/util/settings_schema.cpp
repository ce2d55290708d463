#include "core/util/settings_schema.hpp"
#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>
#include "core/util/error.hpp"
#include "core/util/format.hpp"

namespace gilab {

const char* to_string(SettingType type) {
    switch (type) {
        case SettingType::Integer: return "integer";
        case SettingType::Number: return "number";
        case SettingType::Boolean: return "boolean";
        case SettingType::Choice: return "choice";
        case SettingType::Text: return "text";
    }
    return "?";
}

namespace {

std::string bound_text(double v) {
    if (v == std::floor(v) && std::fabs(v) < 1e15) return std::to_string(int64_t(v));
    return number_as_given(v);
}

std::string value_text(const nlohmann::json& v) {
    if (v.is_string()) return v.get<std::string>();
    if (v.is_boolean()) return v.get<bool>() ? "true" : "false";
    if (v.is_number_integer()) return std::to_string(v.get<int64_t>());
    if (v.is_number()) return number_as_given(v.get<double>());
    return v.dump();
}

// Edit distance, for "did you mean".
size_t edit_distance(const std::string& a, const std::string& b) {
    std::vector<size_t> row(b.size() + 1);
    for (size_t j = 0; j <= b.size(); ++j) row[j] = j;
    for (size_t i = 1; i <= a.size(); ++i) {
        size_t diagonal = row[0];
        row[0] = i;
        for (size_t j = 1; j <= b.size(); ++j) {
            const size_t above = row[j];
            row[j] = std::min({row[j] + 1, row[j - 1] + 1, diagonal + (a[i - 1] == b[j - 1] ? 0 : 1)});
            diagonal = above;
        }
    }
    return row[b.size()];
}

// Words of `text` filled into lines of at most `width` characters.
std::vector<std::string> wrap(const std::string& text, size_t width) {
    std::vector<std::string> lines;
    std::istringstream words(text);
    std::string line;
    for (std::string word; words >> word;) {
        if (!line.empty() && line.size() + 1 + word.size() > width) {
            lines.push_back(line);
            line.clear();
        }
        line += (line.empty() ? "" : " ") + word;
    }
    if (!line.empty()) lines.push_back(line);
    return lines;
}

// "at least 1", "positive", "0 to 1", "in (0, 1)": the range as a message says it.
std::string requirement_text(const SettingSpec& s) {
    const bool has_low = std::isfinite(s.low), has_high = std::isfinite(s.high);
    if (has_low && has_high) {
        if (!s.low_exclusive && !s.high_exclusive)
            return s.low == s.high ? bound_text(s.low) : bound_text(s.low) + " to " + bound_text(s.high);
        return "in " + s.range_text();
    }
    if (has_low && s.low == 0) return s.low_exclusive ? "positive" : "zero or more";
    if (has_low) return (s.low_exclusive ? "greater than " : "at least ") + bound_text(s.low);
    return (s.high_exclusive ? "less than " : "at most ") + bound_text(s.high);
}

// "cascaded, dense": the choices as a message lists them.
std::string choice_list(const SettingSpec& s) {
    return join(s.choices);
}

// "≥ 1 (pixels)", "(degrees)", "≥ 1".
std::string range_with_unit(const SettingSpec& s) {
    std::string out = s.range_text();
    if (s.unit.empty()) return out;
    if (!out.empty()) out.push_back(' ');
    out.append("(").append(s.unit).append(")");
    return out;
}

}  // namespace

std::string SettingSpec::default_text() const {
    if (default_value.is_null()) return derived_default.empty() ? "none" : derived_default;
    return value_text(default_value);
}

std::string SettingSpec::range_text() const {
    if (type == SettingType::Choice) {
        std::string out;
        for (size_t i = 0; i < choices.size(); ++i) out += (i ? " | " : "") + choices[i];
        return out;
    }
    if (type != SettingType::Integer && type != SettingType::Number) return "";
    const bool has_low = std::isfinite(low), has_high = std::isfinite(high);
    if (has_low && has_high) {
        if (!low_exclusive && !high_exclusive) return bound_text(low) + " … " + bound_text(high);
        return std::string(low_exclusive ? "(" : "[") + bound_text(low) + ", " + bound_text(high) +
               (high_exclusive ? ")" : "]");
    }
    if (has_low) return (low_exclusive ? "> " : "≥ ") + bound_text(low);
    if (has_high) return (high_exclusive ? "< " : "≤ ") + bound_text(high);
    return "";
}

SettingsSchema::Entry SettingsSchema::add(SettingSpec spec) {
    if (declares(spec.key)) throw std::logic_error("setting '" + spec.key + "' declared twice in " + technique_);
    specs_.push_back(std::move(spec));
    return Entry(specs_.back());
}

SettingsSchema::Entry SettingsSchema::integer(const std::string& key, int64_t default_value) {
    SettingSpec s;
    s.key = key;
    s.type = SettingType::Integer;
    s.default_value = default_value;
    return add(std::move(s));
}

SettingsSchema::Entry SettingsSchema::number(const std::string& key, double default_value) {
    SettingSpec s;
    s.key = key;
    s.type = SettingType::Number;
    // A default held in single precision is declared as its shortest decimal (0.05, not
    // 0.0500000007), which reads back as the same float.
    const float narrowed = float(default_value);
    s.default_value = double(narrowed) == default_value ? std::stod(number_as_given(narrowed)) : default_value;
    return add(std::move(s));
}

SettingsSchema::Entry SettingsSchema::boolean(const std::string& key, bool default_value) {
    SettingSpec s;
    s.key = key;
    s.type = SettingType::Boolean;
    s.default_value = default_value;
    return add(std::move(s));
}

SettingsSchema::Entry SettingsSchema::choice(const std::string& key, const std::string& default_value,
                                             std::vector<std::string> choices) {
    SettingSpec s;
    s.key = key;
    s.type = SettingType::Choice;
    if (std::find(choices.begin(), choices.end(), default_value) == choices.end())
        throw std::logic_error("setting '" + key + "': default '" + default_value + "' is not among its choices");
    s.default_value = default_value;
    s.choices = std::move(choices);
    return add(std::move(s));
}

SettingsSchema::Entry SettingsSchema::text(const std::string& key, const std::string& default_value) {
    SettingSpec s;
    s.key = key;
    s.type = SettingType::Text;
    s.default_value = default_value;
    return add(std::move(s));
}

bool SettingsSchema::declares(const std::string& key) const {
    return std::any_of(specs_.begin(), specs_.end(), [&](const SettingSpec& s) { return s.key == key; });
}

const SettingSpec& SettingsSchema::spec(const std::string& key) const {
    for (const SettingSpec& s : specs_)
        if (s.key == key) return s;
    throw std::logic_error("setting '" + key + "' is not declared in the " + technique_ + " settings schema");
}

const SettingSpec* SettingsSchema::quality_knob() const {
    for (const SettingSpec& s : specs_)
        if (s.knob) return &s;
    return nullptr;
}

void SettingsSchema::check_known(const Settings& settings) const {
    std::vector<std::string> unknown;
    for (auto it = settings.json().begin(); it != settings.json().end(); ++it)
        if (!declares(it.key())) unknown.push_back(it.key());
    if (unknown.empty()) return;
    std::ostringstream msg;
    msg << (unknown.size() == 1 ? "unknown setting " : "unknown settings ");
    for (size_t i = 0; i < unknown.size(); ++i) {
        msg << (i ? ", '" : "'") << unknown[i] << "'";
        const SettingSpec* nearest = nullptr;
        size_t best = 3;  // at most two edits away
        for (const SettingSpec& s : specs_)
            if (size_t d = edit_distance(unknown[i], s.key); d < best) best = d, nearest = &s;
        if (nearest) msg << " (did you mean '" << nearest->key << "'?)";
    }
    msg << " for technique '" << technique_ << "'; `gilab list settings " << technique_ << "` lists them";
    throw Error(settings.context(), msg.str());
}

void SettingsSchema::check_range(const Settings& settings, const SettingSpec& s, double v) const {
    const bool low_ok = s.low_exclusive ? v > s.low : v >= s.low;
    const bool high_ok = s.high_exclusive ? v < s.high : v <= s.high;
    if (!low_ok || !high_ok)
        throw Error(settings.context(), "setting '" + s.key + "' must be " + requirement_text(s) +
                                            (s.unit.empty() ? "" : " (" + s.unit + ")") + ", got " +
                                            value_text(settings.json().at(s.key)) +
                                            (value_text(settings.json().at(s.key)) == number_as_given(v)
                                                 ? ""
                                                 : " (" + number_as_given(v) + " as stored)"));
}

void SettingsSchema::check_values(const Settings& settings) const {
    check_known(settings);
    for (const SettingSpec& s : specs_)
        if (settings.has(s.key)) (void)checked(settings, s);
}

nlohmann::json SettingsSchema::checked(const Settings& settings, const SettingSpec& s) const {
    const std::string& where = settings.context();
    const std::string name = "setting '" + s.key + "'";
    switch (s.type) {
        case SettingType::Integer:
        case SettingType::Number: {
            // Settings::get checks the JSON type, finiteness and (integers) wholeness and fit.
            check_range(settings, s, s.type == SettingType::Integer ? double(settings.get<int64_t>(s.key, 0))
                                                                    : settings.get<double>(s.key, 0.0));
            return settings.json().at(s.key);
        }
        case SettingType::Boolean: return settings.get<bool>(s.key, false);
        case SettingType::Text: return settings.get<std::string>(s.key, "");
        case SettingType::Choice: {
            const nlohmann::json& given = settings.get<nlohmann::json>(s.key, nullptr);
            if (given.is_boolean() && s.boolean_aliases)
                return given.get<bool>() ? s.boolean_aliases->first : s.boolean_aliases->second;
            const std::string value = given.is_string() ? given.get<std::string>() : given.dump();
            if (!given.is_string() || std::find(s.choices.begin(), s.choices.end(), value) == s.choices.end())
                throw Error(where, name + " must be one of " + choice_list(s) + ", got " +
                                       (given.is_string() ? "'" + value + "'" : value));
            return value;
        }
    }
    return nullptr;
}

std::string SettingsSchema::table_text() const {
    size_t key_width = 3, default_width = 7, range_width = 5;
    for (const SettingSpec& s : specs_) {
        key_width = std::max(key_width, s.key.size());
        if (!s.default_value.is_null()) default_width = std::max(default_width, s.default_text().size());
        range_width = std::max(range_width, s.range_text().size());
    }
    range_width = std::min<size_t>(range_width, 36);
    auto pad = [](std::string s, size_t w) { return s.size() >= w ? s + " " : s + std::string(w - s.size() + 1, ' '); };
    std::ostringstream out;
    out << technique_ << ": " << title_ << "\n\n";
    out << "  " << pad("key", key_width) << pad("type", 7) << pad("default", default_width) << "range (unit)\n";
    for (const SettingSpec& s : specs_) {
        const std::string def = s.default_value.is_null() ? "derived" : s.default_text();
        std::string line = "  " + pad(s.key, key_width) + pad(to_string(s.type), 7) + pad(def, default_width) +
                           range_with_unit(s);
        while (line.back() == ' ') line.pop_back();
        out << line << "\n";
        std::string text = s.description;
        if (s.default_value.is_null()) text += " Default: " + s.derived_default + ".";
        if (s.knob)
            text += " Quality knob of equal-time comparisons (searched in " + bound_text(s.knob->low) + " … " +
                    bound_text(s.knob->high) + ").";
        for (const std::string& line : wrap(text, 84)) out << "      " << line << "\n";
    }
    return out.str();
}

std::string SettingsSchema::table_markdown() const {
    auto cell = [](std::string s) {
        for (size_t i = 0; (i = s.find('|', i)) != std::string::npos; i += 2) s.replace(i, 1, "\\|");
        return s;
    };
    std::ostringstream out;
    out << "| key | type | default | range | description |\n|---|---|---|---|---|\n";
    for (const SettingSpec& s : specs_) {
        const std::string range = range_with_unit(s);
        std::string text = s.description;
        if (s.knob)
            text += " Equal-time quality knob (" + bound_text(s.knob->low) + " … " + bound_text(s.knob->high) + ").";
        out << "| `" << s.key << "` | " << to_string(s.type) << " | "
            << cell(s.default_value.is_null() ? s.derived_default : s.default_text()) << " | " << cell(range)
            << " | " << cell(text) << " |\n";
    }
    return out.str();
}

}  // namespace gilab
