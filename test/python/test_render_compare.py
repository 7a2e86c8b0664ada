"""ofv.render against `ofv render`, ofv.compare and ofv.read_compare against `ofv compare`."""

import math

import numpy as np
import pytest

import ofv
from conftest import DATA, needs_simulation, samples_while_running

pytestmark = needs_simulation


# --- render


def test_render_writes_the_command_lines_pictures(tmp_path, run_cli):
    code, out, err = run_cli("render", "dvd-one-hand", "--time", "1.2", "--out", tmp_path / "cli")
    assert code == 0, err
    frame = ofv.render("dvd-one-hand", 1.2, out=tmp_path / "py")
    for name in ("colour.png", "depth.png", "labels.png"):
        assert (tmp_path / "py" / name).read_bytes() == (tmp_path / "cli" / name).read_bytes(), name
    # "visible fraction V, occluders in the sphere K"
    words = out.split()
    assert frame.visible_fraction == pytest.approx(float(words[words.index("fraction") + 1].rstrip(",")), rel=1e-5)
    assert frame.occluders_in_sphere == int(words[-1])


def test_render_arrays_are_the_pictures():
    import matplotlib.image

    frame = ofv.render("dvd-one-hand", 1.2, noise=False)
    k = frame.intrinsics
    assert frame.depth.shape == (k["height"], k["width"]) and frame.depth.dtype == np.float32
    assert frame.colour.shape == (k["height"], k["width"], 3) and frame.colour.dtype == np.uint8
    assert frame.labels.shape == frame.depth.shape and frame.labels.dtype == np.uint16
    obj = frame.labels == ofv.LABEL_OBJECT
    assert obj.any() and np.all(frame.depth[obj] > 0.0) and np.all(frame.depth[obj] < frame.max_depth)
    assert np.all(frame.labels[frame.depth == 0.0] == ofv.LABEL_NONE)
    np.testing.assert_array_equal(frame.wMc, ofv.load_scenario("dvd-one-hand").wMc_start)
    assert frame.occluders_in_sphere >= 0 and 0.0 < frame.visible_fraction <= 1.0
    occluders = np.unique(frame.labels[frame.labels >= ofv.LABEL_OCCLUDER0])
    assert frame.occluders_in_view == len(occluders)
    del matplotlib


def test_render_pose_as_matrix_or_theta_u_and_size(tmp_path, run_cli):
    pose = [0.05, -0.02, 0.55, math.pi, 0.0, 0.0]  # above the table, looking down
    code, _, err = run_cli("render", "dvd-static", "--pose", ",".join(map(str, pose)), "--size", "64x48",
                           "--out", tmp_path / "cli")
    assert code == 0, err
    small = ofv.render("dvd-static", 0.0, pose, size=(64, 48), out=tmp_path / "py")
    assert small.depth.shape == (48, 64)
    assert (tmp_path / "py" / "colour.png").read_bytes() == (tmp_path / "cli" / "colour.png").read_bytes()
    as_matrix = ofv.render("dvd-static", 0.0, small.wMc, size=[np.int64(64), 48])
    np.testing.assert_array_equal(as_matrix.colour, small.colour)
    np.testing.assert_allclose(small.wMc[:3, 3], pose[:3])


@pytest.mark.parametrize("kwargs,error,message", [
    ({"time": -1.0}, ValueError, r"time: expected a number in \[0, 3600\], got -1"),
    ({"time": math.nan}, ValueError, "time: expected a number"),
    ({"time": 10**400}, ValueError, r"time: expected a number in \[0, 3600\], got 1000"),
    ({"time": "0"}, TypeError, r"time: expected a number in \[0, 3600\], got a str"),
    ({"pose": [0, 0, math.nan, 0, 0, 0]}, ValueError, r"pose: value 3 is nan, expected a finite number in \[-1000, 1000\]"),
    ({"pose": [0, 0, 2000.0, 0, 0, 0]}, ValueError, "pose: value 3 is 2000"),
    ({"pose": [0, 0, 1]}, ValueError, r"pose: expected a float64 array of shape \(6,\)"),
    ({"pose": np.diag([1.0, 2.0, 1.0, 1.0])}, ValueError, "pose: expected a homogeneous transform"),
    ({"pose": np.eye(4, dtype=np.int64)}, TypeError, "pose: expected a float64 array"),
    ({"size": (4, 4)}, ValueError, r"size: the width: expected an integer in \[8, 4096\], got 4"),
    ({"size": (64, 10**30)}, ValueError, r"size: the height: expected an integer in \[8, 4096\], got 1000"),
    ({"size": (64, 48, 1)}, ValueError, r"size: expected \(width, height\)"),
    ({"size": (64.0, 48)}, TypeError, "size: the width: expected an integer in .* got a float"),
    ({"size": (True, 48)}, TypeError, "size: the width: expected an integer in .* got a bool"),
    ({"out": "pictures\0"}, ValueError, "out: contains a NUL character"),
    ({"out": b"pictures"}, TypeError, r"out: expected a path \(str or os.PathLike of str\), got a bytes"),
])
def test_bad_render_arguments_are_refused(kwargs, error, message):
    args = {"time": 0.0, **kwargs}
    with pytest.raises(error, match=message):
        ofv.render("dvd-static", args.pop("time"), **args)


# --- compare

GRID = {
    "name": "python-test",
    "seeds": 1,
    "set": {"perception": "ground-truth", "duration": 0.4},
    "variants": [{"name": "paper"}, {"name": "static", "set": {"method": "static"}}],
}
GRID_YAML = """name: python-test
seeds: 1
set: {perception: ground-truth, duration: 0.4}
variants:
  - name: paper
  - name: static
    set: {method: static}
"""
TIMING = ("_ms",)


