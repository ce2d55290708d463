#include "core/util/memory_budget.hpp"

#include <unistd.h>

#include <atomic>
#include <cctype>
#include <cmath>
#include <fstream>
#include <limits>
#include <sstream>
#include "core/util/error.hpp"

namespace gilab {

namespace {

std::atomic<uint64_t>& override_limit() {
    static std::atomic<uint64_t> bytes{0};  // 0: the default
    return bytes;
}

// A cgroup (container) limit below the machine's memory is the real ceiling.
uint64_t cgroup_limit() {
    for (const char* file : {"/sys/fs/cgroup/memory.max", "/sys/fs/cgroup/memory/memory.limit_in_bytes"}) {
        std::ifstream in(file);
        std::string text;
        if (!(in >> text) || text.empty() || !std::isdigit(static_cast<unsigned char>(text[0]))) continue;
        try {
            return std::stoull(text);
        } catch (const std::exception&) {
        }
    }
    return std::numeric_limits<uint64_t>::max();
}

uint64_t physical_memory() {
    const long pages = ::sysconf(_SC_PHYS_PAGES), page = ::sysconf(_SC_PAGE_SIZE);
    if (pages > 0 && page > 0) return MemoryBudget::times(uint64_t(pages), uint64_t(page));
    return uint64_t(8) << 30;  // unknown: assume a modest machine
}

std::string lower(std::string s) {
    for (char& c : s) c = char(std::tolower(static_cast<unsigned char>(c)));
    return s;
}

}  // namespace

uint64_t MemoryBudget::times(uint64_t count, uint64_t each) {
    if (each != 0 && count > std::numeric_limits<uint64_t>::max() / each) return std::numeric_limits<uint64_t>::max();
    return count * each;
}

uint64_t MemoryBudget::default_limit() {
    static const uint64_t bytes = std::min(physical_memory(), cgroup_limit()) / 2;
    return bytes;
}

uint64_t MemoryBudget::limit() {
    const uint64_t set = override_limit().load();
    return set ? set : default_limit();
}

void MemoryBudget::set_limit(uint64_t bytes) { override_limit().store(bytes); }

std::string MemoryBudget::format(uint64_t bytes) {
    if (bytes < 1024) return std::to_string(bytes) + (bytes == 1 ? " byte" : " bytes");
    const char* units[] = {"KiB", "MiB", "GiB", "TiB", "PiB", "EiB"};
    double value = double(bytes) / 1024.0;
    int unit = 0;
    while (value >= 1024.0 && unit < 5) {
        value /= 1024.0;
        ++unit;
    }
    std::ostringstream out;
    out.precision(value < 10 ? 2 : value < 100 ? 3 : 4);
    out << value << " " << units[unit];
    return out.str();
}

void MemoryBudget::check(uint64_t bytes, const std::string& what, const std::string& where) {
    const uint64_t allowed = limit();
    if (bytes <= allowed) return;
    const std::string needed = bytes == std::numeric_limits<uint64_t>::max()
                                   ? std::string("more than 16 EiB")
                                   : format(bytes) + " (" + std::to_string(bytes) + " bytes)";
    throw Error(where, what + " needs " + needed + ", more than the memory limit of " + format(allowed) +
                           " (set with --memory-limit)");
}

void MemoryBudget::check_count(uint64_t count, uint64_t min_file_bytes_each, uint64_t file_bytes_left,
                               uint64_t memory_bytes_each, const std::string& field, const std::string& where) {
    const uint64_t file_bytes = times(count, min_file_bytes_each);
    if (file_bytes > file_bytes_left) {
        const std::string needed = file_bytes == std::numeric_limits<uint64_t>::max()
                                       ? std::string("more than 16 EiB")
                                       : std::to_string(file_bytes) + " bytes";
        throw Error(where, field + " is " + std::to_string(count) + ", which needs at least " + needed +
                               " of file data, but only " + std::to_string(file_bytes_left) +
                               " bytes are left (a corrupt count or a truncated file)");
    }
    check(times(count, memory_bytes_each), field + " " + std::to_string(count), where);
}

uint64_t MemoryBudget::parse_size(const std::string& text, const std::string& option) {
    auto fail = [&]() -> uint64_t {
        throw Error(option, "'" + text + "' is not a memory size (give bytes, or a number with K, M, G or T, e.g. 8G or 512M)");
    };
    size_t i = 0;
    while (i < text.size() && (std::isdigit(static_cast<unsigned char>(text[i])) || text[i] == '.')) ++i;
    if (i == 0) return fail();
    double value = 0;
    try {
        size_t used = 0;
        value = std::stod(text.substr(0, i), &used);
        if (used != i) return fail();
    } catch (const std::exception&) {
        return fail();
    }
    std::string unit = lower(text.substr(i));
    while (!unit.empty() && unit.front() == ' ') unit.erase(unit.begin());
    double scale = 1;
    if (unit.empty() || unit == "b") scale = 1;
    else if (unit == "k" || unit == "kb" || unit == "kib") scale = 1024.0;
    else if (unit == "m" || unit == "mb" || unit == "mib") scale = 1024.0 * 1024.0;
    else if (unit == "g" || unit == "gb" || unit == "gib") scale = 1024.0 * 1024.0 * 1024.0;
    else if (unit == "t" || unit == "tb" || unit == "tib") scale = 1024.0 * 1024.0 * 1024.0 * 1024.0;
    else return fail();
    const double bytes = std::floor(value * scale);
    if (!std::isfinite(bytes) || bytes >= 18446744073709551616.0)
        throw Error(option, "'" + text + "' is larger than 16 EiB");
    if (bytes < 1) throw Error(option, "'" + text + "' must be at least one byte");
    return uint64_t(bytes);
}

ScopedMemoryLimit::ScopedMemoryLimit(uint64_t bytes) : previous_(override_limit().load()) {
    MemoryBudget::set_limit(bytes);
}

ScopedMemoryLimit::~ScopedMemoryLimit() { override_limit().store(previous_); }

}  // namespace gilab
