"""Shared fixtures: the built module, the built `gilab` CLI, and a runner for it.

Run through CTest (which sets PYTHONPATH, GILAB_CLI and GILAB_SOURCE_DIR), or by hand:

    PYTHONPATH=build/python /usr/bin/python3 -m pytest -q tests/python
"""
import os
import pathlib
import subprocess

import pytest

SOURCE_DIR = pathlib.Path(os.environ.get("GILAB_SOURCE_DIR", pathlib.Path(__file__).resolve().parents[2]))
SHARED_SCENES = (SOURCE_DIR / ".." / "shared" / "scenes").resolve()


def _find_cli():
    if os.environ.get("GILAB_CLI"):
        return pathlib.Path(os.environ["GILAB_CLI"])
    # Next to the module: build-dir/python/gilab*.so → build-dir/gilab
    import gilab

    return pathlib.Path(gilab.__file__).resolve().parents[1] / "gilab"


@pytest.fixture(scope="session")
def cli():
    path = _find_cli()
    if not path.is_file():
        pytest.fail(f"the gilab CLI is not built at {path} (set GILAB_CLI)")
    return path


@pytest.fixture(scope="session")
def run_cli(cli):
    """Runs `gilab ARGS…` at 2 threads and returns the completed process (check=True)."""

    def run(*args, check=True):
        result = subprocess.run([str(cli), "--threads", "2", *map(str, args)], capture_output=True, text=True)
        if check and result.returncode != 0:
            raise AssertionError(f"gilab {' '.join(map(str, args))} failed:\n{result.stderr}")
        return result

    return run


@pytest.fixture(scope="session")
def cornell():
    import gilab

    return gilab.load_scene("cornell")


def require_shared_asset(relative):
    """The path of a shared scene asset, or a clear skip naming it."""
    path = SHARED_SCENES / relative
    if not path.exists():
        pytest.skip(f"shared asset missing: {path}")
    return path
