#!/usr/bin/env python3
"""The random suite's figures broken down by what the scenes drew.

Reads the JSON of `stereoguard eval --suite random ... --json FILE` and prints, per trait (platform,
ego motion, image size, noise, compression, blur, f B, textures, obstacle shape and path), the
colliding scenes' mean recall_settled and the clear scenes' mean false alarm rate in each group.
A scene with several obstacles counts in the group of each of them. Then the colliding scenes
with the lowest recall and the clear scenes with the most false alarms, with their seeds
(`stereoguard simulate --random --seed S --out DIR` renders one).

Usage: scripts/suite_breakdown.py SUITE.json [--worst N]
"""
import argparse
import json
import statistics
import sys


def bucket(value, edges, unit=""):
    """The label of the interval of `edges` (ascending) that holds value."""
    for edge in edges:
        if value < edge:
            return f"< {edge:g}{unit}"
    return f">= {edges[-1]:g}{unit}"


TRAITS = [
    ("platform", lambda r, s: [r["platform"]]),
    ("ego motion", lambda r, s: [s["ego_motion"]]),
    ("image size", lambda r, s: [f"{r['width']}x{r['height']}"]),
    ("noise sigma", lambda r, s: [bucket(s["noise_sigma"], [1, 2, 3])]),
    ("JPEG quality", lambda r, s: ["none" if s["jpeg_quality"] == 0
                                   else bucket(s["jpeg_quality"], [60, 80])]),
    ("exposure (motion blur)", lambda r, s: [bucket(s["exposure_ms"], [1, 5, 10, 15], " ms")]),
    ("f B (disparity at 1 m)", lambda r, s: [bucket(s["focal_baseline_px_m"], [20, 50, 100, 200],
                                                    " px")]),
    ("shadow casters", lambda r, s: [s["shadow_casters"]]),
    ("ground texture", lambda r, s: [s["ground_texture"]]),
    ("obstacle texture", lambda r, s: sorted(set(s["textures"]))),
    ("obstacle", lambda r, s: sorted(set(f"{a} {b}" for a, b in zip(s["shapes"], s["paths"])))),
]


def order(label):
    """Interval labels in ascending order ("< 5 ms" before "< 10 ms" before ">= 15 ms"), the
    rest alphabetically."""
    parts = label.split()
    try:
        return (0, float(parts[1].rstrip("msxp")), parts[0] == ">=", label)
    except (IndexError, ValueError):
        return (1, 0.0, False, label)


def mean(values):
    return f"{statistics.mean(values):.3f}" if values else "-"


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("suite", help="JSON written by eval --suite random --json")
    parser.add_argument("--worst", type=int, default=15, help="scenes listed at the end")
    args = parser.parse_args()
    try:
        scenes = json.load(open(args.suite))["scenes"]
        for r in scenes:
            r["scene"]["ego_motion"]  # written by eval since the traits were added
    except (OSError, ValueError, KeyError, TypeError) as e:
        print(f"{args.suite}: not a suite JSON with scene traits ({e})", file=sys.stderr)
        return 2
    for name, key in TRAITS:
        groups = {}
        for r in scenes:
            for label in key(r, r["scene"]):
                groups.setdefault(str(label), []).append(r)
        print(f"{name}:")
        for label in sorted(groups, key=order):
            g = groups[label]
            recall = [r["recall_settled"] for r in g if r["colliding"]]
            alarms = [r["false_alarm_rate"] for r in g if not r["colliding"]]
            print(f"  {label:28s} colliding {len(recall):4d}  recall_settled {mean(recall):>6s}"
                  f"   clear {len(alarms):4d}  false alarms {mean(alarms):>6s}")
    colliding = sorted((r for r in scenes if r["colliding"]), key=lambda r: r["recall_settled"])
    clear = sorted((r for r in scenes if not r["colliding"]), key=lambda r: -r["false_alarm_rate"])
    print("lowest recall_settled (colliding):")
    for r in colliding[:args.worst]:
        print(f"  seed {r['seed']}  {r['recall_settled']:.2f}  {r['description']}")
    print("most false alarms (clear):")
    for r in clear[:args.worst]:
        if r["false_alarm_rate"] > 0:
            print(f"  seed {r['seed']}  {r['false_alarm_rate']:.3f}  {r['description']}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
