#!/usr/bin/env python3
"""Runs a scenario with stereoguard and plots the nearest obstacle's distance and the smallest
time to contact over time, with the frames that raised an alarm shaded.

Usage: plot_distance_ttc.py OUT.png [SCENARIO]   (SCENARIO: built-in name or YAML; default
head-on). Needs the module on PYTHONPATH (docs/python.md).
"""
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

import stereoguard as sg  # noqa: E402


def main(argv):
    if len(argv) not in (2, 3):
        sys.exit(__doc__)
    out, scenario = argv[1], argv[2] if len(argv) == 3 else "head-on"
    times, nearest, ttc, alarm = [], [], [], []
    for event in sg.run(scenario=scenario):
        obstacles = event["obstacles"]
        times.append(event["time_s"])
        nearest.append(min((o["distance_m"] for o in obstacles), default=float("nan")))
        ttcs = [o["ttc_s"] for o in obstacles if o["ttc_s"] is not None]
        ttc.append(min(ttcs, default=float("nan")))
        alarm.append(event["signal"])

    fig, (top, bottom) = plt.subplots(2, 1, sharex=True, figsize=(8, 5))
    top.plot(times, nearest, ".-", ms=3)
    top.set_ylabel("nearest obstacle (m)")
    bottom.plot(times, ttc, ".-", ms=3, color="tab:red")
    bottom.set_ylabel("smallest TTC (s)")
    bottom.set_xlabel("time (s)")
    for axis in (top, bottom):
        axis.fill_between(times, 0, 1, where=alarm, step="mid", alpha=0.15, color="tab:orange",
                          transform=axis.get_xaxis_transform(), label="alarm")
        axis.grid(alpha=0.3)
    top.legend(loc="upper right")
    top.set_title(f"stereoguard {sg.version}: scenario {scenario}")
    fig.tight_layout()
    fig.savefig(out, dpi=100)
    print(f"{out}: {len(times)} frames, {sum(alarm)} alarm frames")


if __name__ == "__main__":
    main(sys.argv)
