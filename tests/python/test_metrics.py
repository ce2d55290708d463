"""relMSE, SSIM and FLIP on NumPy arrays against the figures `gilab compare` computes in
C++ for the same two images, plus the metrics' defining properties."""
import json

import numpy as np
import pytest

import gilab


@pytest.fixture(scope="module")
def compared(tmp_path_factory, run_cli):
    results = tmp_path_factory.mktemp("compare")
    run_cli("compare", "cornell", "-t", "path", "-W", 24, "-H", 20, "--reference-spp", 4, "--frames", 1,
            "--set", "path:spp=1", "--results", results)
    folder = results / "compare" / "cornell"
    figures = json.loads((folder / "results.json").read_text())["techniques"][0]
    image = gilab.read_exr(folder / "path.exr")["color"]
    reference = gilab.read_exr(folder / "reference.exr")["color"]
    return figures, image, reference


def test_metrics_equal_gilab_compare(compared):
    figures, image, reference = compared
    assert gilab.relative_mse(image, reference) == figures["relmse"]
    assert gilab.ssim(image, reference) == figures["ssim"]
    assert gilab.flip(image, reference) == figures["flip"]


def test_relative_mse_is_the_formula(compared):
    _, image, reference = compared
    a, r = image.astype(np.float64), reference.astype(np.float64)
    assert gilab.relative_mse(image, reference) == pytest.approx(np.mean((a - r) ** 2 / (r * r + 1e-2)), rel=1e-9)
    assert gilab.relative_mse(image, reference, epsilon=1.0) == pytest.approx(np.mean((a - r) ** 2 / (r * r + 1)), rel=1e-9)


def test_identical_images_and_maps(compared):
    _, image, reference = compared
    assert gilab.relative_mse(image, image) == 0.0
    assert gilab.ssim(image, image) == pytest.approx(1.0)
    assert gilab.flip(image, image) == 0.0
    mean, flip_map = gilab.flip(image, reference, return_map=True)
    assert flip_map.shape == image.shape[:2] and flip_map.dtype == np.float32
    assert mean == pytest.approx(float(flip_map.astype(np.float64).mean()), rel=1e-6)
    assert gilab.flip(reference, image) == pytest.approx(mean)  # symmetric
    mean, ssim_map = gilab.ssim(image, reference, return_map=True)
    assert ssim_map.shape == image.shape[:2]
    grey = image[:, :, 1]
    assert gilab.relative_mse(grey, grey[:, :, None]) == 0.0  # (H, W) and (H, W, 1) are the same image


def test_wrong_shapes_and_dtypes_raise(compared):
    _, image, reference = compared
    with pytest.raises(gilab.Error, match="same size|size"):
        gilab.relative_mse(image, reference[:-1])
    with pytest.raises(gilab.Error, match="image.*dtype"):
        gilab.ssim(image.astype(np.int32), reference)
    with pytest.raises(gilab.Error, match=r"reference.*shape"):
        gilab.flip(image, np.zeros((4, 4, 4), dtype=np.float32))
    with pytest.raises(gilab.Error, match="reference"):
        gilab.relative_mse(image, np.zeros((0, 4, 3), dtype=np.float32))
    with pytest.raises(gilab.Error):
        gilab.relative_mse(image, image[:, :, :1])  # 3 channels against 1
