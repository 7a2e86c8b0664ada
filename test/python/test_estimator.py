"""ofv.estimate_view, ofv.Scene and ofv.EstimatorSettings against `ofv estimate`."""

import concurrent.futures
import copy
import json
import math
import pickle
import numpy as np
import pytest

import ofv
from conftest import DATA, samples_while_running

CASES = sorted(p for p in (DATA / "conformance").glob("*.json") if not p.name.endswith(".expected.json"))


def test_the_shipped_cases_are_there():
    assert len(CASES) >= 40


def _check_attributes(e, j):
    """Every attribute of a ViewEstimate against the JSON of `ofv estimate`."""
    assert e.status.name == j["status"]
    assert e.initial_view_used.name == j["initial_view_used"]
    for key in ("iterations", "skipped_supervoxels", "skipped_occluders", "axes_from_world", "occlusion_points",
                "clearance_points", "tf_to_t0_deg"):
        assert getattr(e, key) == j[key], key
    for key in ("t0", "tf", "centroid", "axes"):
        np.testing.assert_array_equal(getattr(e, key), np.array(j[key]), err_msg=key)
    for which, stats in (("t0", e.error_t0), ("tf", e.error_tf)):
        if j["angular_error_deg"][which] is None:
            assert stats is None
        else:
            assert (stats.mean, stats.std) == (j["angular_error_deg"][which]["mean"], j["angular_error_deg"][which]["std"])
    assert e.is_free == (j["status"] in ("converged", "no_occluders"))
    if "path" in j:
        np.testing.assert_array_equal(e.path, np.array(j["path"]).reshape(-1, 3))
    else:
        assert e.path.shape == (0, 3)


@pytest.fixture(scope="session")
def cli_results(run_cli):
    """`ofv estimate CASE --compact --path` on every case, two at a time (the program takes ~0.4 s to start)."""
    with concurrent.futures.ThreadPoolExecutor(max_workers=2) as pool:
        return dict(zip(CASES, pool.map(lambda c: run_cli("estimate", c, "--compact", "--path"), CASES)))


@pytest.mark.parametrize("case", CASES, ids=lambda p: p.stem)
def test_scene_file_estimate_equals_the_command_line(case, cli_results):
    code, out, err = cli_results[case]
    scene = ofv.load_scene(case)
    e = scene.estimate(record_path=True)
    if code == 2 and "no usable supervoxel" in err:
        assert e.status == ofv.ViewStatus.no_supervoxels  # an outcome for the library, a usage error for the CLI
        return
    assert code == 0, err
    j = json.loads(out)
    assert e.to_dict() == j
    _check_attributes(e, j)


@pytest.mark.parametrize("case", CASES[::3], ids=lambda p: p.stem)
def test_numpy_arrays_give_the_command_line_result(case, cli_results):
    """The arrays path (not the scene file's) with the scene's settings."""
    code, out, err = cli_results[case]
    assert code == 0, err
    j = json.loads(out)
    s = ofv.load_scene(case)
    e = ofv.estimate_view(s.positions, s.normals, s.occluders, centroid=s.centroid, axes=s.axes, camera=s.camera,
                          previous_view=s.previous_view, settings=s.settings, record_path=True)
    assert e.to_dict() == j
    _check_attributes(e, j)


def test_keyword_settings_equal_set_on_the_command_line(cli_json):
    case = DATA / "conformance" / "edge-occluder-on-initial-ray.json"
    j = cli_json("estimate", case, "--compact", "--set", "preset=authors_code", "--set", "step=r_seed",
                 "--set", "push_weighting=inverse_distance", "--set", "max_iterations=7")
    s = ofv.load_scene(case)
    e = s.estimate(preset="authors_code", step="r_seed", push_weighting="inverse_distance", max_iterations=7)
    assert e.to_dict() == j
    assert e.iterations <= 7
    assert s.settings.max_iterations == 500  # the scene's own settings are not changed


# --- settings


