#include "core/util/progress.hpp"

#include <cstdio>
#include <unistd.h>

namespace gilab {

Progress::Progress(std::string label, size_t total)
    : label_(std::move(label)), total_(total), enabled_(isatty(fileno(stderr)) != 0),
      start_(std::chrono::steady_clock::now()) {}

Progress::~Progress() { finish(); }

void Progress::advance(size_t amount) {
    done_ += amount;
    if (!enabled_) return;
    auto now_ms = std::chrono::duration_cast<std::chrono::milliseconds>(std::chrono::steady_clock::now() - start_).count();
    int64_t last = last_draw_ms_.load();
    // Redraw at most 10 times a second; only the thread that wins the exchange draws.
    if (now_ms - last >= 100 && last_draw_ms_.compare_exchange_strong(last, now_ms)) draw(false);
}

void Progress::finish() {
    if (finished_) return;
    finished_ = true;
    if (enabled_) draw(true);
}

void Progress::draw(bool final) {
    size_t done = std::min(done_.load(), total_);
    double fraction = total_ ? double(done) / double(total_) : 1.0;
    double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
    const int bar = 30;
    int filled = int(fraction * bar);
    std::string cells(size_t(filled), '#');
    cells.append(size_t(bar - filled), '.');
    double eta = fraction > 0 ? seconds / fraction - seconds : 0.0;
    std::fprintf(stderr, "\r%s [%s] %5.1f%%  %.1fs elapsed, %.1fs left%s", label_.c_str(), cells.c_str(),
                 100.0 * fraction, seconds, final ? 0.0 : eta, final ? "\n" : "   ");
    std::fflush(stderr);
}

}  // namespace gilab
