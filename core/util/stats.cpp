#include "core/util/stats.hpp"

#include "core/util/error.hpp"

#include <malloc.h>
#include <sys/resource.h>
#include <unistd.h>
#include <fstream>
#include <sstream>

namespace gilab {

double Stats::get(const std::string& key) const {
    auto it = values_.find(key);
    if (it != values_.end()) return it->second;
    std::string present;
    for (const auto& [k, v] : values_) present += (present.empty() ? "" : ", ") + k;
    throw Error("stats", "no figure '" + key + "' (present: " + (present.empty() ? "none" : present) + ")");
}

double Stats::get_or(const std::string& key, double fallback) const {
    auto it = values_.find(key);
    return it == values_.end() ? fallback : it->second;
}

void Stats::merge(const Stats& other, const std::string& prefix) {
    for (const auto& [k, v] : other.values_) values_[prefix + k] += v;
}

nlohmann::json Stats::to_json() const {
    nlohmann::json j = nlohmann::json::object();
    for (const auto& [k, v] : values_) j[k] = v;
    return j;
}

namespace {
size_t read_status_kib(const char* field) {
    std::ifstream status("/proc/self/status");
    std::string line;
    const std::string prefix = std::string(field) + ":";
    while (std::getline(status, line)) {
        if (line.rfind(prefix, 0) == 0) {
            std::istringstream in(line.substr(prefix.size()));
            size_t kib = 0;
            in >> kib;
            return kib;
        }
    }
    return 0;
}
}  // namespace

double process_cpu_seconds() {
    rusage usage{};
    if (getrusage(RUSAGE_SELF, &usage) != 0) return 0.0;
    const auto seconds = [](const timeval& t) { return double(t.tv_sec) + double(t.tv_usec) * 1e-6; };
    return seconds(usage.ru_utime) + seconds(usage.ru_stime);
}

size_t peak_rss_bytes() { return read_status_kib("VmHWM") * 1024; }
size_t current_rss_bytes() { return read_status_kib("VmRSS") * 1024; }

size_t default_memory_limit_bytes() {
    const long pages = sysconf(_SC_PHYS_PAGES), page = sysconf(_SC_PAGE_SIZE);
    if (pages <= 0 || page <= 0) return size_t(8) << 30;
    return size_t(pages) * size_t(page) / 2;
}

bool reset_peak_rss() {
    malloc_trim(0);  // give freed heap back first so the baseline is what is really held
    {
        std::ofstream f("/proc/self/clear_refs");
        if (!f) return false;
        f << "5";
        f.flush();
        if (!f) return false;
    }
    return peak_rss_bytes() <= current_rss_bytes() + (size_t(4) << 20);
}

}  // namespace gilab
