#pragma once
// Thin helpers over TBB. Work is split into fixed tiles whose results depend only on
// the tile, so outputs are identical at any thread count.
#include <cstddef>
#include <functional>
#include <memory>

namespace gilab {

struct Tile {
    int x0, y0, x1, y1;  // [x0, x1) × [y0, y1)
};

// Calls fn(tile) for every tile of a width × height image, in parallel.
void parallel_for_tiles(int width, int height, int tile_size, const std::function<void(const Tile&)>& fn);
// Calls fn(begin, end) over [0, count) in chunks of at least grain, in parallel.
void parallel_for(size_t count, size_t grain, const std::function<void(size_t, size_t)>& fn);

// Limits TBB to n threads while alive (n ≤ 0: leave the default).
class ThreadLimit {
public:
    explicit ThreadLimit(int threads);
    ~ThreadLimit();

private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
};
int default_thread_count();

}  // namespace gilab
