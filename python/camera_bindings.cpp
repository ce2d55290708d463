// Cameras and the HMD rig: gilab.Camera (one pinhole eye), gilab.HmdRig, gilab.hmd(),
// head poses and head-pose traces.
#include <filesystem>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>
#include "core/scene/camera.hpp"
#include "core/util/error.hpp"
#include "core/scene/hmd.hpp"
#include "python/array_helpers.hpp"
#include "python/bindings.hpp"

namespace gilab::python {

using namespace pybind11::literals;

namespace {

Eye eye_from(const std::string& name) {
    if (name == "left") return Eye::Left;
    if (name == "right") return Eye::Right;
    throw Error("eye", "'" + name + "' is not an eye; give \"left\" or \"right\"");
}

py::tuple fov_tuple(const FrustumTangents& f) { return py::make_tuple(f.left, f.right, f.bottom, f.top); }

FrustumTangents fov_from(const py::handle& value) {
    auto t = value.cast<std::vector<float>>();
    if (t.size() != 4) throw Error("fov", "expected 4 tangents (left, right, bottom, top)");
    FrustumTangents f{t[0], t[1], t[2], t[3]};
    if (!(f.left < f.right && f.bottom < f.top))
        throw Error("fov", "tangents must satisfy left < right and bottom < top");
    return f;
}

py::dict preset_dict(const HmdPreset& p) {
    return py::dict("name"_a = p.name, "display_name"_a = p.display_name, "width"_a = p.width, "height"_a = p.height,
                    "ipd"_a = p.ipd, "left_fov"_a = fov_tuple(p.left_fov), "right_fov"_a = fov_tuple(p.right_fov),
                    "source"_a = p.source);
}

HeadPose pose_from(const py::handle& position, const py::handle& orientation) {
    return {vec3_from(position, "position"), quat_from(orientation, "orientation")};
}

// A loaded trace, so Python code can step a rig along it as `gilab render --head-trace` does.
struct HeadTrace {
    std::string path;
    std::vector<HeadPoseSample> samples;
};

}  // namespace

void register_camera_bindings(py::module_& m) {
    py::class_<EyeCamera>(m, "Camera", R"doc(A pinhole camera with an asymmetric frustum: one eye of an HMD, or a mono camera.

Camera space is +X right, +Y up, looking down −Z. The frustum is given as the
tangents of its four half angles (left, right, bottom, top), signed: a symmetric
90° frustum is (-1, 1, -1, 1). Orientation quaternions are (w, x, y, z).
Pixel (i, j) covers [i, i+1) × [j, j+1); row 0 is the top row.
)doc")
        .def(py::init([](const py::object& position, const py::object& orientation, const py::object& fov, int width,
                         int height) {
                 check_resolution(width, height);
                 return EyeCamera(vec3_from(position, "position"), quat_from(orientation, "orientation"), fov_from(fov),
                                  width, height);
             }),
             "position"_a, "orientation"_a, "fov"_a, "width"_a, "height"_a,
             "A camera at `position` turned by `orientation` (w, x, y, z), frustum tangents `fov`.")
        .def_static(
            "look_at",
            [](const py::object& eye, const py::object& target, const py::object& up, float fov, int width, int height) {
                check_resolution(width, height);
                return EyeCamera::look_at(vec3_from(eye, "eye"), vec3_from(target, "target"), vec3_from(up, "up"), fov,
                                          width, height);
            },
            "eye"_a, "target"_a, "up"_a = py::make_tuple(0, 1, 0), "vertical_fov"_a = 45.0f, "width"_a = 512,
            "height"_a = 512, "A mono camera looking from `eye` at `target`, vertical field of view in degrees.")
        .def_property_readonly("position", [](const EyeCamera& c) { return to_tuple(c.position()); })
        .def_property_readonly("orientation", [](const EyeCamera& c) { return to_tuple(c.orientation()); },
                               "(w, x, y, z).")
        .def_property_readonly("fov", [](const EyeCamera& c) { return fov_tuple(c.fov()); },
                               "Frustum tangents (left, right, bottom, top).")
        .def_property_readonly("width", &EyeCamera::width)
        .def_property_readonly("height", &EyeCamera::height)
        .def_property_readonly("forward", [](const EyeCamera& c) { return to_tuple(c.forward()); },
                               "World direction the camera looks along.")
        .def(
            "generate_ray",
            [](const EyeCamera& c, float px, float py) {
                Ray r = c.generate_ray(px, py);
                return py::make_tuple(to_tuple(r.origin), to_tuple(r.direction));
            },
            "px"_a, "py"_a, "(origin, unit direction) of the ray through continuous pixel coordinate (px, py).")
        .def(
            "project",
            [](const EyeCamera& c, const py::object& point) -> py::object {
                auto p = c.project(vec3_from(point, "point"));
                if (!p) return py::none();
                return py::make_tuple(p->x, p->y);
            },
            "point"_a, "Continuous pixel coordinate of a world point, or None behind the camera.")
        .def(
            "pixel_of",
            [](const EyeCamera& c, const py::object& point) -> py::object {
                auto p = c.pixel_of(vec3_from(point, "point"));
                if (!p) return py::none();
                return py::make_tuple(p->x, p->y);
            },
            "point"_a, "Integer pixel (x, y) holding a world point, or None outside the image.")
        .def("view_matrix", [](const EyeCamera& c) { return matrix_to_numpy(c.view_matrix()); },
             "World → camera matrix, 4×4 indexed [row, column].")
        .def(
            "projection_matrix",
            [](const EyeCamera& c, float near_plane, float far_plane) {
                return matrix_to_numpy(c.projection_matrix(near_plane, far_plane));
            },
            "near"_a, "far"_a, "OpenGL off-axis projection matrix, 4×4 indexed [row, column].")
        .def("__repr__", [](const EyeCamera& c) {
            return "<gilab.Camera " + std::to_string(c.width()) + "×" + std::to_string(c.height()) + ">";
        });

    py::class_<HeadPose>(m, "HeadPose", "A head position and orientation (w, x, y, z).")
        .def(py::init([](const py::object& position, const py::object& orientation) {
                 return pose_from(position, orientation);
             }),
             "position"_a = py::make_tuple(0, 0, 0), "orientation"_a = py::make_tuple(1, 0, 0, 0))
        .def_property(
            "position", [](const HeadPose& p) { return to_tuple(p.position); },
            [](HeadPose& p, const py::object& v) { p.position = vec3_from(v, "position"); })
        .def_property(
            "orientation", [](const HeadPose& p) { return to_tuple(p.orientation); },
            [](HeadPose& p, const py::object& v) { p.orientation = quat_from(v, "orientation"); })
        .def("__repr__", [](const HeadPose& p) {
            return "<gilab.HeadPose position=" + py::repr(to_tuple(p.position)).cast<std::string>() +
                   " orientation=" + py::repr(to_tuple(p.orientation)).cast<std::string>() + ">";
        });

    py::class_<HmdRig>(m, "HmdRig", R"doc(A head-mounted display: a head pose and two eyes ±IPD/2 along the head's +X axis,
each with the headset's own asymmetric frustum and per-eye resolution.

Make one with gilab.hmd("vive"). Pass it as ``camera=`` to gilab.render for a
stereo pair rendered in one call (so techniques can reuse work between eyes).
)doc")
        .def(py::init([](const std::string& preset) { return HmdRig(find_hmd_preset(preset)); }), "preset"_a)
        .def_property(
            "pose", [](const HmdRig& r) { return r.pose(); }, &HmdRig::set_pose, "The head pose (a copy).")
        .def(
            "set_pose",
            [](HmdRig& r, const py::object& position, const py::object& orientation) {
                r.set_pose(pose_from(position, orientation));
            },
            "position"_a, "orientation"_a = py::make_tuple(1, 0, 0, 0), "Moves the head.")
        .def_property(
            "ipd", [](const HmdRig& r) { return r.preset().ipd; },
            [](HmdRig& r, float ipd) {
                if (!(ipd >= 0 && ipd < 1)) throw Error("ipd", std::to_string(ipd) + " is out of range: give metres in [0, 1)");
                r.set_ipd(ipd);
            },
            "Inter-pupillary distance in metres (scene units).")
        .def_property(
            "resolution", [](const HmdRig& r) { return py::make_tuple(r.preset().width, r.preset().height); },
            [](HmdRig& r, std::pair<int, int> size) {
                check_resolution(size.first, size.second);
                r.set_resolution(size.first, size.second);
            },
            "Per-eye (width, height) in pixels.")
        .def_property_readonly("preset", [](const HmdRig& r) { return preset_dict(r.preset()); },
                               "The headset's figures: name, size, IPD, per-eye frustum tangents, source.")
        .def("eye", [](const HmdRig& r, const std::string& which) { return r.eye(eye_from(which)); }, "which"_a,
             "The camera of the \"left\" or \"right\" eye at the current pose.")
        .def_property_readonly("left", [](const HmdRig& r) { return r.eye(Eye::Left); }, "The left eye's camera.")
        .def_property_readonly("right", [](const HmdRig& r) { return r.eye(Eye::Right); }, "The right eye's camera.")
        .def(
            "eye_position", [](const HmdRig& r, const std::string& which) { return to_tuple(r.eye_position(eye_from(which))); },
            "which"_a, "World position of one eye.")
        .def("__repr__", [](const HmdRig& r) {
            return "<gilab.HmdRig " + r.preset().name + " " + std::to_string(r.preset().width) + "×" +
                   std::to_string(r.preset().height) + " per eye>";
        });

    m.def(
        "hmd", [](const std::string& preset) { return HmdRig(find_hmd_preset(preset)); }, "preset"_a = "vive", R"doc(An HMD rig with a headset preset (see gilab.hmd_presets()), head at the origin
looking down −Z. gilab.Error lists the presets when the name is unknown.
)doc");
    m.def(
        "hmd_presets",
        [] {
            py::list list;
            for (const auto& p : hmd_presets()) list.append(preset_dict(p));
            return list;
        },
        "The built-in headset presets as dicts (name, display_name, width, height, ipd, fovs, source).");

    py::class_<HeadTrace>(m, "HeadTrace", "A head-pose trace (CSV t,px,py,pz,qw,qx,qy,qz).")
        .def_readonly("path", &HeadTrace::path)
        .def("__len__", [](const HeadTrace& t) { return t.samples.size(); })
        .def_property_readonly("duration", [](const HeadTrace& t) {
            return t.samples.back().time - t.samples.front().time;
        }, "Seconds from the first sample to the last.")
        .def(
            "sample", [](const HeadTrace& t, double time) { return sample_head_pose(t.samples, time); }, "time"_a,
            "The pose at `time` (linear in position, slerp in orientation, clamped at the ends).")
        .def(
            "relative_to",
            [](const HeadTrace& t, const HeadPose& base, double time, float scale) {
                return trace_pose_relative_to(base, t.samples, t.samples.front().time + time, scale);
            },
            "base"_a, "time"_a, "scale"_a = 1.0f,
            "The trace's motion since its first sample, replayed from `base` (as `gilab render --head-trace`); "
            "`time` counts from the first sample.");
    m.def(
        "load_head_trace",
        [](const std::filesystem::path& path) { return HeadTrace{path.string(), load_head_pose_trace(path.string())}; },
        "path"_a,
        "Reads a head-pose trace CSV (gilab.Error naming the file and line on bad input).");
}

}  // namespace gilab::python
