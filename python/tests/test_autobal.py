"""The Python package against the `study` command on the same inputs: the
same numbers bit for bit, the same refusals naming the same key.

The command is target/debug/study of this repository (build it with
`cargo build` first), or $AUTOBAL_STUDY."""

import json
import os
import subprocess
from pathlib import Path

import numpy as np
import polars as pl
import pytest

import autobal

ROOT = Path(__file__).resolve().parents[2]
STUDY = os.environ.get("AUTOBAL_STUDY", str(ROOT / "target" / "debug" / "study"))
SCENE = ROOT / "scenes" / "three_balls.toml"

# The main job's design 2 (3 balls at the optimal radius ratio, drag 10
# N·s/m) on its rotor, as a dict of the scene file's tables.
MAIN_JOB_DESIGN = {
    "rotor": {"mass": 10.0, "kx": 1.0e5, "ky": 1.0e5, "bx": 100.0, "by": 100.0, "eccentricity": 2.0e-4},
    "balancer": {"kind": "ball", "n": 3, "rho": "optimal", "race_radius": 0.05, "density": 7850.0, "drag": 10.0},
    "speed": {"mode": "constant", "omega": 300.0},
    "start": {"mode": "locked_steady", "angles_deg": [60, 140, 220]},
    "metrics": {"t_end_revs": 2000},
}


def study(*args):
    return subprocess.run([STUDY, *map(str, args)], capture_output=True, text=True)


def recorded_both_ways(scene, tmp_path):
    """The scene run with its time history by the package and by
    `study simulate --series --json` (a recorded run goes to its horizon, so
    both print those metrics): the package's run and the command's series,
    after checking that the metrics are the same text."""
    run = autobal.simulate(scene)
    series = tmp_path / "series.parquet"
    cli = study("simulate", scene, "--series", series, "--json")
    assert cli.returncode == 0, cli.stderr
    assert run.metrics_json == cli.stdout.rstrip("\n")
    return run, pl.read_parquet(series)


def test_a_scene_simulates_bit_for_bit_as_the_command_line(tmp_path):
    plain = autobal.simulate(SCENE, series=False)
    cli = study("simulate", SCENE, "--json")
    assert cli.returncode == 0, cli.stderr
    assert plain.metrics_json == cli.stdout.rstrip("\n")
    assert plain.metrics == json.loads(cli.stdout)
    # With the time history, as `--series` writes it.
    run, frame = recorded_both_ways(SCENE, tmp_path)
    for name in ("t", "x", "y", "r"):
        assert np.array_equal(getattr(run, name), frame[name].to_numpy()), name
    assert run.angles.shape == (3, len(run.t))
    assert np.array_equal(run.angles[0], frame["psi_0"].to_numpy())
    assert run.bearing_x.size == 0  # a plane rotor has no bearings of its own


def test_a_two_support_rotors_bearing_orbits_are_the_command_lines(tmp_path):
    run, frame = recorded_both_ways(ROOT / "scenes" / "two_support_single.toml", tmp_path)
    assert run.bearing_x.shape == (2, len(run.t))
    for b in range(2):
        assert np.array_equal(run.bearing_x[b], frame[f"bearing_{b}_x"].to_numpy())
        assert np.array_equal(run.bearing_y[b], frame[f"bearing_{b}_y"].to_numpy())


def test_a_dict_and_a_toml_string_are_the_file(tmp_path):
    path = tmp_path / "design2.toml"
    from_dict = autobal.simulate(MAIN_JOB_DESIGN, series=False)
    path.write_text(autobal._toml_of(MAIN_JOB_DESIGN))
    assert from_dict.metrics_json == autobal.simulate(path, series=False).metrics_json
    assert from_dict.metrics_json == autobal.simulate(path.read_text(), series=False).metrics_json
    assert from_dict.metrics["settled"] is True
    assert from_dict.t.size == 0


def test_a_bad_key_raises_naming_the_key(tmp_path):
    bad = dict(MAIN_JOB_DESIGN, balancer=dict(MAIN_JOB_DESIGN["balancer"], dragg=1.0))
    with pytest.raises(autobal.InputError) as caught:
        autobal.simulate(bad)
    assert caught.value.key == "balancer.dragg"
    assert "unknown field `dragg`" in str(caught.value)
    # A value outside its domain: the same message as the command line's.
    negative = dict(MAIN_JOB_DESIGN, balancer=dict(MAIN_JOB_DESIGN["balancer"], drag=-1.0))
    path = tmp_path / "negative.toml"
    path.write_text(autobal._toml_of(negative))
    with pytest.raises(autobal.InputError) as caught:
        autobal.simulate(path)
    assert caught.value.key == "balancer.drag"
    cli = study("simulate", path)
    assert cli.returncode == 2
    assert cli.stderr.strip() == f"error: {caught.value}"
    # A key left out: named by its table and its name.
    rotor = {k: v for k, v in MAIN_JOB_DESIGN["rotor"].items() if k != "kx"}
    with pytest.raises(autobal.InputError) as caught:
        autobal.simulate(dict(MAIN_JOB_DESIGN, rotor=rotor))
    assert caught.value.key == "rotor.kx", str(caught.value)
    with pytest.raises(autobal.InputError):
        autobal.simulate(tmp_path / "missing.toml")


def test_a_studys_frames_are_the_command_lines_runs(tmp_path):
    text = (ROOT / "studies" / "three_balls.toml").read_text()
    text = text.replace("samples = 500", "samples = 8")
    result = autobal.run_study(text, threads=2, out=tmp_path / "py")
    path = tmp_path / "cli.toml"
    path.write_text(text.replace('seed = 20261122', f'seed = 20261122\noutput = "{tmp_path / "cli"}"'))
    cli = study("run", path, "--quiet", "--threads", "1")
    assert cli.returncode == 0, cli.stderr
    folder = next((tmp_path / "cli").iterdir())
    runs = pl.read_parquet(folder / "runs.parquet")
    assert result.runs.height == 8 * 20
    timing = ["wall_time_s"]
    assert result.runs.drop(timing).equals(runs.drop(timing))
    assert result.summary.columns == pl.read_parquet(folder / "summary.parquet").columns
    decision = result.decision
    assert decision.recommendation["kind"] in ("build", "none_balances")
    assert decision.ranked[0]["design_id"] == result.summary.sort("rank")["design_id"][0]
    assert "recommendation" in decision.text
    # Results already there are refused unless asked to overwrite.
    with pytest.raises(autobal.InputError):
        autobal.run_study(text, out=tmp_path / "py")
    assert autobal.run_study(text, out=tmp_path / "py", overwrite=True).runs.height == 160


def test_the_design_table_is_the_command_lines():
    table = autobal.design(range(1, 5), kind="ball")
    cli = study("design", "--kind", "ball", "--n", "1..4", "--json")
    assert table.to_dicts() == json.loads(cli.stdout)
    with pytest.raises(autobal.InputError) as caught:
        autobal.design(3, kind="sphere")
    assert caught.value.key == "kind"
