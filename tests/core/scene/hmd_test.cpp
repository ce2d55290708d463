#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <functional>
#include <string>
#include <vector>
#include "core/util/error.hpp"
#include "core/scene/hmd.hpp"
#include "tests/test_support.hpp"

namespace gilab {
namespace {

using test::error_of;

std::string write_trace(const std::string& dir_name, const std::string& file,
                        const std::string& text) {
    auto path = test::temp_dir(dir_name) / file;
    std::ofstream(path) << text;
    return path.string();
}

float yaw_degrees(const Quat& q) {
    Vec3 f = q * Vec3(0, 0, -1);
    return glm::degrees(std::atan2(-f.x, -f.z));
}

TEST(HmdPresets, RealHeadsetsWithSaneFigures) {
    const auto& vive = find_hmd_preset("vive");
    EXPECT_EQ(vive.display_name, "HTC Vive");
    EXPECT_EQ(vive.width, 1080);
    EXPECT_EQ(vive.height, 1200);
    EXPECT_FLOAT_EQ(vive.ipd, 0.063f);
    EXPECT_FLOAT_EQ(vive.left_fov.left, -1.3975f);
    const auto& quest = find_hmd_preset("quest2");
    EXPECT_EQ(quest.width, 1832);
    EXPECT_EQ(quest.height, 1920);
    EXPECT_GE(hmd_presets().size(), 2u);
    for (const auto& p : hmd_presets()) {
        SCOPED_TRACE(p.name);
        EXPECT_FALSE(p.display_name.empty());
        EXPECT_NE(p.source.find("http"), std::string::npos) << "source must say where from";
        EXPECT_GT(p.width, 0);
        EXPECT_GT(p.height, 0);
        EXPECT_GT(p.ipd, 0.05f);
        EXPECT_LT(p.ipd, 0.08f);
        for (const auto* f : {&p.left_fov, &p.right_fov}) {
            EXPECT_LT(f->left, 0.0f);
            EXPECT_GT(f->right, 0.0f);
            EXPECT_LT(f->bottom, 0.0f);
            EXPECT_GT(f->top, 0.0f);
            float horizontal = glm::degrees(std::atan(-f->left) + std::atan(f->right));
            float vertical = glm::degrees(std::atan(-f->bottom) + std::atan(f->top));
            EXPECT_GT(horizontal, 80.0f);
            EXPECT_LT(horizontal, 120.0f);
            EXPECT_GT(vertical, 80.0f);
            EXPECT_LT(vertical, 125.0f);
        }
        // Lookup is by name, case-insensitively.
        EXPECT_EQ(&find_hmd_preset(p.name), &p);
    }
    EXPECT_EQ(&find_hmd_preset("VIVE"), &vive);
}

TEST(HmdPresets, UnknownPresetListsKnownNames) {
    std::string message = error_of([] { find_hmd_preset("rift-dk0"); });
    EXPECT_NE(message.find("'rift-dk0'"), std::string::npos) << message;
    for (const auto& p : hmd_presets()) {
        EXPECT_NE(message.find(p.name), std::string::npos) << message;
    }
}

TEST(HmdRig, ResolutionCanBeChangedButMustBeSane) {
    HmdRig rig(find_hmd_preset("vive"));
    rig.set_resolution(108, 120);
    EXPECT_EQ(rig.eye(Eye::Left).width(), 108);
    EXPECT_EQ(rig.eye(Eye::Right).height(), 120);
    EXPECT_THROW(rig.set_resolution(0, 120), Error);
    EXPECT_THROW(rig.set_resolution(100, -3), Error);
    EXPECT_EQ(rig.preset().width, 108);  // unchanged by the failed calls
    HmdPreset broken;
    broken.name = "broken";
    EXPECT_THROW(HmdRig{broken}, Error);
}

TEST(HeadPoseTrace, ParsesRowsWithHeaderAndNormalizesQuaternions) {
    auto path = write_trace("hmd_trace_ok", "trace.csv",
                            "# comment\n"
                            "t,px,py,pz,qw,qx,qy,qz\n"
                            "0.0, 1, 2, 3, 2, 0, 0, 0\n"
                            "\n"
                            "0.5,4,5,6,0,0,3,0\n"
                            "1.25,7,8,9,1,1,1,1\n");
    auto trace = load_head_pose_trace(path);
    ASSERT_EQ(trace.size(), 3u);
    EXPECT_DOUBLE_EQ(trace[1].time, 0.5);
    EXPECT_EQ(trace[1].pose.position, Vec3(4, 5, 6));
    EXPECT_EQ(trace[0].pose.orientation, Quat(1, 0, 0, 0));
    EXPECT_EQ(trace[1].pose.orientation, Quat(0, 0, 1, 0));
    for (const auto& s : trace) EXPECT_NEAR(glm::length(s.pose.orientation), 1.0f, 1e-6f);
    EXPECT_NEAR(trace[2].pose.orientation.x, 0.5f, 1e-6f);

    // Without a header too.
    auto bare = write_trace("hmd_trace_bare", "bare.csv", "0,0,0,0,1,0,0,0\n1,1,0,0,1,0,0,0\n");
    EXPECT_EQ(load_head_pose_trace(bare).size(), 2u);
}

TEST(HeadPoseTrace, ErrorsNameFileAndLine) {
    struct Case {
        const char* file;
        const char* text;
        const char* line;  // expected "file:line"
        const char* what;
    };
    const Case cases[] = {
        {"columns.csv", "t,px,py,pz,qw,qx,qy,qz\n0,0,0,0,1,0,0,0\n1,0,0,0,1,0,0\n", ":3", "8 columns"},
        {"word.csv", "0,0,0,0,1,0,0,0\n1,0,zero,0,1,0,0,0\n", ":2", "'py' is not a number"},
        {"nan.csv", "t,px,py,pz,qw,qx,qy,qz\n0,0,0,0,1,0,0,0\n\n1,0,0,nan,1,0,0,0\n", ":4", "not finite"},
        {"inf.csv", "0,0,0,0,1,0,0,inf\n", ":1", "not finite"},
        {"time.csv", "0,0,0,0,1,0,0,0\n1,0,0,0,1,0,0,0\n1,0,0,0,1,0,0,0\n", ":3", "does not increase"},
        {"back.csv", "0,0,0,0,1,0,0,0\n2,0,0,0,1,0,0,0\n1.5,0,0,0,1,0,0,0\n", ":3", "does not increase"},
        {"zero.csv", "0,0,0,0,1,0,0,0\n1,0,0,0,0,0,0,0\n", ":2", "quaternion is zero"},
        {"late_header.csv", "0,0,0,0,1,0,0,0\nt,px,py,pz,qw,qx,qy,qz\n", ":2", "not a number"},
    };
    for (const auto& c : cases) {
        auto path = write_trace("hmd_trace_errors", c.file, c.text);
        std::string message = error_of([&] { load_head_pose_trace(path); });
        EXPECT_NE(message.find(path + c.line + ":"), std::string::npos) << c.file << ": " << message;
        EXPECT_NE(message.find(c.what), std::string::npos) << c.file << ": " << message;
    }
    auto empty = write_trace("hmd_trace_empty", "empty.csv", "t,px,py,pz,qw,qx,qy,qz\n");
    EXPECT_NE(error_of([&] { load_head_pose_trace(empty); }).find("no samples"), std::string::npos);
    std::string missing = error_of([] { load_head_pose_trace("/nonexistent/trace.csv"); });
    EXPECT_NE(missing.find("/nonexistent/trace.csv"), std::string::npos) << missing;
    // /dev/zero read without end.
    const std::string device = error_of([] { load_head_pose_trace("/dev/zero"); });
    EXPECT_NE(device.find("/dev/zero: is a character device, not a regular file"), std::string::npos) << device;
}

TEST(HeadPoseTrace, SamplingInterpolatesAndClamps) {
    std::vector<HeadPoseSample> trace(3);
    trace[0].time = 1.0;
    trace[0].pose.position = Vec3(0, 0, 0);
    trace[1].time = 2.0;
    trace[1].pose.position = Vec3(2, 4, -6);
    trace[1].pose.orientation = glm::angleAxis(glm::radians(90.0f), Vec3(0, 1, 0));
    trace[2].time = 4.0;
    trace[2].pose.position = Vec3(2, 4, -6);
    // The same rotation written as -q must not make the head spin the long way round.
    trace[2].pose.orientation = -trace[1].pose.orientation;

    HeadPose mid = sample_head_pose(trace, 1.5);
    EXPECT_LT(glm::length(mid.position - Vec3(1, 2, -3)), 1e-6f);
    EXPECT_NEAR(yaw_degrees(mid.orientation), 45.0f, 1e-3f);
    HeadPose quarter = sample_head_pose(trace, 1.25);
    EXPECT_NEAR(yaw_degrees(quarter.orientation), 22.5f, 1e-3f);
    EXPECT_NEAR(yaw_degrees(sample_head_pose(trace, 3.0).orientation), 90.0f, 1e-3f);
    // Exact at the samples, clamped outside.
    EXPECT_EQ(sample_head_pose(trace, 2.0).position, trace[1].pose.position);
    EXPECT_EQ(sample_head_pose(trace, -5.0).position, trace[0].pose.position);
    EXPECT_EQ(sample_head_pose(trace, 50.0).position, trace[2].pose.position);
    EXPECT_NEAR(glm::length(sample_head_pose(trace, 1.7).orientation), 1.0f, 1e-6f);
    EXPECT_THROW(sample_head_pose({}, 0.0), Error);
}

TEST(HeadPoseTrace, ExampleTraceInTheRepository) {
    std::string path = std::string(GILAB_SOURCE_DIR) + "/scenes/traces/head_turn.csv";
    auto trace = load_head_pose_trace(path);
    ASSERT_EQ(trace.size(), 61u);
    EXPECT_DOUBLE_EQ(trace.front().time, 0.0);
    EXPECT_NEAR(trace.back().time, 2.0, 1e-9);
    EXPECT_NEAR(yaw_degrees(trace.front().pose.orientation), -15.0f, 0.05f);
    EXPECT_NEAR(yaw_degrees(trace.back().pose.orientation), 15.0f, 0.05f);
    EXPECT_NEAR(yaw_degrees(sample_head_pose(trace, 1.0).orientation), 0.0f, 0.05f);
    EXPECT_NEAR(sample_head_pose(trace, 1.0).position.x, 0.0f, 1e-4f);
    // A gentle turn: no two consecutive samples differ by more than 2 degrees.
    for (size_t i = 1; i < trace.size(); ++i) {
        float angle = glm::degrees(2.0f * std::acos(std::min(1.0f, std::abs(glm::dot(
                                           trace[i].pose.orientation, trace[i - 1].pose.orientation)))));
        EXPECT_LT(angle, 2.0f);
    }
}

Quat yaw(float degrees) { return glm::angleAxis(glm::radians(degrees), Vec3(0, 1, 0)); }

// Angle in degrees between two orientations (q and -q are the same rotation); atan2 stays
// accurate for tiny angles, where acos of a dot product near 1 does not.
float angle_between(const Quat& a, const Quat& b) {
    Quat d = glm::conjugate(a) * b;
    return glm::degrees(2.0f * std::atan2(glm::length(Vec3(d.x, d.y, d.z)), std::abs(d.w)));
}

HeadPoseSample sample_at(double time, Vec3 position, Quat orientation) {
    HeadPoseSample s;
    s.time = time;
    s.pose.position = position;
    s.pose.orientation = orientation;
    return s;
}

TEST(TraceRelativePose, IdentityAtTheFirstSample) {
    // The trace starts away from the origin, turned and at a non-zero time: none of it shows.
    std::vector<HeadPoseSample> trace = {
        sample_at(0.5, Vec3(1, 2, 3), glm::angleAxis(glm::radians(30.0f), glm::normalize(Vec3(1, 2, 0.5f)))),
        sample_at(1.5, Vec3(4, 0, -1), yaw(-70.0f)),
    };
    HeadPose base{Vec3(5, -1, 2), glm::angleAxis(glm::radians(140.0f), glm::normalize(Vec3(0.3f, 1, -0.2f)))};
    for (double t : {0.5, 0.0, -3.0}) {  // before the trace starts it is clamped to its first sample
        HeadPose pose = trace_pose_relative_to(base, trace, t);
        EXPECT_EQ(pose.position, base.position) << t;
        EXPECT_EQ(pose.orientation, base.orientation) << t;
    }
    // Just after the first sample the pose is still (continuously) close to the base.
    HeadPose soon = trace_pose_relative_to(base, trace, 0.5 + 1e-6);
    EXPECT_LT(glm::length(soon.position - base.position), 1e-4f);
    EXPECT_LT(angle_between(soon.orientation, base.orientation), 0.05f);
    // Later in the trace the pose does change.
    HeadPose later = trace_pose_relative_to(base, trace, 1.5);
    EXPECT_GT(glm::length(later.position - base.position), 1.0f);
    EXPECT_GT(angle_between(later.orientation, base.orientation), 10.0f);
}

TEST(TraceRelativePose, PureYawTurnsTheBaseByTheSameAngle) {
    std::vector<HeadPoseSample> trace = {
        sample_at(0, Vec3(0, 1.6f, 0), yaw(10.0f)),
        sample_at(1, Vec3(0, 1.6f, 0), yaw(40.0f)),
    };
    // A base turned 180 degrees and pitched down: the 30 degree yaw is about the head's own up.
    Quat base_orientation = yaw(180.0f) * glm::angleAxis(glm::radians(-20.0f), Vec3(1, 0, 0));
    HeadPose base{Vec3(0.5f, 0.3f, -1.8f), base_orientation};
    HeadPose end = trace_pose_relative_to(base, trace, 1.0);
    EXPECT_LT(angle_between(end.orientation, base_orientation * yaw(30.0f)), 0.05f);
    EXPECT_NEAR(angle_between(end.orientation, base_orientation), 30.0f, 0.05f);
    EXPECT_LT(glm::length(end.position - base.position), 1e-6f);  // the trace did not move
    HeadPose mid = trace_pose_relative_to(base, trace, 0.5);
    EXPECT_LT(angle_between(mid.orientation, base_orientation * yaw(15.0f)), 0.05f);
    EXPECT_NEAR(glm::length(end.orientation), 1.0f, 1e-6f);
}

TEST(TraceRelativePose, TranslationIsExpressedInTheBaseFrameAndScaled) {
    // In tracking space the head faces -X (yawed 90 degrees) and steps 0.2 m forward, along
    // -X; the base faces +Z, so in the scene the head steps 0.2 along +Z.
    std::vector<HeadPoseSample> trace = {
        sample_at(0, Vec3(3, 1.7f, 2), yaw(90.0f)),
        sample_at(2, Vec3(2.8f, 1.7f, 2), yaw(90.0f)),
    };
    HeadPose base{Vec3(1, 1, 1), yaw(180.0f)};
    HeadPose moved = trace_pose_relative_to(base, trace, 2.0);
    EXPECT_LT(glm::length(moved.position - Vec3(1, 1, 1.2f)), 1e-5f);
    EXPECT_LT(angle_between(moved.orientation, base.orientation), 0.05f);
    // Scale converts trace metres into scene units: 2.5 units per metre, or none at all.
    EXPECT_LT(glm::length(trace_pose_relative_to(base, trace, 2.0, 2.5f).position - Vec3(1, 1, 1.5f)), 1e-5f);
    EXPECT_LT(glm::length(trace_pose_relative_to(base, trace, 1.0, 0.5f).position - Vec3(1, 1, 1.05f)), 1e-5f);
    EXPECT_LT(glm::length(trace_pose_relative_to(base, trace, 2.0, 0.0f).position - base.position), 1e-6f);
    // A sideways step to the head's right stays a step to the right of the base.
    std::vector<HeadPoseSample> right = {
        sample_at(0, Vec3(0), yaw(90.0f)),
        sample_at(1, yaw(90.0f) * Vec3(0.1f, 0, 0), yaw(90.0f)),
    };
    HeadPose stepped = trace_pose_relative_to(base, right, 1.0);
    EXPECT_LT(glm::length(stepped.position - (base.position + base.orientation * Vec3(0.1f, 0, 0))), 1e-5f);
    EXPECT_LT(glm::length(stepped.position - Vec3(0.9f, 1, 1)), 1e-5f);
}

TEST(TraceRelativePose, EmptyTraceIsAnError) {
    std::string message = error_of([] { trace_pose_relative_to(HeadPose{}, {}, 0.0); });
    EXPECT_NE(message.find("empty head-pose trace"), std::string::npos) << message;
}

}  // namespace
}  // namespace gilab
