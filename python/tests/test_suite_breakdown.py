"""scripts/suite_breakdown.py on a small suite written by the CLI."""
import json
import os
import subprocess
import sys

from conftest import cli


def test_breakdown_groups_every_scene(tmp_path):
    suite = tmp_path / "suite.json"
    subprocess.run([cli(), "eval", "--suite", "random", "--count", "4", "--seed", "1000",
                    "--max-size", "320x240", "--max-frames", "12", "--quiet", "--json", str(suite)],
                   check=True, stdout=subprocess.DEVNULL)
    script = os.path.join(os.environ["SG_SOURCE_DIR"], "scripts", "suite_breakdown.py")
    out = subprocess.run([sys.executable, script, str(suite)], check=True, capture_output=True,
                         text=True).stdout
    scenes = json.load(open(suite))["scenes"]
    # Each platform's line counts its colliding and clear scenes; together, every scene.
    lines = out.split("ego motion:")[0].splitlines()[1:]
    counted = {}
    for line in lines:
        words = line.split()
        counted[words[0]] = int(words[2]) + int(words[6])
    expected = {}
    for s in scenes:
        expected[s["platform"]] = expected.get(s["platform"], 0) + 1
    assert counted == expected
    assert "obstacle texture:" in out and "lowest recall_settled" in out


def test_breakdown_refuses_a_file_without_traits(tmp_path):
    bad = tmp_path / "bad.json"
    bad.write_text(json.dumps({"scenes": [{"seed": 1}]}))
    script = os.path.join(os.environ["SG_SOURCE_DIR"], "scripts", "suite_breakdown.py")
    r = subprocess.run([sys.executable, script, str(bad)], capture_output=True, text=True)
    assert r.returncode == 2
    assert "not a suite JSON with scene traits" in r.stderr
