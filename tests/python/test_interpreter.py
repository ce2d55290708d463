"""`import gilab` from an interpreter the module was not built for says which to use."""
import importlib.util
import os
import subprocess
import sys

import pytest

MODULE_DIR = os.environ["PYTHONPATH"].split(os.pathsep)[0]


def test_another_python_version_is_told_the_interpreter_to_use():
    # Another version cannot load the compiled module (its ABI tag differs) and imports
    # the plain gilab.py beside it; here it is imported by path, as that version would.
    spec = importlib.util.spec_from_file_location("gilab_fallback", os.path.join(MODULE_DIR, "gilab.py"))
    with pytest.raises(ImportError) as raised:
        spec.loader.exec_module(importlib.util.module_from_spec(spec))
    message = str(raised.value)
    assert "built for " + sys.executable in message
    assert "Python %d.%d" % sys.version_info[:2] in message


def test_the_compiled_module_wins_for_the_interpreter_it_was_built_for():
    import gilab

    assert gilab.__file__.endswith(".so"), gilab.__file__


def test_an_interpreter_without_numpy_fails_at_import_naming_the_right_one():
    # -S leaves out site-packages (and with them Debian's NumPy) while the module, built
    # for this version, still loads: the case of a same-version interpreter without NumPy.
    run = subprocess.run([sys.executable, "-S", "-c", "import gilab"], capture_output=True, text=True,
                         env=dict(os.environ), timeout=60)
    assert run.returncode != 0
    assert "ImportError" in run.stderr, run.stderr
    assert "gilab needs NumPy" in run.stderr, run.stderr
    assert "built for " + sys.executable in run.stderr, run.stderr
