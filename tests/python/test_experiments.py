"""gilab.experiments / gilab.run_experiment against `gilab experiment` for the same run."""
import json

import pytest

import gilab
from conftest import require_shared_asset


def test_experiment_list_matches_the_cli(run_cli):
    listed = run_cli("experiment", "list").stdout
    names = [line.split()[0] for line in listed.splitlines()[1:] if line.startswith("  ")]
    assert [e["name"] for e in gilab.experiments()] == names
    assert all(e["paper"] and e["description"] for e in gilab.experiments())


def test_run_experiment_returns_the_cli_tables(tmp_path, run_cli):
    # vct-table1 counts voxels: deterministic, so both runs must agree exactly.
    require_shared_asset("bunny/stanford-bunny.obj")
    run_cli("experiment", "vct-table1", "--quick", "--results", tmp_path / "cli")
    written = json.loads((tmp_path / "cli" / "vct-table1" / "results.json").read_text())
    result = gilab.run_experiment("vct-table1", quick=True, results=tmp_path / "py", threads=2)
    assert result["name"] == "vct-table1" and result["directory"] == str(tmp_path / "py" / "vct-table1")
    assert result["tables"] == written["tables"]
    assert result["config"] == written["config"]
    assert isinstance(result["tables"][0]["rows"][0], dict)
    assert (tmp_path / "py" / "vct-table1" / "table.md").is_file()
    assert not list((tmp_path / "py").glob(".*partial"))


def test_run_without_results_leaves_nothing(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    result = gilab.run_experiment("core-rays", threads=2)
    assert result["directory"] is None and result["tables"][0]["rows"]
    assert list(tmp_path.iterdir()) == []


def test_unknown_experiment_lists_the_names():
    with pytest.raises(gilab.Error, match="pm-table1"):
        gilab.run_experiment("pm-table99")


def test_experiment_plan_matches_the_cli(run_cli):
    """gilab.experiment_plan gives the tasks `gilab experiment plan` prints."""
    plan = gilab.experiment_plan("pm-radius-sweep", quick=True)
    printed = [json.loads(line) for line in run_cli("experiment", "plan", "pm-radius-sweep", "--quick").stdout.splitlines()]
    assert plan == printed
    assert [t["id"] for t in plan] == list(range(len(plan)))
    assert {v["technique"] for t in plan for v in t["variants"]} == {"photon"}
    with pytest.raises(gilab.Error, match="pm-radius-sweep"):
        gilab.experiment_plan("pm-table99")


SPEC = {
    "name": "cornell-radius",
    "paper": "P1",
    "figure": "Radius",
    "description": "gather radius on the Cornell box",
    "scenes": ["cornell"],
    "size": {"full": 64, "quick": 24},
    "frames": 1,
    "variants": [{"name": "hash grid", "technique": "photon",
                  "settings": {"photon_map": "hash_grid", "photons": 4096}}],
    "axes": [{"setting": "radius", "values": [0.05, 0.1]}],
    "measures": [{"column": "frame_ms", "key": "render_ms"},
                 {"column": "photons_stored", "key": "photons_stored", "source": "prepare stat"},
                 {"column": "digest", "key": "color", "source": "last frame's layer digest"}],
}


def test_a_spec_declared_as_a_dict_plans_and_runs(tmp_path):
    """A dict spec is planned and run like a registered one; its config is the spec."""
    plan = gilab.experiment_plan(SPEC)
    assert [t["axes"]["radius"] for t in plan] == [0.05, 0.1]
    result = gilab.run_experiment(SPEC, results=str(tmp_path))
    rows = result["tables"][0]["rows"]
    assert [r["radius (scene units)"] for r in rows] == [0.05, 0.1]
    assert all(r["photons_stored"] > 0 for r in rows)
    assert rows[0]["digest"] != rows[1]["digest"]  # a larger radius changes the image
    assert result["config"]["variants"][0]["settings"]["photons"] == 4096
    assert (tmp_path / "cornell-radius" / "tasks" / "quick" / "1.json").exists()
    # Run again: same seed, same images.
    again = gilab.run_experiment(SPEC)
    assert [r["digest"] for r in again["tables"][0]["rows"]] == [r["digest"] for r in rows]


def test_a_bad_spec_dict_names_the_problem():
    with pytest.raises(gilab.Error, match="unknown key 'scene'"):
        gilab.experiment_plan({**SPEC, "scene": "cornell"})
    with pytest.raises(gilab.Error, match="radii"):
        gilab.experiment_plan({**SPEC, "axes": [{"setting": "radii", "values": [0.1]}]})
    with pytest.raises(gilab.Error, match="no probe named 'nope'"):
        gilab.experiment_plan({**SPEC, "variants": [{"name": "x", "probe": "nope"}]})
