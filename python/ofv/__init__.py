"""ofv: occlusion-free view estimation and visual servoing, from Python.

The estimator of Cuiral-Zueco and Lopez-Nicolas (ESTIMATOR-SPEC.md) on numpy
arrays, the scene files of ``ofv estimate``, and the simulated closed loop of
``ofv simulate``, ``ofv render`` and ``ofv compare``: the same C++ libraries,
settings (by the names of ``ofv settings``), results and error messages as the
command line.

    >>> import numpy as np, ofv
    >>> positions = np.array([[0.0, 0.0, 0.0], [0.01, 0.0, 0.0]])
    >>> normals = np.array([[0.0, 0.0, 1.0], [0.0, 0.0, 1.0]])
    >>> e = ofv.estimate_view(positions, normals, np.array([[0.0, 0.0, 0.2]]), r_sphere=0.4)
    >>> e.status, e.tf                                         # doctest: +SKIP
    >>> ep = ofv.simulate("dvd-one-hand", duration=0.5, perception="ground-truth")
    >>> ep.metrics["mean_visible_fraction"], ep.trajectory["visible_fraction"]  # doctest: +SKIP

Arrays are float64 numpy arrays (any strides) or lists of numbers; other
dtypes raise TypeError, other shapes ValueError. Bad input raises ValueError
with the command line's message (numbers out of range however large, text
with a NUL or a lone surrogate), an argument of another type TypeError, any
other failure RuntimeError. The GIL is
released while the estimator, episodes, renders and sweeps run.
"""

import os
import shutil
import tempfile

from . import _ofv
from ._ofv import (
    AngularErrorStats,
    EstimatorSettings,
    InitialViewUsed,
    Scene,
    ViewEstimate,
    ViewStatus,
    __version__,
    estimate_view,
    git_commit,
    estimator_settings,
)
from ._tables import read_csv_columns

__all__ = [
    "AngularErrorStats",
    "EstimatorSettings",
    "InitialViewUsed",
    "Scene",
    "ViewEstimate",
    "ViewStatus",
    "__version__",
    "estimate_view",
    "estimator_settings",
    "git_commit",
    "load_scene",
    "save_scene",
]


def load_scene(path):
    """Reads a scene file (the JSON of ``ofv estimate``) into a Scene.

    Raises ValueError naming the file, the field and the value."""
    return Scene.load(os.fspath(path))


def save_scene(scene, path):
    """Writes a Scene as the JSON that ``ofv estimate`` and load_scene read."""
    if not isinstance(scene, Scene):
        raise TypeError(f"scene: expected an ofv.Scene, got a {type(scene).__name__}")
    scene.save(os.fspath(path))


# The simulator side exists when ofv was built with the closed loop (sim, servo, loop).
HAS_SIMULATION = hasattr(_ofv, "simulate")

if HAS_SIMULATION:
    from ._ofv import (
        LABEL_BACKGROUND,
        LABEL_INTERACTING,
        LABEL_NONE,
        LABEL_OBJECT,
        LABEL_OCCLUDER0,
        Episode,
        Frame,
        Scenario,
        builtin_scenarios,
        episode_settings,
        load_scenario,
        render,
        simulate,
    )

    __all__ += [
        "LABEL_BACKGROUND",
        "LABEL_INTERACTING",
        "LABEL_NONE",
        "LABEL_OBJECT",
        "LABEL_OCCLUDER0",
        "Episode",
        "Frame",
        "Scenario",
        "builtin_scenarios",
        "compare",
        "episode_settings",
        "load_scenario",
        "read_compare",
        "render",
        "simulate",
    ]


def read_compare(out):
    """The tables of an ``ofv compare`` output folder, in a form pandas reads
    directly (``pandas.DataFrame(tables["summary"])``).

    Returns {"episodes": ..., "summary": ...} (and "missing" when the folder
    has a missing.csv, from an incomplete merge), each a dict of numpy columns
    named as the CSV file's header: one row per episode (every setting and
    metric) and per scenario x variant (means and 95 % intervals over seeds).
    Integer columns are int64, numbers float64 (an empty field is NaN), the
    rest str. Raises FileNotFoundError when a table is missing."""
    out = os.fspath(out)
    tables = {}
    for name in ("episodes", "summary", "missing"):
        path = os.path.join(out, name + ".csv")
        if name == "missing" and not os.path.exists(path):
            continue
        if not os.path.exists(path):
            raise FileNotFoundError(f"{path}: no such file (is {out} an `ofv compare` output folder?)")
        tables[name] = read_csv_columns(path)
    return tables


def compare(scenarios, grid, *, seeds=None, jobs=None, out=None, shard=None, plots=None):
    """Runs a comparison sweep, as ``ofv compare`` (docs/compare.md), and
    returns its tables (read_compare()).

    scenarios: a scenario name or file, a folder of them, or a list of these.
    grid: a grid file (YAML) or the same grid as a dict, e.g.
    ``{"seeds": 1, "set": {"duration": 1}, "variants": [{"name": "paper"},
    {"name": "static", "set": {"method": "static"}}]}``. seeds: seeds per
    scenario x variant (default: the grid's); jobs: episodes in parallel
    (default: one per core); shard: "K/N", part K of N of the sweep.
    out: the output folder (resumable: finished episodes are kept); None runs
    in a temporary folder removed afterwards. plots: also the PNG plots
    (default: when out is given).

    Returns the tables dict of read_compare() plus "run": planned, episodes,
    ran, resumed and out. Raises ValueError on a bad grid, scenario or
    argument (before anything runs), RuntimeError when an episode fails.
    The GIL is released while the sweep runs."""
    if not HAS_SIMULATION:
        raise RuntimeError("ofv was built without the closed loop (sim, servo, loop): no compare")
    scratch = None
    if out is None:
        scratch = tempfile.mkdtemp(prefix="ofv-compare-")
        out = scratch
    try:
        run = _ofv._compare(
            scenarios,
            grid,
            os.fspath(out),
            seeds=seeds,
            jobs=jobs,
            shard=shard,
            plots=(scratch is None) if plots is None else bool(plots),
        )
        tables = read_compare(out)
    finally:
        if scratch is not None:
            shutil.rmtree(scratch, ignore_errors=True)
    tables["run"] = run
    if scratch is not None:
        tables["run"]["out"] = ""
    return tables
