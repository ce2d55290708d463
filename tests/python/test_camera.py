"""Cameras and the HMD rig through Python against the CLI's presets and the geometry the
C++ camera defines."""
import math

import numpy as np
import pytest

import gilab


def test_presets_match_gilab_list(run_cli):
    listed = run_cli("list", "hmds").stdout
    for preset in gilab.hmd_presets():
        assert f"  {preset['name']} — {preset['display_name']}, {preset['width']}×{preset['height']} per eye" in listed


def test_rig_eyes_are_ipd_apart_and_follow_the_pose():
    rig = gilab.hmd("vive")
    assert rig.resolution == (1080, 1200) and rig.ipd == pytest.approx(0.063)
    left, right = np.array(rig.eye_position("left")), np.array(rig.eye_position("right"))
    assert np.linalg.norm(right - left) == pytest.approx(0.063) and right[0] > left[0]
    half = math.sqrt(0.5)
    rig.set_pose((1, 2, 3), (half, 0, half, 0))  # 90° about +Y: the head's +X becomes −Z
    left, right = np.array(rig.left.position), np.array(rig.right.position)
    assert np.allclose((left + right) / 2, (1, 2, 3))
    assert np.allclose(right - left, (0, 0, -0.063), atol=1e-6)
    assert rig.left.fov == pytest.approx(rig.preset["left_fov"])
    rig.ipd = 0.07
    rig.resolution = (64, 48)
    assert rig.left.width == 64 and rig.right.height == 48


def test_camera_rays_project_back_to_their_pixel():
    camera = gilab.Camera.look_at((0, 0, 3), (0, 0, 0), vertical_fov=60, width=40, height=30)
    origin, direction = camera.generate_ray(10.5, 20.5)
    point = np.array(origin) + 2.0 * np.array(direction)
    assert camera.project(point) == pytest.approx((10.5, 20.5), abs=1e-3)
    assert camera.pixel_of(point) == (10, 20)
    assert camera.project((0, 0, 10)) is None  # behind
    assert camera.view_matrix().shape == (4, 4)
    assert np.allclose(camera.view_matrix() @ np.array([0, 0, 0, 1.0]), (0, 0, -3, 1), atol=1e-6)


def test_head_trace(tmp_path):
    trace = tmp_path / "trace.csv"
    trace.write_text("t,px,py,pz,qw,qx,qy,qz\n0,0,0,0,1,0,0,0\n1,1,0,0,1,0,0,0\n")
    loaded = gilab.load_head_trace(trace)
    assert len(loaded) == 2 and loaded.duration == 1
    assert loaded.sample(0.5).position == pytest.approx((0.5, 0, 0))
    moved = loaded.relative_to(gilab.HeadPose((0, 1, 0)), 1.0, scale=2.0)
    assert moved.position == pytest.approx((2, 1, 0))


def test_bad_camera_input_raises(tmp_path):
    with pytest.raises(gilab.Error, match="nope"):
        gilab.hmd("nope")
    with pytest.raises(gilab.Error, match="eye"):
        gilab.hmd().eye("middle")
    with pytest.raises(gilab.Error, match="ipd"):
        gilab.hmd().ipd = 2.0
    with pytest.raises(gilab.Error, match="orientation"):
        gilab.HeadPose((0, 0, 0), (0, 0, 0, 0))
    with pytest.raises(gilab.Error, match="position"):
        gilab.HeadPose((0, 0))
    with pytest.raises(gilab.Error):
        gilab.Camera.look_at((0, 0, 1), (0, 0, 0), width=0, height=4)
    (tmp_path / "bad.csv").write_text("t,px\n0,zero\n")
    with pytest.raises(gilab.Error, match="bad.csv"):
        gilab.load_head_trace(tmp_path / "bad.csv")
