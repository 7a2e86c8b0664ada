"""ofv.simulate, ofv.load_scenario against `ofv simulate`."""

import csv
import json
import math
import threading
import time

import numpy as np
import pytest

import ofv
from conftest import TIMING_COLUMNS, TIMING_METRICS, needs_simulation, samples_while_running

pytestmark = needs_simulation


def _read_trajectory(path):
    with open(path, newline="") as f:
        rows = list(csv.reader(f))
    return rows[0], rows[1:]


def _assert_same_episode(episode, cli_dir):
    """metrics.json and trajectory.csv of `ofv simulate` against the Episode, compute times aside."""
    cli_metrics = json.loads((cli_dir / "metrics.json").read_text())
    assert list(episode.metrics) == list(cli_metrics)
    for key in cli_metrics:
        if key not in TIMING_METRICS:
            assert episode.metrics[key] == cli_metrics[key], key
    header, rows = _read_trajectory(cli_dir / "trajectory.csv")
    assert list(episode.trajectory) == header
    assert len(rows) == episode.metrics["steps"]
    for k, name in enumerate(header):
        column = episode.trajectory[name]
        assert len(column) == len(rows), name
        if name in TIMING_COLUMNS:
            assert column.dtype == np.float64 and np.all(column >= 0.0)
        elif column.dtype == np.float64:
            expected = np.array([float(r[k]) if r[k] else math.nan for r in rows])
            np.testing.assert_array_equal(column, expected, err_msg=name)
        else:
            assert column.tolist() == [r[k] for r in rows], name


@pytest.mark.parametrize("perception,duration,sets", [
    ("ground-truth", 0.5, {}),
    ("ground-truth", 0.5, {"method": "static"}),
    ("full", 1.5, {"seed": 1}),  # the hand enters: tracks, anticipation, the PCL front end; sensor noise of seed 1
])
def test_episode_equals_the_command_lines(tmp_path, run_cli, perception, duration, sets):
    args = ["simulate", "dvd-one-hand", "--perception", perception, "--set", f"duration={duration}", "--no-pictures",
            "--out", tmp_path / "cli"]
    for name, value in sets.items():
        args += ["--seed", value] if name == "seed" else ["--set", f"{name}={value}"]
    code, _, err = run_cli(*args)
    assert code == 0, err
    episode = ofv.simulate("dvd-one-hand", perception=perception, duration=duration, **sets)
    _assert_same_episode(episode, tmp_path / "cli")
    assert episode.out == "" and episode.files == []
    assert episode.metrics["perception"]["mode"] == perception
    if perception == "full":
        assert np.nanmax(episode.trajectory["tracks"]) >= 1
        # Every frame of the front end scored against the rendered labels.
        assert np.all(np.isfinite(episode.trajectory["object_recall"]))
        assert episode.metrics["perception"]["object_precision"]["frames"] == episode.metrics["steps"]
        assert episode.metrics["perception"]["object_precision"]["mean"] >= 0.98
    else:
        assert set(episode.metrics["perception"]) == {"mode"}
        assert np.all(np.isnan(episode.trajectory["object_recall"]))


def test_files_written_into_out_are_those_of_the_command_line(tmp_path):
    scenario = ofv.load_scenario("dvd-two-hands")
    episode = ofv.simulate(scenario, out=tmp_path / "py", duration=0.4, perception="ground-truth", pictures=True)
    assert episode.out == str(tmp_path / "py")
    assert {"trajectory.csv", "metrics.json", "visibility.png"} <= set(episode.files)
    _assert_same_episode(episode, tmp_path / "py")


def test_the_callback_sees_every_row_of_the_trajectory():
    rows = []
    episode = ofv.simulate("dvd-static", duration=0.3, perception="ground-truth", callback=rows.append)
    assert len(rows) == len(episode.trajectory["time"]) == episode.metrics["steps"]
    for name, column in episode.trajectory.items():
        values = [row[name] for row in rows]
        if column.dtype == np.float64:
            np.testing.assert_array_equal(column, np.array(values), err_msg=name)
        else:
            assert column.tolist() == values


def test_the_episodes_settings_run_it_again():
    episode = ofv.simulate("dvd-two-hands", duration=0.3, perception="ground-truth", gain=3, preset="authors_code")
    s = episode.settings
    assert (s["duration"], s["perception"], s["gain"], s["preset"], s["step"]) == (0.3, "ground-truth", 3.0, "authors_code", 0.01)
    assert list(s) == [d["name"] for d in ofv.episode_settings()]
    again = ofv.simulate("dvd-two-hands", **s)
    assert again.settings == s
    for name, column in episode.trajectory.items():
        if name not in TIMING_COLUMNS:
            np.testing.assert_array_equal(again.trajectory[name], column, err_msg=name)


