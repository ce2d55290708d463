#pragma once
// Small functions the experiments share to turn measurements into table cells: sizes
// in MB (10⁶ B) and MiB (2²⁰ B), ratios that stay empty when the divisor is zero, the
// median and mean of repeated timings, and the machine's load while timing.
#include <algorithm>
#include <fstream>
#include <vector>
#include <nlohmann/json.hpp>

namespace gilab {

inline double mb(double bytes) { return bytes / 1e6; }
inline double mib(double bytes) { return bytes / double(1 << 20); }
inline nlohmann::json ratio(double a, double b) { return b > 0 ? nlohmann::json(a / b) : nlohmann::json(nullptr); }

// The middle value; the mean of the two middle values for an even count; 0 when empty.
inline double median(std::vector<double> v) {
    if (v.empty()) return 0;
    std::sort(v.begin(), v.end());
    const size_t n = v.size();
    return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

inline double mean(const std::vector<double>& v) {
    double sum = 0;
    for (double x : v) sum += x;
    return v.empty() ? 0 : sum / double(v.size());
}

// 1-minute load average (−1 if unknown): other work on a shared machine slows timings,
// and this says how much was running.
inline double load_average() {
    std::ifstream in("/proc/loadavg");
    double load = -1;
    in >> load;
    return load;
}

}  // namespace gilab