def test_every_setting_is_an_attribute_with_its_documented_default(run_cli):
    docs = ofv.EstimatorSettings.docs()
    code, out, _ = run_cli("settings")
    assert code == 0
    cli_names = [line.split()[0] for line in out.splitlines() if line.startswith("  ") and not line.startswith("      ")]
    assert [d["name"] for d in docs] == cli_names[: len(docs)]
    s = ofv.EstimatorSettings()
    for d in docs:
        value = getattr(s, d["name"])
        if isinstance(value, bool):
            text = "true" if value else "false"
        elif isinstance(value, float):
            text = repr(value)
            text = text[:-2] if text.endswith(".0") else text
        else:
            text = str(value)
        assert text == d["default"], d["name"]
        assert d["doc"] in type(s).__dict__[d["name"]].__doc__
    assert set(s.to_dict()) == {d["name"] for d in docs}


def test_each_attribute_reads_the_setting_it_writes():
    s = ofv.EstimatorSettings()
    for k, d in enumerate(ofv.estimator_settings()):
        name = d["name"]
        if d["type"].startswith("number"):
            value = 0.0123 + 0.001 * k
        elif d["type"].startswith("integer"):
            value = 17 + k
        elif d["type"] == "bool":
            value = not getattr(s, name)
        else:  # words: the last one listed
            value = d["type"].split(" | ")[-1]
        setattr(s, name, value)
        assert getattr(s, name) == value, name
        assert type(getattr(s, name)) is type(value), name


def test_presets_resolve_as_the_spec_says():
    s = ofv.EstimatorSettings(preset="authors_code", r_seed=0.04)
    assert (s.step, s.clearance, s.max_iterations, s.push_radius) == (0.02, 0.08, 50, 0.5)
    s.step = 0.03  # an explicit value wins over the preset
    assert s.step == 0.03 and s.clearance == 0.08
    assert ofv.EstimatorSettings(r_sphere=0.3, push_radius="r_seed").push_radius == 0.02


def _cli_set_error(run_cli, name, value):
    code, _, err = run_cli("estimate", DATA / "conformance" / "edge-no-occluders.json", "--set", f"{name}={value}")
    assert code == 2
    prefix = f"ofv estimate: --set {name}={value}: "
    if err.startswith(prefix):
        return err[len(prefix):].strip()
    # range errors are found when the settings resolve, after the scene's name
    prefix = f"ofv estimate: {DATA / 'conformance' / 'edge-no-occluders.json'}: "
    assert err.startswith(prefix), err
    return err[len(prefix):].strip()


@pytest.mark.parametrize("name,value,text", [
    ("step", "abc", "abc"), ("max_iterations", -1, "-1"), ("max_iterations", 1.5, "1.5"), ("warm_start", 1, "1"),
    ("initial_view", "median", "median"), ("r_seed", -0.5, "-0.5"), ("time_budget", 0, "0"),
    ("clearance", math.inf, "inf"), ("no_such_setting", 1, "1"),
])
def test_bad_settings_raise_the_command_lines_message(run_cli, name, value, text):
    expected = _cli_set_error(run_cli, name, text)
    positions = np.zeros((1, 3))
    normals = np.array([[0.0, 0.0, 1.0]])
    with pytest.raises(ValueError) as raised:
        ofv.estimate_view(positions, normals, **{name: value})
    assert str(raised.value) == expected
    s = ofv.EstimatorSettings()
    before = s.to_dict()
    with pytest.raises((ValueError, AttributeError)):
        setattr(s, name, value)
    assert s.to_dict() == before  # a rejected value changes nothing
    with pytest.raises(ValueError, match="^" + expected.replace("(", r"\(").replace(")", r"\)").replace("[", r"\[")
                       .replace("]", r"\]").replace("+", r"\+").replace(".", r"\.") + "$"):
        ofv.EstimatorSettings(**{name: value})