def test_an_exception_in_the_callback_ends_the_episode_and_propagates():
    seen = []

    def stop_at_third(row):
        seen.append(row["time"])
        if len(seen) == 3:
            raise KeyError("enough")

    with pytest.raises(KeyError, match="enough"):
        ofv.simulate("dvd-static", duration=2.0, perception="ground-truth", callback=stop_at_third)
    assert len(seen) == 3
    with pytest.raises(TypeError, match="callback: expected a callable, got a int"):
        ofv.simulate("dvd-static", duration=0.1, callback=3)


@pytest.mark.parametrize("args,sets", [
    (["--set", "gain=-1"], {"gain": -1}),
    (["--set", "duration=abc"], {"duration": "abc"}),
    (["--set", "no_such=1"], {"no_such": 1}),
    (["--robot", "puma"], {"robot": "puma"}),
    (["--perception", "psychic"], {"perception": "psychic"}),
])
def test_bad_settings_raise_the_command_lines_message(run_cli, args, sets):
    code, _, err = run_cli("simulate", "dvd-static", *args)
    assert code == 2
    with pytest.raises(ValueError) as raised:
        ofv.simulate("dvd-static", **sets)
    assert "ofv simulate: " + str(raised.value) == err.strip()


def test_bad_scenarios_raise_the_command_lines_message(run_cli, tmp_path):
    code, _, err = run_cli("simulate", "no-such-scenario")
    assert code == 2
    with pytest.raises(ValueError) as raised:
        ofv.load_scenario("no-such-scenario")
    assert "ofv simulate: " + str(raised.value) == err.strip()
    bad = tmp_path / "bad.yaml"
    bad.write_text("duration: -1\n")
    code, _, err = run_cli("simulate", bad)
    with pytest.raises(ValueError) as raised:
        ofv.simulate(bad)
    assert code == 2 and "ofv simulate: " + str(raised.value) == err.strip()
    with pytest.raises(TypeError, match="scenario: expected a Scenario"):
        ofv.simulate(42)
    with pytest.raises(ValueError, match="out=FOLDER"):
        ofv.simulate("dvd-static", pictures=True)


def test_scenarios_load_by_name_and_path():
    names = ofv.builtin_scenarios()
    assert "dvd-one-hand" in names and names == sorted(names)
    s = ofv.load_scenario("dvd-one-hand")
    again = ofv.load_scenario(s.path)
    assert (again.name, again.duration, again.rate, again.bodies) == (s.name, s.duration, s.rate, s.bodies)
    np.testing.assert_array_equal(s.wMc_start, again.wMc_start)
    assert s.wMc_start.shape == (4, 4) and s.estimator.r_sphere == s.r_sphere
    assert {d["name"] for d in ofv.episode_settings()} >= {"duration", "perception", "robot", "seed", "gain", "step"}


def test_threads_run_episodes_in_parallel_with_the_results_of_one_at_a_time():
    """The GIL is released during an episode: other threads run meanwhile,
    and episodes in threads give what they give alone."""
    alone, inside = samples_while_running(
        lambda: ofv.simulate("dvd-one-hand", duration=0.5, perception="ground-truth", seed=1))
    assert inside > 20
    results = [None, None]

    def run(k):
        results[k] = ofv.simulate("dvd-one-hand", duration=0.5, perception="ground-truth", seed=1)

    workers = [threading.Thread(target=run, args=(k,)) for k in range(2)]
    for w in workers:
        w.start()
    for w in workers:
        w.join()
    for r in results:
        for name, column in alone.trajectory.items():
            if name not in TIMING_COLUMNS:
                np.testing.assert_array_equal(r.trajectory[name], column, err_msg=name)


def test_ctrl_c_interrupts_a_long_episode():
    """SIGINT during an episode (GIL released) raises KeyboardInterrupt within a fraction of a second."""
    import os
    import signal
    import subprocess
    import sys

    child = subprocess.Popen(
        [sys.executable, "-c", "import ofv; print('go', flush=True); "
         "ofv.simulate('dvd-one-hand', duration=600, perception='ground-truth')"],
        stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=dict(os.environ))
    try:
        assert child.stdout.readline().strip() == "go"
        time.sleep(0.5)  # well into the episode
        child.send_signal(signal.SIGINT)
        start = time.monotonic()
        _, err = child.communicate(timeout=30)
        assert time.monotonic() - start < 5.0
    finally:
        if child.poll() is None:
            child.kill()
            child.communicate()
    assert child.returncode != 0 and "KeyboardInterrupt" in err
