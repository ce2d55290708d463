"""gilab.render against `gilab render`: the same scene, camera, settings and seed must
give bit-identical layers, for mono and stereo, path tracer and photon mapping."""
import numpy as np
import pytest

import gilab

# Provenance that may differ between two runs of the same render.
RUN_SPECIFIC = {"render_time_seconds", "git_revision", "gitRevision"}


def assert_films_identical(python_film, exr_film, ignore=()):
    assert python_film.layer_names == exr_film.layer_names
    for name in python_film.layer_names:
        a, b = python_film[name], exr_film[name]
        assert a.shape == b.shape and a.dtype == b.dtype == np.float32, name
        # Bit for bit, NaNs included.
        assert np.array_equal(a.view(np.uint32), b.view(np.uint32)), f"layer {name} differs"
    strip = lambda m: {k: v for k, v in m.items() if k not in RUN_SPECIFIC and k not in ignore}
    assert strip(python_film.metadata) == strip(exr_film.metadata)


def test_path_mono_matches_cli(tmp_path, run_cli, cornell):
    run_cli("render", "cornell", "-t", "path", "-W", 40, "-H", 32, "--spp", 3, "--seed", 11, "--set", "max_depth=5",
            "-o", tmp_path / "path")
    result = gilab.render(cornell, "path", width=40, height=32, spp=3, seed=11, settings={"max_depth": 5}, threads=2)
    assert result.views == ["mono"] and not result.stereo
    assert_films_identical(result.film, gilab.read_exr(tmp_path / "path.exr"))


def test_photon_mono_matches_cli(tmp_path, run_cli, cornell):
    run_cli("render", "cornell", "-t", "photon", "-W", 32, "-H", 32, "--seed", 5, "--set", "photons=8192",
            "--set", "radius=0.08", "--set", "gather=knn", "--set", "k=16", "-o", tmp_path / "photon")
    result = gilab.render(cornell, "photon", width=32, height=32, seed=5,
                          settings={"photons": 8192, "radius": 0.08, "gather": "knn", "k": 16})
    assert_films_identical(result.film, gilab.read_exr(tmp_path / "photon.exr"))
    assert result.settings == {"photons": 8192, "radius": 0.08, "gather": "knn", "k": 16, "seed": 5}


def test_photon_stereo_matches_cli(tmp_path, run_cli, cornell):
    run_cli("render", "cornell", "-t", "photon", "--hmd", "vive", "-W", 24, "-H", 28, "--seed", 2,
            "--set", "photons=4096", "--set", "stereo_reuse=true", "-o", tmp_path / "stereo")
    result = gilab.render(cornell, "photon", hmd="vive", width=24, height=28, seed=2,
                          settings={"photons": 4096, "stereo_reuse": True})
    assert result.stereo and result.views == ["left", "right"]
    assert_films_identical(result.left, gilab.read_exr(tmp_path / "stereo.exr", "left"))
    # A multi-view EXR keeps the left film's metadata only.
    assert_films_identical(result.right, gilab.read_exr(tmp_path / "stereo.exr", "right"), ignore={"view"})
    assert not np.array_equal(result.left["color"], result.right["color"])  # two different eyes


def test_explicit_cameras_equal_the_default_views(cornell):
    default = gilab.render(cornell, "path", width=20, height=16, spp=1)
    explicit = gilab.render(cornell, "path", camera=cornell.camera_view(20, 16), spp=1)
    assert np.array_equal(default["color"], explicit["color"])

    rig = gilab.hmd("vive")
    rig.pose = cornell.head_pose()
    rig.resolution = (12, 10)
    by_name = gilab.render(cornell, "path", hmd="vive", width=12, height=10, spp=1)
    by_rig = gilab.render(cornell, "path", camera=rig, spp=1)
    for eye in ("left", "right"):
        assert np.array_equal(by_name.images[eye]["color"], by_rig.images[eye]["color"])
    assert by_rig.left.metadata["hmd"] == "vive"


