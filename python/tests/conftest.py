"""Fixtures: the CLI binary (SG_CLI, set by CTest) and scenario data written by it."""
import glob
import json
import os
import subprocess

import numpy as np
import pytest
from PIL import Image


def cli():
    path = os.environ.get("SG_CLI", "")
    if not path or not os.path.exists(path):
        pytest.fail("SG_CLI must name the built stereoguard binary (set by ctest)")
    return path


def strip_timing(event):
    event = dict(event)
    event.pop("latency_ms", None)
    return event


@pytest.fixture(scope="session")
def cli_head_on_events(tmp_path_factory):
    """The events of `stereoguard run --scenario head-on`, one dict per frame."""
    out = tmp_path_factory.mktemp("cli") / "events.jsonl"
    subprocess.run([cli(), "run", "--scenario", "head-on", "--events", str(out), "--no-timing",
                    "--quiet", "--overlay", ""], check=True, stdout=subprocess.DEVNULL)
    with open(out) as f:
        return [json.loads(line) for line in f]


@pytest.fixture(scope="session")
def folder(tmp_path_factory):
    """The head-on-fast scenario rendered into a stereo folder (left/, right/, camera.yaml)."""
    out = tmp_path_factory.mktemp("folder") / "head-on-fast"
    subprocess.run([cli(), "simulate", "--scenario", "head-on-fast", "--out", str(out)],
                   check=True, stdout=subprocess.DEVNULL)
    return out


def read_pairs(folder):
    """(left, right) uint8 gray arrays of a stereo folder, in order."""
    lefts = sorted(glob.glob(str(folder / "left" / "*.png")))
    rights = sorted(glob.glob(str(folder / "right" / "*.png")))
    assert lefts and len(lefts) == len(rights)
    for l, r in zip(lefts, rights):
        yield (np.asarray(Image.open(l).convert("L")), np.asarray(Image.open(r).convert("L")))
