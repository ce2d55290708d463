#include "techniques/stereo_frame.hpp"

#include <vector>
#include "core/util/stats.hpp"

namespace gilab {

StereoFrame render_stereo_frame(Technique& technique, const HmdRig& rig) {
    ViewSet views = ViewSet::stereo_pair(rig.eye(Eye::Left), rig.eye(Eye::Right));
    std::vector<Film> films(2);
    Stopwatch clock;
    technique.render(views, films);
    StereoFrame frame;
    frame.render_ms = clock.elapsed_ms();
    frame.left = std::move(films[0]);
    frame.right = std::move(films[1]);
    return frame;
}

}  // namespace gilab