def test_setting_values_of_other_types_raise_type_error():
    with pytest.raises(TypeError, match="setting 'step': expected a bool, int, float or str, got a list"):
        ofv.EstimatorSettings(step=[0.01])
    with pytest.raises(TypeError):
        ofv.EstimatorSettings(r_seed=None)


def test_settings_copy_pickle_and_equality():
    s = ofv.EstimatorSettings(preset="authors_code", warm_start=True, time_budget=0.5)
    t = copy.copy(s)
    t.step = 0.001
    assert s.step == 0.01 and s != t
    assert pickle.loads(pickle.dumps(s)) == s
    assert s.copy() == s and s != ofv.EstimatorSettings()


# --- what the binding library would otherwise see


def _classes():
    """Every class of the extension (a class added later is checked too)."""
    return [c for c in vars(ofv._ofv).values()
            if isinstance(c, type) and not issubclass(c, BaseException) and c is not ofv._ofv._Type]


@pytest.mark.parametrize("cls", _classes(), ids=lambda c: c.__name__)
def test_objects_made_without_their_constructor_are_refused(cls):
    # Without the check, their methods read memory no constructor wrote.
    with pytest.raises(TypeError, match=rf"^{cls.__name__}\.__new__\({cls.__name__}\) alone would make"):
        cls.__new__(cls)


def test_subclasses_enums_and_pickles_still_construct():
    class Settings(ofv.EstimatorSettings):
        pass

    assert Settings(r_sphere=0.3).r_sphere == 0.3
    s = ofv.EstimatorSettings(preset="authors_code", r_sphere=0.4, max_iterations=7)
    for protocol in range(pickle.HIGHEST_PROTOCOL + 1):
        assert pickle.loads(pickle.dumps(s, protocol=protocol)) == s
        for member in (ofv.ViewStatus.out_of_time, ofv.InitialViewUsed.camera):
            assert pickle.loads(pickle.dumps(member, protocol=protocol)) == member
    assert ofv.ViewStatus(2) == ofv.ViewStatus.out_of_time and copy.deepcopy(s) == s


@pytest.mark.parametrize("call,error,message", [
    (lambda: ofv.EstimatorSettings(preset="paper\udc80"), ValueError, r"^setting 'preset': not valid text \(a lone surrogate"),
    (lambda: ofv.EstimatorSettings(preset="paper\0"), ValueError, "^setting 'preset': contains a NUL character$"),
    (lambda: ofv.EstimatorSettings(**{"r_sphere\udc80": 0.3}), ValueError, "^setting name: not valid text"),
    (lambda: ofv.EstimatorSettings(max_iterations=10**30), ValueError, r"must be an integer in \[0, 100000000\]"),
    (lambda: ofv.EstimatorSettings(r_sphere=10**400), ValueError, "'r_sphere' must be a finite number"),
    (lambda: ofv.Scene.load("scene\0.json"), ValueError, "^path: contains a NUL character$"),
    (lambda: ofv.Scene.load("\udc80.json"), ValueError, "^path: not valid text"),
    (lambda: ofv.Scene.load(b"scene.json"), TypeError, r"^path: expected a path \(str or os.PathLike of str\), got a bytes$"),
    (lambda: ofv.Scene.from_json("{}", source="\udc80"), ValueError, "^source: not valid text"),
    (lambda: ofv.Scene.from_json(1), TypeError, "^text: expected a str, got a int$"),
])
def test_numbers_that_do_not_fit_and_text_no_file_can_hold_raise_the_documented_errors(call, error, message):
    with pytest.raises(error, match=message):
        call()


