#include "experiments/runner/result_writers.hpp"

#include <cmath>
#include <fstream>
#include <sstream>
#include <thread>
#include "core/util/build_info.hpp"
#include "core/util/parallel.hpp"

namespace gilab {

std::string format_cell(const nlohmann::json& value) {
    if (value.is_null()) return "";
    if (value.is_string()) return value.get<std::string>();
    if (value.is_boolean()) return value.get<bool>() ? "yes" : "no";
    if (value.is_number_integer() || value.is_number_unsigned()) return value.dump();
    if (value.is_number_float()) {
        double v = value.get<double>();
        if (!std::isfinite(v)) return "n/a";
        std::ostringstream out;
        double a = std::fabs(v);
        if (a != 0 && (a >= 1e6 || a < 1e-3)) out.precision(3), out << std::scientific << v;
        else out.precision(4), out << v;
        return out.str();
    }
    return value.dump();
}

namespace {
std::string csv_escape(const std::string& s) {
    if (s.find_first_of(",\"\n") == std::string::npos) return s;
    std::string out = "\"";
    for (char c : s) out += (c == '"') ? std::string("\"\"") : std::string(1, c);
    return out + "\"";
}
}  // namespace

std::string to_csv(const ResultTable& table) {
    std::ostringstream out;
    for (size_t i = 0; i < table.columns.size(); ++i) out << (i ? "," : "") << csv_escape(table.columns[i]);
    out << "\n";
    for (const auto& row : table.rows) {
        for (size_t i = 0; i < table.columns.size(); ++i) {
            const auto& c = table.columns[i];
            std::string cell;
            if (row.contains(c)) cell = row[c].is_number_float() ? row[c].dump() : format_cell(row[c]);
            out << (i ? "," : "") << csv_escape(cell);
        }
        out << "\n";
    }
    return out.str();
}

std::string to_markdown(const ResultTable& table) {
    std::ostringstream out;
    if (!table.title.empty()) out << "### " << table.title << "\n\n";
    out << "|";
    for (const auto& c : table.columns) out << " " << c << " |";
    out << "\n|";
    for (size_t i = 0; i < table.columns.size(); ++i) out << "---|";
    out << "\n";
    for (const auto& row : table.rows) {
        out << "|";
        for (const auto& c : table.columns) out << " " << (row.contains(c) ? format_cell(row[c]) : "") << " |";
        out << "\n";
    }
    return out.str();
}

nlohmann::json machine_description() {
    nlohmann::json m;
    std::ifstream cpuinfo("/proc/cpuinfo");
    std::string line;
    while (std::getline(cpuinfo, line))
        if (line.rfind("model name", 0) == 0) {
            m["cpu"] = line.substr(line.find(':') + 2);
            break;
        }
    m["hardware_threads"] = std::thread::hardware_concurrency();
    m["tbb_threads"] = default_thread_count();
    std::ifstream meminfo("/proc/meminfo");
    while (std::getline(meminfo, line))
        if (line.rfind("MemTotal:", 0) == 0) {
            std::istringstream in(line.substr(9));
            double kib = 0;
            in >> kib;
            m["memory_gib"] = std::round(kib / (1024.0 * 1024.0) * 10) / 10;
        }
    return m;
}

std::string git_revision() { return build_git_revision(); }

}  // namespace gilab
