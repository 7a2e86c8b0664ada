#!/usr/bin/env python3
"""ofv from Python: estimate an occlusion-free view from numpy arrays, run a
short closed-loop episode, and plot what the camera saw.

    PYTHONPATH=build/python python3 tutorials/python/tutorial-python.py --out visibility.png

(after `cmake --install`, plain `python3` finds the module.)
"""

import argparse

import matplotlib

matplotlib.use("Agg")  # no display needed: the plot goes to a PNG file
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import ofv  # noqa: E402


def estimate_from_arrays():
    # 1. One frame: the object's supervoxels (a 10 cm square patch facing +z,
    # world frame, metres) and the points of a hand 20 cm above it, a little
    # off-centre. Arrays are float64, one point per row.
    u, v = np.meshgrid(np.linspace(-0.05, 0.05, 6), np.linspace(-0.05, 0.05, 6))
    positions = np.column_stack([u.ravel(), v.ravel(), np.zeros(u.size)])
    normals = np.tile([0.0, 0.0, 1.0], (len(positions), 1))
    rng = np.random.default_rng(0)
    hand = rng.normal(loc=[0.02, 0.0, 0.2], scale=[0.03, 0.02, 0.01], size=(200, 3))

    # Settings by the names of `ofv settings`; here the sphere's radius.
    estimate = ofv.estimate_view(positions, normals, hand, r_sphere=0.4)
    print(f"estimate: {estimate.status.name} after {estimate.iterations} pushes")
    print(f"  t0 (occlusion-blind) = {np.round(estimate.t0, 3)}, tf (clear) = {np.round(estimate.tf, 3)}")
    print(f"  the view moved {estimate.tf_to_t0_deg:.1f} deg to clear the hand")
    return estimate


def run_episodes(duration):
    # 2. The closed loop of `ofv simulate`: a hand comes between the DVD case
    # and the camera. The same episode with the camera standing still for
    # comparison (method=static). Settings as with `--set`.
    moving = ofv.simulate("dvd-one-hand", duration=duration)
    static = ofv.simulate("dvd-one-hand", duration=duration, method="static")
    for name, episode in (("ofv", moving), ("static camera", static)):
        m = episode.metrics
        print(f"{name:>13}: mean visible {m['mean_visible_fraction']:.3f}, lowest {m['min_visible_fraction']:.3f}, "
              f"{m['time_below_threshold_s']:.2f} s below {m['visibility_threshold']}")
    return moving, static


def plot(moving, static, path):
    # 3. The trajectory's columns are numpy arrays (those of trajectory.csv):
    # pandas.DataFrame(moving.trajectory) would take them as they are.
    fig, ax = plt.subplots(figsize=(7, 3.5))
    for label, episode, style in (("ofv (sphere law)", moving, "-"), ("static camera", static, "--")):
        t = episode.trajectory
        ax.plot(t["time"], t["visible_fraction"], style, lw=2, label=label)
    threshold = moving.metrics["visibility_threshold"]
    ax.axhline(threshold, color="grey", lw=0.8)
    for event in moving.metrics["occlusions"]:
        ax.axvline(event["onset_s"], color="red", lw=0.8, alpha=0.5)
    ax.set_xlabel("time [s]")
    ax.set_ylabel("visible fraction of the object")
    ax.set_ylim(0.0, 1.02)
    ax.set_title("dvd-one-hand: a hand moves in front of the object")
    ax.legend(loc="lower left")
    fig.tight_layout()
    fig.savefig(path, dpi=100)
    print(f"wrote {path}")


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", default="tutorial-python-visibility.png", help="PNG file of the plot")
    parser.add_argument("--duration", type=float, default=3.0, help="episode length [s]")
    args = parser.parse_args()
    estimate = estimate_from_arrays()
    assert estimate.is_free, "the patch has a clear view on its sphere"
    moving, static = run_episodes(args.duration)
    plot(moving, static, args.out)


if __name__ == "__main__":
    main()
