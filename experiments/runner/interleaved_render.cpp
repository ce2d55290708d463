#include "experiments/runner/interleaved_render.hpp"

#include <algorithm>

namespace gilab {

InterleavedRender render_interleaved(const std::vector<std::unique_ptr<Technique>>& techniques, const ViewSet& views,
                                     int frames, const std::vector<std::string>& keys, SpecSlowFrames slow) {
    InterleavedRender result;
    result.runs.resize(techniques.size());
    result.frames = frames;
    for (int f = 0; f < result.frames; ++f) {
        double slowest = 0;
        for (size_t i = 0; i < techniques.size(); ++i) {
            InterleavedRun& run = result.runs[i];
            run.films.clear();
            techniques[i]->render(views, run.films);
            run.last = techniques[i]->stats();
            for (const std::string& key : keys) run.per_frame[key].push_back(run.last.get(key));
            slowest = std::max(slowest, run.last.get("render_ms"));
        }
        if (f == 0 && slow.frame_ms > 0 && slowest > slow.frame_ms) result.frames = std::min(result.frames, slow.frames);
    }
    return result;
}

}  // namespace gilab
