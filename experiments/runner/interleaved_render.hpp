#pragma once
// Prepared techniques rendered in turn, frame by frame (A B C A B C …), so that a change
// in the machine's load hits every one of them alike and the ratios between them are
// fair. The spec runner renders interleaved variants with it, and so do the probes that
// compare techniques on views or images of their own (stereo pairs, written images).
#include <map>
#include <memory>
#include <string>
#include <vector>
#include "core/image/film.hpp"
#include "core/util/stats.hpp"
#include "experiments/runner/experiment_spec.hpp"
#include "techniques/technique.hpp"

namespace gilab {

struct InterleavedRun {
    std::vector<Film> films;  // the last frame's views
    Stats last;               // stats after the last frame
    std::map<std::string, std::vector<double>> per_frame;  // the requested stats, one value per frame
};

struct InterleavedRender {
    std::vector<InterleavedRun> runs;  // one per technique, in order
    int frames = 0;                    // frames rendered (fewer when slow)
};

// Renders every technique `frames` times over `views`, in turn within each frame, and
// keeps `keys` of each frame's stats. With `slow` set, a first frame slower than
// slow.frame_ms (render_ms of the slowest technique) cuts the frames to slow.frames.
InterleavedRender render_interleaved(const std::vector<std::unique_ptr<Technique>>& techniques, const ViewSet& views,
                                     int frames, const std::vector<std::string>& keys, SpecSlowFrames slow = {});

}  // namespace gilab
