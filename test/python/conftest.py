"""Shared fixtures of the Python tests: the module under test, the `ofv`
program of the same build (for comparisons with the command line), the
test data. ctest sets PYTHONPATH and OFV_BINARY (python/CMakeLists.txt)."""

import json
import os
import pathlib
import subprocess

import pytest

import ofv

DATA = pathlib.Path(__file__).resolve().parent.parent / "data"

# Compute times are wall-clock measurements: every other value of an episode is deterministic.
TIMING_METRICS = {"max_compute_time", "mean_compute_time"}
TIMING_COLUMNS = {"render_s", "perception_s", "estimate_s", "control_s"}


def _ofv_binary():
    path = os.environ.get("OFV_BINARY")
    if not path:  # the module in <build>/python/ofv, the program in <build>/bin
        path = str(pathlib.Path(ofv.__file__).resolve().parent.parent.parent / "bin" / "ofv")
    return path


@pytest.fixture(scope="session")
def ofv_bin():
    path = _ofv_binary()
    if not os.access(path, os.X_OK):
        pytest.fail(f"the ofv program {path} is missing: set OFV_BINARY")
    return path


@pytest.fixture(scope="session")
def run_cli(ofv_bin):
    """Runs `ofv ARGS...`; returns (exit code, stdout, stderr)."""

    def run(*args, cwd=None):
        p = subprocess.run([ofv_bin, *map(str, args)], capture_output=True, text=True, cwd=cwd, timeout=120)
        return p.returncode, p.stdout, p.stderr

    return run


@pytest.fixture(scope="session")
def cli_json(run_cli):
    """`ofv ARGS...` that must succeed and print one JSON object."""

    def run(*args):
        code, out, err = run_cli(*args)
        assert code == 0, err
        return json.loads(out)

    return run


needs_simulation = pytest.mark.skipif(not ofv.HAS_SIMULATION, reason="ofv built without the closed loop")


def samples_while_running(call):
    """Runs call() while another Python thread records the time in a loop;
    returns (call's result, how many of those records fall well inside the
    call). Holding the GIL for the whole call would leave none there."""
    import threading
    import time

    stamps = []
    stop = threading.Event()

    def record():
        while not stop.is_set():
            stamps.append(time.monotonic())
            time.sleep(0.001)

    thread = threading.Thread(target=record)
    thread.start()
    time.sleep(0.02)
    start = time.monotonic()
    result = call()
    end = time.monotonic()
    stop.set()
    thread.join()
    margin = 0.1 * (end - start)
    return result, sum(start + margin < t < end - margin for t in stamps)