def test_a_path_with_a_nul_writes_nothing(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    positions, normals, _ = _scene_arrays()
    with pytest.raises(ValueError, match="^path: contains a NUL character$"):
        ofv.Scene(positions, normals).save("scene\0.json")
    assert list(tmp_path.iterdir()) == []  # not a file "scene" beside it


def test_numpy_scalars_are_numbers():
    assert ofv.EstimatorSettings(r_sphere=np.float32(0.25), max_iterations=np.int64(9)).to_dict()["r_sphere"] == 0.25


# --- scenes


def _scene_arrays():
    rng = np.random.default_rng(3)
    positions = rng.normal(scale=0.03, size=(40, 3))
    normals = np.tile([0.0, 0.2, 1.0], (40, 1)) + rng.normal(scale=0.1, size=(40, 3))
    occluders = rng.normal(loc=[0.0, 0.05, 0.25], scale=0.02, size=(30, 3))
    return positions, normals, occluders


def test_saved_scene_reads_back_and_gives_the_same_estimate_on_the_command_line(tmp_path, cli_json):
    positions, normals, occluders = _scene_arrays()
    scene = ofv.Scene(positions, normals, occluders, camera=[0.0, 0.0, 0.6], previous_view=np.array([0.1, 0.0, 0.4]),
                      axes=np.eye(3)[[1, 0, 2]], r_sphere=0.4, step="r_seed", max_iterations=300, time_budget=2.5)
    path = tmp_path / "scene.json"
    ofv.save_scene(scene, path)
    back = ofv.load_scene(path)
    for key in ("positions", "normals", "occluders", "camera", "previous_view", "axes"):
        np.testing.assert_array_equal(getattr(back, key), getattr(scene, key), err_msg=key)
    assert back.centroid is None
    assert back.settings == scene.settings and back.settings.time_budget == 2.5
    assert json.loads(scene.to_json()) == json.loads(path.read_text())
    assert scene.estimate().to_dict() == cli_json("estimate", path, "--compact")


def test_scene_settings_are_the_scenes_own():
    positions, normals, occluders = _scene_arrays()
    scene = ofv.Scene(positions, normals, occluders)
    scene.settings.r_sphere = 0.3  # a reference into the scene, not a copy
    assert scene.settings.r_sphere == 0.3
    assert scene.estimate().to_dict() == ofv.estimate_view(positions, normals, occluders, r_sphere=0.3).to_dict()


def test_scene_errors_name_the_file_as_the_command_line_does(tmp_path, run_cli):
    # Opposite normals leave t0 to the camera fallback; without a camera it is an error (spec §2).
    bad = tmp_path / "no-camera.json"
    ofv.save_scene(ofv.Scene([[0.0, 0.0, 0.0], [0.0, 0.0, 0.001]], [[0.0, 0.0, 1.0], [0.0, 0.0, -1.0]]), bad)
    code, _, err = run_cli("estimate", bad)
    assert code == 2
    with pytest.raises(ValueError) as raised:
        ofv.load_scene(bad).estimate()
    assert "ofv estimate: " + str(raised.value) == err.strip()
    broken = tmp_path / "broken.json"
    broken.write_text('{"supervoxels": [{"position": [0, 0, 0], "normal": "up"}]}')
    code, _, err = run_cli("estimate", broken)
    assert code == 2
    with pytest.raises(ValueError) as raised:
        ofv.load_scene(broken)
    assert "ofv estimate: " + str(raised.value) == err.strip()
    with pytest.raises(ValueError, match="no-such-file.json"):
        ofv.load_scene(tmp_path / "no-such-file.json")


# --- arrays: the wrong dtype or shape is refused, any layout read right


def test_arrays_of_any_layout_are_read_by_their_strides():
    positions, normals, occluders = _scene_arrays()
    expected = ofv.estimate_view(positions, normals, occluders).to_dict()
    wide = np.zeros((40, 9))
    wide[:, 3:6] = positions
    views = {
        "fortran": np.asfortranarray(positions),
        "column slice": wide[:, 3:6],
        "transposed": np.ascontiguousarray(positions.T).T,
        "reversed twice": positions[::-1][::-1],
    }
    for name, p in views.items():
        assert not p.flags.c_contiguous or name == "reversed twice", name
        assert ofv.estimate_view(p, normals, occluders).to_dict() == expected, name
    every_other = ofv.estimate_view(positions[::2], normals[::2], occluders[::3]).to_dict()
    assert every_other == ofv.estimate_view(positions[::2].copy(), normals[::2].copy(), occluders[::3].copy()).to_dict()
    assert ofv.estimate_view(positions.tolist(), normals.tolist(), occluders.tolist()).to_dict() == expected


@pytest.mark.parametrize("bad,error,message", [
    (lambda p: p.astype(np.int64), TypeError, r"positions: expected a float64 array of shape \(N, 3\), got a int64 array"),
    (lambda p: p.astype(np.float32), TypeError, "got a float32 array"),
    (lambda p: p.astype(">f8"), TypeError, "non-native byte order"),
    (lambda p: p.astype(object), TypeError, "got a object array"),
    (lambda p: p.T, ValueError, r"got shape \(3, 40\)"),
    (lambda p: p.ravel(), ValueError, r"got shape \(120,\)"),
    (lambda p: p[:, :2], ValueError, r"got shape \(40, 2\)"),
    (lambda p: p[None], ValueError, r"got shape \(1, 40, 3\)"),
    (lambda p: "positions", TypeError, "got a str"),
    (lambda p: [[0.0, 0.0, True]] * 40, TypeError, r"positions\[0\]\[2\]: expected a number"),
    (lambda p: [[0.0, 0.0]] * 40, ValueError, r"positions\[0\]: expected 3 numbers"),
])
def test_wrong_arrays_are_refused_not_misread(bad, error, message):
    positions, normals, occluders = _scene_arrays()
    with pytest.raises(error, match=message):
        ofv.estimate_view(bad(positions), normals, occluders)


def test_optional_points_and_counts_are_checked():
    positions, normals, occluders = _scene_arrays()
    with pytest.raises(ValueError, match=r"normals: expected one normal per position \(40\), got 39"):
        ofv.estimate_view(positions, normals[:39], occluders)
    with pytest.raises(ValueError, match=r"camera: expected a float64 array of shape \(3,\)"):
        ofv.estimate_view(positions, normals, camera=[0.0, 0.5])
    with pytest.raises(TypeError, match="centroid"):
        ofv.estimate_view(positions, normals, centroid=np.zeros(3, dtype=np.int32))
    with pytest.raises(ValueError, match=r"axes: expected a float64 array of shape \(3, 3\)"):
        ofv.estimate_view(positions, normals, axes=np.eye(4))
    with pytest.raises(ValueError, match="camera"):  # non-finite optional points: the estimator's message
        ofv.estimate_view(positions, normals, camera=[math.nan, 0.0, 0.5])


def test_no_usable_supervoxel_is_a_status():
    e = ofv.estimate_view(np.full((2, 3), np.nan), np.ones((2, 3)), camera=[0.0, 0.0, 1.0])
    assert e.status == ofv.ViewStatus.no_supervoxels and e.skipped_supervoxels == 2
    np.testing.assert_array_equal(e.tf, [0.0, 0.0, 1.0])
    assert e.error_t0 is None


def test_results_are_copies():
    positions, normals, occluders = _scene_arrays()
    kept = positions.copy()
    e = ofv.estimate_view(positions, normals, occluders)
    e.tf[:] = 0.0
    assert np.any(e.tf != 0.0)
    np.testing.assert_array_equal(positions, kept)


def test_the_gil_is_released_while_estimating():
    # An object caged on every side has no free view: the iteration runs until time_budget.
    rng = np.random.default_rng(1)
    directions = rng.normal(size=(3000, 3))
    cage = 0.2 * directions / np.linalg.norm(directions, axis=1, keepdims=True)
    positions, normals, _ = _scene_arrays()
    e, inside = samples_while_running(
        lambda: ofv.estimate_view(positions, normals, cage, max_iterations=100000000, time_budget=0.4))
    assert e.status == ofv.ViewStatus.out_of_time
    assert inside > 20  # another Python thread ran while the estimator did
