#include "core/util/parallel.hpp"

#include <tbb/blocked_range.h>
#include <tbb/global_control.h>
#include <tbb/info.h>
#include <tbb/parallel_for.h>
#include <vector>

namespace gilab {

void parallel_for_tiles(int width, int height, int tile_size, const std::function<void(const Tile&)>& fn) {
    tile_size = std::max(tile_size, 1);
    std::vector<Tile> tiles;
    for (int y = 0; y < height; y += tile_size)
        for (int x = 0; x < width; x += tile_size)
            tiles.push_back({x, y, std::min(x + tile_size, width), std::min(y + tile_size, height)});
    tbb::parallel_for(tbb::blocked_range<size_t>(0, tiles.size(), 1), [&](const tbb::blocked_range<size_t>& r) {
        for (size_t i = r.begin(); i != r.end(); ++i) fn(tiles[i]);
    });
}

void parallel_for(size_t count, size_t grain, const std::function<void(size_t, size_t)>& fn) {
    if (count == 0) return;
    tbb::parallel_for(tbb::blocked_range<size_t>(0, count, std::max<size_t>(grain, 1)),
                      [&](const tbb::blocked_range<size_t>& r) { fn(r.begin(), r.end()); });
}

struct ThreadLimit::Impl {
    std::unique_ptr<tbb::global_control> control;
};

ThreadLimit::ThreadLimit(int threads) : impl_(std::make_unique<Impl>()) {
    if (threads > 0)
        impl_->control = std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism,
                                                               size_t(threads));
}
ThreadLimit::~ThreadLimit() = default;

int default_thread_count() { return tbb::info::default_concurrency(); }

}  // namespace gilab
