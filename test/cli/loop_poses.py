#!/usr/bin/env python3
"""Setting `poses` end to end through the `ofv` binary: `ofv simulate --poses
odometry` (trajectory.csv's pose columns, metrics.json's poses block, the
summary), its usage errors, and `ofv run --poses odometry --dry-run`
replaying the episode's recording with the same commands and pose statuses.

usage: loop_poses.py OFV OUT_DIR
"""
import csv
import json
import pathlib
import shutil
import subprocess
import sys

STATUSES = {"first_frame", "ok", "failed", "implausible"}
# As test/loop/test_one_loop.cpp: the object found as `ofv run` finds it in a recording.
SETTINGS = ["--set", "gain=5", "--set", "target_hysteresis=false", "--set", "select=auto"]


def ofv(binary, *args):
    return subprocess.run([binary, *args], capture_output=True, text=True)


def check(condition, what):
    if not condition:
        print("FAILED: " + what)
        sys.exit(1)
    print("ok: " + what)


def main():
    binary, out = sys.argv[1], pathlib.Path(sys.argv[2])
    shutil.rmtree(out, ignore_errors=True)
    episode, frames = out / "episode", out / "frames"

    r = ofv(binary, "simulate", "dvd-one-hand", "--set", "duration=1.5", "--poses", "odometry", "--no-pictures",
            *SETTINGS, "--out", str(episode), "--record", str(frames))
    check(r.returncode == 0, "ofv simulate --poses odometry runs: " + r.stderr)
    check(", poses odometry" in r.stdout and "poses: odometry, ATE " in r.stdout, "the summary names the poses")
    rows = list(csv.DictReader(open(episode / "trajectory.csv")))
    check(len(rows) == 46, "46 rows")
    check(rows[0]["pose_status"] == "first_frame" and float(rows[0]["pose_error_m"]) == 0.0,
          "the first pose is the true one")
    check(all(row["pose_status"] in STATUSES for row in rows), "every row has a pose status")
    worst = max(float(row["pose_error_m"]) for row in rows)
    check(0.0 < worst < 0.01, f"pose errors of millimetres ({1000 * worst:.2f} mm at worst)")
    for row in rows:
        if row["pose_status"] in ("failed", "implausible"):
            check(row["safety"] == "pose unknown", f"t={row['time']}: a pose unknown stops")
    m = json.loads((episode / "metrics.json").read_text())
    poses = m["poses"]
    check(poses["source"] == "odometry" and 0.0 < poses["ate_m"] < 0.005, f"ATE {poses['ate_m']} m")
    check(sum(poses["status_counts"].values()) == m["steps"], "frames per status add up")
    check(abs(poses["max_translation_error_m"] - worst) < 1e-9, "the worst error is the trajectory's")

    # The same frames replayed by `ofv run` with odometry: the same poses, the same commands.
    r = ofv(binary, "run", "--robot", "camera", "--source", str(frames), "--poses", "odometry", "--dry-run", *SETTINGS[:4])
    check(r.returncode == 0, "ofv run --poses odometry --dry-run runs: " + r.stderr)
    lines = [json.loads(line) for line in r.stdout.splitlines() if line.strip()]
    check(len(lines) == len(rows) + 1 and lines[-1]["status"] == "stop", "a line per frame, then the stop")
    check([line["pose"] for line in lines[:-1]] == [row["pose_status"] for row in rows], "the same pose statuses")
    difference = max(abs(line["v"][i] - float(row[name])) for line, row in zip(lines, rows)
                     for i, name in enumerate(["vx", "vy", "vz", "wx", "wy", "wz"]))
    check(difference <= 1e-9, f"the same commands (largest difference {difference:g})")
    check(", poses odometry: 0 unknown" in r.stderr, "the run's summary counts the unknown poses")
    r = ofv(binary, "run", "--robot", "camera", "--source", str(frames), "--dry-run", "--set", "duration=0.2")
    check(r.returncode == 0 and '"pose"' not in r.stdout, "without a pose source the lines have no pose")

    # The rehearsal on ViSP's threaded arm: the lines carry the pose's status, the summary the poses block.
    r = ofv(binary, "run", "--robot", "viper850", "--source", "sim:dvd-static", "--poses", "odometry", "--dry-run",
            "--set", "duration=0.5")
    lines = [json.loads(line) for line in r.stdout.splitlines() if line.startswith("{")]
    check(r.returncode == 0 and len(lines) >= 2 and all(line["pose"] in STATUSES for line in lines[:-1]),
          "a rehearsal's lines carry the pose status: " + r.stderr)
    check("poses: odometry, ATE " in r.stdout + r.stderr, "a rehearsal's summary has the poses")

    # Usage errors: exit 2 and one line naming the setting.
    for args, word in [(["--poses", "odometry", "--perception", "ground-truth"], "perception"),
                       (["--poses", "odometry:nope"], "odometry:fast_icp"),
                       (["--poses", "odometry:"], "odometry:fast_icp"),
                       (["--poses", "odometry", "--set", "poses=simulator"], "--poses"),
                       (["--poses", "odometry", "--set", "method=hindsight"], "hindsight")]:
        r = ofv(binary, "simulate", "dvd-static", "--set", "duration=0.1", "--no-pictures", "--out", str(out / "bad"),
                *args)
        check(r.returncode == 2 and word in r.stderr and r.stderr.count("\n") == 1,
              " ".join(args) + " is a usage error: " + r.stderr.strip())
    r = ofv(binary, "run", "--robot", "camera", "--source", str(frames), "--poses", "gps", "--dry-run")
    check(r.returncode == 2 and "poses" in r.stderr, "ofv run --poses gps is a usage error: " + r.stderr.strip())


if __name__ == "__main__":
    main()
