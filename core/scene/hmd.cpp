#include "core/scene/hmd.hpp"

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include "core/util/error.hpp"
#include "core/image/film.hpp"
#include "core/util/input_file.hpp"

namespace gilab {

namespace {

std::vector<HmdPreset> make_presets() {
    std::vector<HmdPreset> presets;

    HmdPreset vive;
    vive.name = "vive";
    vive.display_name = "HTC Vive";
    vive.width = 1080;
    vive.height = 1200;
    vive.ipd = 0.063f;
    // GetProjectionRaw(pfLeft, pfRight, pfTop, pfBottom) as SteamVR reported them.
    vive.left_fov = FrustumTangents::from_openvr(-1.3975f, 1.25023f, -1.47588f, 1.46464f);
    vive.right_fov = FrustumTangents::from_openvr(-1.25107f, 1.40556f, -1.48467f, 1.46426f);
    vive.source =
        "Resolution: the 1080x1200 per-eye display panel (HTC specification; SteamVR's "
        "recommended render target at the default 1.4x supersampling is 1512x1680, not used "
        "here). Frustum: IVRSystem::GetProjectionRaw as reported by SteamVR on an HTC Vive, "
        "left (-1.3975, 1.25023, -1.47588, 1.46464), right (-1.25107, 1.40556, -1.48467, "
        "1.46426), https://github.com/ValveSoftware/openvr/issues/256; an independent hmdq "
        "record of another unit agrees within 1% (https://risa2000.github.io/hmdgdb/hmd_cfgs/"
        "Vive_Native_R90.html). Units differ slightly by factory calibration. IPD: 63 mm "
        "default.";
    presets.push_back(vive);

    HmdPreset quest2;
    quest2.name = "quest2";
    quest2.display_name = "Meta Quest 2";
    quest2.width = 1832;
    quest2.height = 1920;
    quest2.ipd = 0.063f;
    // Signed half angles (XrFovf order: left, right, up, down) in whole degrees: the
    // runtime's tangents are exactly tan(52), tan(45), tan(48), tan(50).
    quest2.left_fov = FrustumTangents::from_openxr(glm::radians(-52.0f), glm::radians(45.0f),
                                                   glm::radians(48.0f), glm::radians(-50.0f));
    quest2.right_fov = FrustumTangents::from_openxr(glm::radians(-45.0f), glm::radians(52.0f),
                                                    glm::radians(48.0f), glm::radians(-50.0f));
    quest2.source =
        "Resolution: the 1832x1920 per-eye display panel (Meta specification; the Oculus PC "
        "runtime recommends 2352x2368 per eye at pixel density 1.0 over Link). Frustum: "
        "default eye field of view reported by the Oculus runtime 1.53, recorded with hmdq: "
        "left eye -52/+45 deg horizontal, -50/+48 deg vertical (tangents 1.279942, 1.0, "
        "1.191754, 1.110613), right eye mirrored, https://risa2000.github.io/hmdgdb/hmd_cfgs/"
        "Quest2_Native_R72.html. IPD: 63 mm, the middle of the 58/63/68 mm lens settings "
        "(the runtime reported eye offsets of +-31.75 mm).";
    presets.push_back(quest2);

    return presets;
}

std::string lower(std::string s) {
    for (char& c : s) c = char(std::tolower(static_cast<unsigned char>(c)));
    return s;
}

std::string trim(const std::string& s) {
    size_t b = s.find_first_not_of(" \t\r\n");
    if (b == std::string::npos) return "";
    size_t e = s.find_last_not_of(" \t\r\n");
    return s.substr(b, e - b + 1);
}

std::vector<std::string> split_csv(const std::string& line) {
    std::vector<std::string> fields;
    std::string field;
    std::istringstream in(line);
    while (std::getline(in, field, ',')) fields.push_back(trim(field));
    if (!line.empty() && line.back() == ',') fields.push_back("");
    return fields;
}

// Whole-field parse; nullopt if the text is not a number.
std::optional<double> parse_number(const std::string& text) {
    if (text.empty()) return std::nullopt;
    errno = 0;
    char* end = nullptr;
    double v = std::strtod(text.c_str(), &end);
    if (end != text.c_str() + text.size() || errno == ERANGE) return std::nullopt;
    return v;
}

}  // namespace

const std::vector<HmdPreset>& hmd_presets() {
    static const std::vector<HmdPreset> presets = make_presets();
    return presets;
}

const HmdPreset& find_hmd_preset(const std::string& name) {
    const auto& presets = hmd_presets();
    std::string key = lower(name);
    for (const auto& p : presets) {
        if (p.name == key) return p;
    }
    std::string known;
    for (const auto& p : presets) known += (known.empty() ? "" : ", ") + p.name;
    throw Error("unknown HMD preset '" + name + "'; known presets: " + known);
}

HmdRig::HmdRig(HmdPreset preset, HeadPose pose) : preset_(std::move(preset)), pose_(pose) {
    if (preset_.width <= 0 || preset_.height <= 0) {
        throw Error("HMD preset '" + preset_.name + "'",
                    "resolution " + std::to_string(preset_.width) + "x" +
                        std::to_string(preset_.height) + " must be positive");
    }
}

void HmdRig::set_resolution(int width, int height) {
    check_resolution(width, height);
    preset_.width = width;
    preset_.height = height;
}

Vec3 HmdRig::eye_position(Eye which) const {
    float half = 0.5f * preset_.ipd;
    Vec3 offset(which == Eye::Left ? -half : half, 0.0f, 0.0f);
    return pose_.position + pose_.orientation * offset;
}

EyeCamera HmdRig::eye(Eye which) const {
    const FrustumTangents& fov = which == Eye::Left ? preset_.left_fov : preset_.right_fov;
    return EyeCamera(eye_position(which), pose_.orientation, fov, preset_.width,
                     preset_.height);
}

std::vector<HeadPoseSample> load_head_pose_trace(const std::string& path) {
    regular_file_exists(path);  // a device or FIFO would be read without end
    std::ifstream in(path);
    if (!in) throw Error(path, "cannot open head-pose trace");
    static const char* kColumns[8] = {"t", "px", "py", "pz", "qw", "qx", "qy", "qz"};

    std::vector<HeadPoseSample> trace;
    std::string line;
    int line_number = 0;
    bool seen_content = false;
    while (std::getline(in, line)) {
        ++line_number;
        std::string text = trim(line);
        if (text.empty() || text[0] == '#') continue;
        std::string where = path + ":" + std::to_string(line_number);
        auto fields = split_csv(text);
        bool first = !seen_content;
        seen_content = true;
        // The first content line may be a header: a line in which no field is a number.
        if (first && std::none_of(fields.begin(), fields.end(),
                                  [](const std::string& f) { return parse_number(f).has_value(); })) {
            continue;
        }
        if (fields.size() != 8) {
            throw Error(where, "expected 8 columns (t,px,py,pz,qw,qx,qy,qz), found " +
                                   std::to_string(fields.size()));
        }
        double v[8];
        for (int i = 0; i < 8; ++i) {
            auto value = parse_number(fields[size_t(i)]);
            if (!value) {
                throw Error(where, std::string("column '") + kColumns[i] + "' is not a number: '" +
                                       fields[size_t(i)] + "'");
            }
            if (!std::isfinite(*value)) {
                throw Error(where, std::string("column '") + kColumns[i] +
                                       "' is not finite: '" + fields[size_t(i)] + "'");
            }
            v[i] = *value;
        }
        if (!trace.empty() && !(v[0] > trace.back().time)) {
            throw Error(where, "time " + fields[0] + " does not increase (previous sample at " +
                                   std::to_string(trace.back().time) + ")");
        }
        glm::dquat q(v[4], v[5], v[6], v[7]);
        double norm = glm::length(q);
        if (!(norm > 1e-12)) throw Error(where, "orientation quaternion is zero");
        HeadPoseSample sample;
        sample.time = v[0];
        sample.pose.position = Vec3(float(v[1]), float(v[2]), float(v[3]));
        sample.pose.orientation = Quat(glm::normalize(q));
        trace.push_back(sample);
    }
    if (trace.empty()) throw Error(path, "head-pose trace has no samples");
    return trace;
}

HeadPose sample_head_pose(const std::vector<HeadPoseSample>& trace, double time) {
    if (trace.empty()) throw Error("sample_head_pose", "empty head-pose trace");
    if (!(time > trace.front().time)) return trace.front().pose;
    if (!(time < trace.back().time)) return trace.back().pose;
    auto next = std::upper_bound(trace.begin(), trace.end(), time,
                                 [](double t, const HeadPoseSample& s) { return t < s.time; });
    auto prev = next - 1;
    float a = float((time - prev->time) / (next->time - prev->time));
    HeadPose pose;
    pose.position = glm::mix(prev->pose.position, next->pose.position, a);
    // glm::slerp takes the shorter arc, so q and -q in a trace do not spin the head.
    pose.orientation = glm::normalize(glm::slerp(prev->pose.orientation, next->pose.orientation, a));
    return pose;
}

HeadPose trace_pose_relative_to(const HeadPose& base, const std::vector<HeadPoseSample>& trace,
                                double time, float scale) {
    if (trace.empty()) throw Error("trace_pose_relative_to", "empty head-pose trace");
    // Exactly the base up to the first sample (q0⁻¹·q0 is only nearly identity in floats).
    if (!(time > trace.front().time)) return base;
    const HeadPose& first = trace.front().pose;
    HeadPose now = sample_head_pose(trace, time);
    Quat inverse_first = glm::conjugate(first.orientation);  // unit quaternions
    Quat delta_rotation = inverse_first * now.orientation;
    Vec3 delta_position = inverse_first * (now.position - first.position);
    HeadPose pose;
    pose.orientation = glm::normalize(base.orientation * delta_rotation);
    pose.position = base.position + base.orientation * (scale * delta_position);
    return pose;
}

}  // namespace gilab
