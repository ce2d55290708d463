#pragma once
// Named figures a run reports (timings, counters, bytes), plus a scoped wall-clock timer
// and the process's peak resident memory.
#include <chrono>
#include <map>
#include <string>
#include <nlohmann/json.hpp>

namespace gilab {

class Stats {
public:
    void set(const std::string& key, double value) { values_[key] = value; }
    void add(const std::string& key, double value) { values_[key] += value; }
    // The figure under key; throws Error naming the key and the keys present when it is
    // missing, so a mistyped or never-set key cannot print as a plausible 0.
    double get(const std::string& key) const;
    // The figure under key, or fallback when it was never set: only where "not set" truly
    // means that value (e.g. a counter of work this frame did not do).
    double get_or(const std::string& key, double fallback) const;
    bool has(const std::string& key) const { return values_.count(key) != 0; }
    const std::map<std::string, double>& values() const { return values_; }
    void merge(const Stats& other, const std::string& prefix = "");
    nlohmann::json to_json() const;

private:
    std::map<std::string, double> values_;
};

class ScopedTimer {
public:
    // Adds the elapsed milliseconds to stats[key] when destroyed.
    ScopedTimer(Stats& stats, std::string key) : stats_(&stats), key_(std::move(key)) {}
    ~ScopedTimer() { stats_->add(key_, elapsed_ms()); }
    double elapsed_ms() const {
        return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start_).count();
    }

private:
    Stats* stats_;
    std::string key_;
    std::chrono::steady_clock::time_point start_ = std::chrono::steady_clock::now();
};

class Stopwatch {
public:
    double elapsed_ms() const {
        return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start_).count();
    }
    void reset() { start_ = std::chrono::steady_clock::now(); }

private:
    std::chrono::steady_clock::time_point start_ = std::chrono::steady_clock::now();
};

// CPU time (user + system) this process's threads have used so far: a task's cost that
// other work on the machine does not inflate the way it inflates wall time.
double process_cpu_seconds();
size_t peak_rss_bytes();      // VmHWM of this process
size_t current_rss_bytes();   // VmRSS of this process
// Resets this process's peak-RSS mark (VmHWM) to its current RSS, so a peak read after a
// piece of work is that work's own peak (plus what the process already held). Linux does
// this on writing "5" to /proc/self/clear_refs. Returns false if the mark did not move.
bool reset_peak_rss();
// Half the machine's physical memory: the default ceiling for what a setting may ask to
// allocate, checked before allocating.
size_t default_memory_limit_bytes();

}  // namespace gilab
