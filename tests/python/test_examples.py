"""The examples in examples/python run at small sizes and write their PNGs."""
import os
import subprocess
import sys

import pytest

from conftest import SOURCE_DIR

EXAMPLES = SOURCE_DIR / "examples" / "python"

CASES = {
    "radius_sweep.py": (["--size", "32", "--photons", "4096", "--reference-spp", "4", "--radii", "0.04", "0.1"],
                        ["radius_sweep.png"]),
    "svdag_nodes.py": (["--resolutions", "8", "16", "32"], ["svdag_nodes.png"]),
    "stereo_render.py": (["--width", "40", "--height", "44"], ["left.png", "right.png"]),
}


@pytest.mark.parametrize("script", sorted(CASES))
def test_example_runs_and_writes_its_pngs(script, tmp_path):
    arguments, outputs = CASES[script]
    output = tmp_path / "out"  # not there yet: the example creates it
    done = subprocess.run([sys.executable, str(EXAMPLES / script), str(output), *arguments],
                          capture_output=True, text=True, env=dict(os.environ, MPLBACKEND="Agg"), timeout=120)
    assert done.returncode == 0, done.stderr
    for name in outputs:
        png = output / name
        assert png.is_file() and png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n", name