def test_layers_shapes_dtypes_and_stats(cornell):
    result = gilab.render(cornell, "path", width=10, height=6, spp=1)
    assert result["color"].shape == (6, 10, 3)
    assert result["depth"].shape == (6, 10)
    assert all(a.dtype == np.float32 for a in result.film.layers.values())
    assert np.isfinite(result["color"]).all() and result["color"].max() > 0
    stats = result.stats
    assert isinstance(stats, dict) and stats["samples"] == 60 and stats["render_ms"] >= 0
    assert result.technique == "path" and result.render_seconds >= 0


def test_layers_are_views_that_keep_the_film_alive(cornell):
    result = gilab.render(cornell, "path", width=8, height=8, spp=1)
    film = result.film
    color = film["color"]
    assert np.shares_memory(color, film["color"])  # no copy per access
    expected = color.copy()
    del result, film
    import gc

    gc.collect()
    assert np.array_equal(color, expected)  # the array still owns a live film


def test_same_seed_same_image_other_seed_other_image(cornell):
    a = gilab.render(cornell, "path", width=16, height=16, spp=1, seed=1)["color"]
    b = gilab.render(cornell, "path", width=16, height=16, spp=1, seed=1, threads=1)["color"]
    c = gilab.render(cornell, "path", width=16, height=16, spp=1, seed=2)["color"]
    assert np.array_equal(a, b)
    assert not np.array_equal(a, c)


@pytest.mark.parametrize(
    "kwargs, message",
    [
        ({"settings": {"sp": 4}}, "unknown setting 'sp'"),
        ({"technique": "nope"}, "nope"),
        ({"hmd": "no-such-headset"}, "no-such-headset"),
        ({"width": 16, "height": None}, "give both or neither"),
        ({"width": 0}, "0"),
        ({"technique": "vct", "spp": 4}, "--spp"),
        ({"settings": {"spp": "many"}}, "spp"),
        ({"camera": "front", "width": None, "height": None}, "camera"),
        ({"threads": -1}, "thread"),
    ],
)
def test_bad_render_requests_raise_with_the_cpp_message(cornell, kwargs, message):
    arguments = {"technique": "path", "width": 8, "height": 8, **kwargs}
    with pytest.raises(gilab.Error, match=message):
        gilab.render(cornell, **arguments)


def test_error_is_a_value_error():
    assert issubclass(gilab.Error, ValueError)


def test_the_gil_is_released_while_rendering(cornell):
    import threading

    done = threading.Event()
    worker = threading.Thread(target=lambda: (gilab.render(cornell, "path", width=96, height=96, spp=16, threads=1),
                                              done.set()))
    ticks = 0
    worker.start()
    while not done.is_set() and worker.is_alive():
        ticks += 1  # runs only while the render does not hold the GIL
    worker.join()
    assert ticks > 1000


def test_settings_schemas_are_listed_and_in_render_help():
    """gilab.settings gives each technique's declared settings; help(gilab.render) shows them."""
    names = [t["name"] for t in gilab.techniques()]
    for name in names:
        specs = gilab.settings(name)
        assert specs, name
        for spec in specs:
            assert {"key", "type", "default", "range", "unit", "description", "quality_knob"} <= spec.keys()
            assert spec["key"] in gilab.render.__doc__, (name, spec["key"])
        assert name + ": " in gilab.render.__doc__
    photon = {s["key"]: s for s in gilab.settings("photon")}
    assert photon["photons"]["default"] == 65536 and photon["photons"]["quality_knob"]
    assert photon["photon_map"]["choices"] == ["hash_grid", "kd_tree", "nanoflann"]
    assert photon["radius"]["default"] is None and "diagonal" in photon["radius"]["derived_default"]
    assert [s["key"] for s in gilab.settings("path") if s["quality_knob"]] == ["spp"]
    with pytest.raises(gilab.Error, match="unknown technique"):
        gilab.settings("nope")
