"""Runs examples/python/plot_distance_ttc.py (the path given) into a temporary folder and checks
that it wrote a real PNG picture. Exit status 0 = passed."""
import os
import subprocess
import sys
import tempfile

from PIL import Image

example = sys.argv[1]
with tempfile.TemporaryDirectory() as tmp:
    out = os.path.join(tmp, "plot.png")
    subprocess.run([sys.executable, example, out, "head-on-fast"], check=True)
    assert os.path.getsize(out) > 10_000, os.path.getsize(out)
    with Image.open(out) as image:
        assert image.format == "PNG" and image.size[0] >= 400 and image.size[1] >= 300
        # Not a blank canvas: the curves use more than a handful of colours.
        assert len(image.convert("RGB").getcolors(1 << 16) or range(1 << 16)) > 20
print("example ok")
