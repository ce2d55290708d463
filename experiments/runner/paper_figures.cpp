#include "experiments/runner/paper_figures.hpp"
#include <algorithm>
#include <charconv>
#include <cmath>
#include <set>
#include "core/util/error.hpp"
#include "core/util/format.hpp"

namespace gilab {

namespace {

// The whole text as a decimal number ("2422", "0.36", "-67.9"), C locale.
std::optional<double> parse_number(std::string_view text) {
    if (text.empty()) return std::nullopt;
    double value = 0;
    const char* end = text.data() + text.size();
    auto [ptr, ec] = std::from_chars(text.data(), end, value);
    if (ec != std::errc() || ptr != end || !std::isfinite(value)) return std::nullopt;
    return value;
}

std::string quoted(const std::string& s) { return "'" + s + "'"; }

std::string joined(const std::vector<std::string>& items) {
    std::string out;
    for (const std::string& item : items) {
        if (!out.empty()) out += ", ";
        out += quoted(item);
    }
    return out;
}

// One line's fields. Quoted fields may hold commas and doubled quotes; a record does not
// span lines.
std::vector<std::string> split_fields(std::string_view line, const std::string& where) {
    std::vector<std::string> fields;
    size_t i = 0;
    while (true) {
        std::string field;
        if (i < line.size() && line[i] == '"') {
            ++i;
            while (true) {
                if (i >= line.size()) throw Error(where, "a quoted field is not closed");
                if (line[i] == '"') {
                    if (i + 1 < line.size() && line[i + 1] == '"') {
                        field += '"';
                        i += 2;
                        continue;
                    }
                    ++i;
                    break;
                }
                field += line[i++];
            }
            if (i < line.size() && line[i] != ',')
                throw Error(where, "text after the closing quote of field " + std::to_string(fields.size() + 1));
        } else {
            while (i < line.size() && line[i] != ',') {
                if (line[i] == '"')
                    throw Error(where, "a quote inside unquoted field " + std::to_string(fields.size() + 1) +
                                           " (quote the whole field and double the quote)");
                field += line[i++];
            }
        }
        fields.push_back(std::move(field));
        if (i >= line.size()) break;
        ++i;  // the comma
    }
    return fields;
}

}  // namespace

std::string PaperKey::describe() const {
    if (const std::string* text = std::get_if<std::string>(&value)) return column + " = " + *text;
    return column + " = " + format_number(std::get<double>(value));
}

std::string PaperRow::where() const { return file_ + ".csv:" + std::to_string(line_); }

const PaperCell& PaperRow::cell(const std::string& column) const {
    auto it = cells_.find(column);
    if (it == cells_.end()) {
        std::vector<std::string> names;
        for (const auto& [name, cell] : cells_) names.push_back(name);
        throw Error(where(), "no column " + quoted(column) + " (columns: " + joined(names) + ")");
    }
    return it->second;
}

double PaperRow::number(const std::string& column) const {
    const PaperCell& c = cell(column);
    if (!c.number) throw Error(where(), "column " + quoted(column) + " holds " + quoted(c.text) + ", not a number");
    return *c.number;
}

int PaperRow::integer(const std::string& column) const {
    const double value = number(column);
    if (value != std::floor(value) || std::abs(value) > 2e9)
        throw Error(where(), "column " + quoted(column) + " holds " + quoted(text(column)) + ", not an integer");
    return int(value);
}

double PaperRow::scaled(const std::string& column, int exponent) const {
    const std::string& text = cell(column).text;
    (void)number(column);  // the cell must be a number
    if (text.find_first_of("eE") != std::string::npos)
        throw Error(where(), "column " + quoted(column) + " holds " + quoted(text) +
                                 ", which already has an exponent; cannot scale it by 10^" + std::to_string(exponent));
    return *parse_number(text + "e" + std::to_string(exponent));
}

bool PaperRow::matches(const PaperKeys& key) const {
    for (const PaperKey& k : key) {
        const PaperCell& c = cell(k.column);
        if (const std::string* text = std::get_if<std::string>(&k.value)) {
            if (c.text != *text) return false;
        } else if (!c.number || *c.number != std::get<double>(k.value)) {
            return false;
        }
    }
    return true;
}

PaperFigures PaperFigures::parse(const std::string& name, std::string_view text) {
    PaperFigures figures;
    figures.name_ = name;
    const std::string file = name + ".csv";
    int line_number = 0;
    bool have_header = false;
    size_t pos = 0;
    while (pos < text.size()) {
        size_t end = text.find('\n', pos);
        if (end == std::string_view::npos) end = text.size();
        std::string_view line = text.substr(pos, end - pos);
        pos = end + 1;
        ++line_number;
        if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
        const std::string where = file + ":" + std::to_string(line_number);
        if (!have_header && line.starts_with('#')) {
            line.remove_prefix(1);
            if (line.starts_with(' ')) line.remove_prefix(1);
            if (!figures.comment_.empty()) figures.comment_ += '\n';
            figures.comment_ += line;
            continue;
        }
        if (line.empty()) {
            // Only the end of the file may be blank.
            const std::string_view rest = pos < text.size() ? text.substr(pos) : std::string_view();
            if (rest.find_first_not_of("\r\n") == std::string_view::npos) break;
            throw Error(where, "empty line");
        }
        std::vector<std::string> fields = split_fields(line, where);
        if (!have_header) {
            std::set<std::string> seen;
            for (const std::string& column : fields) {
                if (column.empty()) throw Error(where, "a column without a name");
                if (!seen.insert(column).second) throw Error(where, "column " + quoted(column) + " named twice");
            }
            figures.columns_ = std::move(fields);
            have_header = true;
            continue;
        }
        if (fields.size() != figures.columns_.size())
            throw Error(where, std::to_string(fields.size()) + " fields, the header has " +
                                   std::to_string(figures.columns_.size()));
        std::map<std::string, PaperCell> cells;
        for (size_t i = 0; i < fields.size(); ++i) {
            std::optional<double> number = parse_number(fields[i]);
            cells.emplace(figures.columns_[i], PaperCell{std::move(fields[i]), number});
        }
        figures.rows_.emplace_back(name, line_number, std::move(cells));
    }
    if (!have_header) throw Error(file, "no header line");
    return figures;
}

bool PaperFigures::has_column(const std::string& column) const {
    return std::find(columns_.begin(), columns_.end(), column) != columns_.end();
}

void PaperFigures::check_key(const PaperKeys& key) const {
    for (const PaperKey& k : key)
        if (!has_column(k.column))
            throw Error(name_ + ".csv", "no column " + quoted(k.column) + " (columns: " + joined(columns_) + ")");
}

std::vector<const PaperRow*> PaperFigures::rows_where(const PaperKeys& key) const {
    check_key(key);
    std::vector<const PaperRow*> found;
    for (const PaperRow& r : rows_)
        if (r.matches(key)) found.push_back(&r);
    return found;
}

namespace {
std::string describe(const PaperKeys& key) {
    std::string out;
    for (const PaperKey& k : key) {
        if (!out.empty()) out += ", ";
        out += k.describe();
    }
    return out;
}
}  // namespace

const PaperRow* PaperFigures::find(const PaperKeys& key) const {
    const std::vector<const PaperRow*> found = rows_where(key);
    if (found.size() > 1)
        throw Error(name_ + ".csv", std::to_string(found.size()) + " rows with " + describe(key) + " (lines " +
                                        std::to_string(found[0]->line()) + " and " + std::to_string(found[1]->line()) +
                                        "); the key must pick one");
    return found.empty() ? nullptr : found.front();
}

const PaperRow& PaperFigures::row(const PaperKeys& key) const {
    const PaperRow* r = find(key);
    if (!r) throw Error(name_ + ".csv", "no row with " + describe(key));
    return *r;
}

namespace {
const std::map<std::string, PaperFigures>& all_paper_figures() {
    static const std::map<std::string, PaperFigures> all = [] {
        std::map<std::string, PaperFigures> files;
        for (const detail::EmbeddedPaperFile& f : detail::embedded_paper_files()) {
            const std::string_view text(reinterpret_cast<const char*>(f.data), f.size);
            files.emplace(f.name, PaperFigures::parse(f.name, text));
        }
        return files;
    }();
    return all;
}
}  // namespace

const PaperFigures& paper_figures(const std::string& name) {
    const auto& all = all_paper_figures();
    auto it = all.find(name);
    if (it == all.end())
        throw Error("paper figures", "no file " + quoted(name) + " in experiments/papers (files: " +
                                         joined(paper_figure_names()) + ")");
    return it->second;
}

std::vector<std::string> paper_figure_names() {
    std::vector<std::string> names;
    for (const auto& [name, figures] : all_paper_figures()) names.push_back(name);
    return names;
}

}  // namespace gilab