def _same_tables(a, b):
    for table in ("episodes", "summary"):
        assert list(a[table]) == list(b[table]), table
        for name in a[table]:
            if name.endswith(TIMING):  # compute times: wall clock
                continue
            np.testing.assert_array_equal(a[table][name], b[table][name], err_msg=f"{table}.{name}")


def test_compare_equals_the_command_lines_tables(tmp_path, run_cli):
    (tmp_path / "grid.yaml").write_text(GRID_YAML)
    code, _, err = run_cli("compare", "--scenarios", "dvd-static", "dvd-one-hand", "--grid", tmp_path / "grid.yaml",
                           "--jobs", "2", "--out", tmp_path / "cli")
    assert code == 0, err
    tables = ofv.compare(["dvd-static", "dvd-one-hand"], GRID, jobs=2)
    assert tables["run"]["episodes"] == tables["run"]["ran"] == 4 and tables["run"]["out"] == ""
    cli = ofv.read_compare(tmp_path / "cli")
    _same_tables(tables, cli)
    episodes = tables["episodes"]
    assert episodes["scenario"].tolist() == ["dvd-static", "dvd-static", "dvd-one-hand", "dvd-one-hand"]
    assert episodes["variant"].tolist() == ["paper", "static", "paper", "static"]
    assert episodes["seed"].dtype == np.int64 and episodes["mean_visible_fraction"].dtype == np.float64
    assert episodes["method"].tolist() == ["", "static", "", "static"]


def test_compare_into_a_folder_resumes_and_takes_a_grid_file(tmp_path):
    (tmp_path / "grid.yaml").write_text(GRID_YAML)
    first = ofv.compare("dvd-static", tmp_path / "grid.yaml", out=tmp_path / "out", jobs=1, plots=False)
    again = ofv.compare("dvd-static", str(tmp_path / "grid.yaml"), out=tmp_path / "out")
    assert (first["run"]["ran"], again["run"]["ran"], again["run"]["resumed"]) == (2, 0, 2)
    _same_tables(first, again)
    assert (tmp_path / "out" / "summary.md").exists()


def test_bad_compare_arguments_raise_the_command_lines_message(tmp_path, run_cli):
    bad = dict(GRID, variants=[{"name": "x", "set": {"gain": -1}}])
    (tmp_path / "bad.yaml").write_text(GRID_YAML.replace("method: static", "gain: -1"))
    code, _, err = run_cli("compare", "--scenarios", "dvd-static", "--grid", tmp_path / "bad.yaml", "--out", tmp_path / "o")
    assert code == 2
    with pytest.raises(ValueError) as raised:
        ofv.compare("dvd-static", tmp_path / "bad.yaml")
    assert "ofv compare: " + str(raised.value) == err.strip()
    with pytest.raises(ValueError, match="gain"):
        ofv.compare("dvd-static", bad)
    with pytest.raises(ValueError, match=r"seeds: expected an integer in \[1, 1000\], got 0"):
        ofv.compare("dvd-static", GRID, seeds=0)
    with pytest.raises(ValueError, match=r"jobs: expected an integer in \[1, 256\], got 1000000000000000000000"):
        ofv.compare("dvd-static", GRID, jobs=10**21)
    with pytest.raises(TypeError, match=r"jobs: expected an integer in \[1, 256\], got a float"):
        ofv.compare("dvd-static", GRID, jobs=1.5)
    with pytest.raises(ValueError, match="out: contains a NUL character"):
        ofv.compare("dvd-static", GRID, out=tmp_path / "o\0")
    with pytest.raises(ValueError, match="no-such-scenario"):
        ofv.compare("no-such-scenario", GRID)
    with pytest.raises(FileNotFoundError, match="episodes.csv"):
        ofv.read_compare(tmp_path)


def test_read_compare_types_columns_as_pandas_does(tmp_path):
    (tmp_path / "episodes.csv").write_text('a,b,c,d,e\n1,2.5,x,,"q,1"\n3,,y,,z\n')
    (tmp_path / "summary.csv").write_text("a\n")
    t = ofv.read_compare(tmp_path)
    e = t["episodes"]
    assert e["a"].dtype == np.int64 and e["a"].tolist() == [1, 3]
    assert e["b"].dtype == np.float64 and e["b"][0] == 2.5 and math.isnan(e["b"][1])
    assert e["c"].tolist() == ["x", "y"] and e["e"].tolist() == ["q,1", "z"]
    assert e["d"].dtype == np.float64 and np.isnan(e["d"]).all()
    assert t["summary"]["a"].shape == (0,)
    (tmp_path / "summary.csv").write_text("a,b\n1\n")
    with pytest.raises(ValueError, match="line 2 has 1 fields, the header 2"):
        ofv.read_compare(tmp_path)


def test_scene_data_files_of_the_repository_load():
    # data/ holds the example scenes `ofv estimate` documents.
    scenes = sorted((DATA.parent.parent / "data").rglob("*.json"))
    loaded = [ofv.load_scene(p) for p in scenes if "supervoxels" in p.read_text()[:2000]]
    assert all(len(s.positions) > 0 for s in loaded)


def test_the_gil_is_released_while_rendering_and_comparing():
    frame, inside = samples_while_running(lambda: ofv.render("dvd-one-hand", 1.0, size=(1280, 960)))
    assert frame.depth.shape == (960, 1280) and inside > 5
    tables, inside = samples_while_running(lambda: ofv.compare("dvd-static", GRID, jobs=1))
    assert len(tables["episodes"]["variant"]) == 2 and inside > 20
