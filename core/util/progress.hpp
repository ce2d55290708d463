#pragma once
// A progress line on stderr for long runs, shown only when stderr is a terminal.
#include <atomic>
#include <chrono>
#include <string>

namespace gilab {

class Progress {
public:
    Progress(std::string label, size_t total);
    ~Progress();
    void advance(size_t amount = 1);  // thread-safe
    void finish();

private:
    void draw(bool final);
    std::string label_;
    size_t total_;
    std::atomic<size_t> done_{0};
    std::atomic<int64_t> last_draw_ms_{0};
    bool enabled_;
    bool finished_ = false;
    std::chrono::steady_clock::time_point start_;
};

}  // namespace gilab
