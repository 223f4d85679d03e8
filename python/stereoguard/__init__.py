"""stereoguard: stereo-camera obstacle detection (docs/python.md).

Detector processes frames one at a time on the caller's thread; run() iterates over the events of
the CLI's pipeline on any input `stereoguard run` takes. Both give dicts shaped like one line of
`stereoguard run --events`. Problems with the input raise Error (a ValueError).
"""
import json
import os
import tempfile

from ._stereoguard import Error, EventStream, version
from . import _stereoguard

__all__ = ["Detector", "Error", "run", "version"]


class _Config:
    """A config argument as a file path: a path as given, a dict written to a temporary YAML file
    (JSON is YAML) that lives as long as this object; None = no config."""

    def __init__(self, config):
        self._file = None
        if config is None:
            self.path = ""
        elif isinstance(config, (str, os.PathLike)):
            self.path = os.fspath(config)
        elif isinstance(config, dict):
            self._file = tempfile.NamedTemporaryFile("w", suffix=".yaml", prefix="sg-config-")
            json.dump(config, self._file)
            self._file.flush()
            self.path = self._file.name
        else:
            raise TypeError("config: expected None, a config.yaml path or a dict")

    def error(self, e):
        """e with the temporary file's name replaced by 'config dict'."""
        if self._file is None:
            return e
        return Error(str(e).replace("config file " + self.path, "config dict")
                     .replace(self.path, "config dict"))


class Detector:
    """The detector, one frame at a time: Detector(camera, config=None, platform=None).

    camera: a camera.yaml path or dict(focal_px, baseline_m[, cx, cy, width, height, fps]);
    without width/height the first frame's size is taken, cx/cy default to the image centre.
    config: None, a config YAML path, or a dict with the same keys. platform: None (the config's,
    else robot), "robot", "walker" or "car". Defaults derived from the camera as the CLI does.
    """

    def __init__(self, camera, config=None, platform=None):
        if isinstance(camera, os.PathLike):
            camera = os.fspath(camera)
        self._config = _Config(config)
        try:
            self._impl = _stereoguard.Detector(camera, self._config.path, platform)
        except Error as e:
            raise self._config.error(e) from None

    def process(self, left, right, t_s):
        """Detects on one stereo pair (uint8 numpy arrays, gray (H, W) or BGR (H, W, 3)) taken at
        t_s seconds; frames in stream order. Returns one events line as a dict."""
        try:
            return self._impl.process(left, right, float(t_s))
        except Error as e:
            raise self._config.error(e) from None

    @property
    def disparity(self):
        """The last frame's disparity, float32 (H, W) px, invalid < 0; a view, no copy."""
        return self._impl.disparity

    @property
    def flow(self):
        """The last frame's backward flow to the previous left image, float32 (H, W, 2) px; None
        for the first frame or a detector without flow."""
        return self._impl.flow


class _Events:
    """Iterator over a run's events; keeps a dict config's file alive while the run reads it."""

    def __init__(self, stream, config):
        self._stream = stream
        self._config = config

    def __iter__(self):
        return self

    def __next__(self):
        try:
            return next(self._stream)
        except Error as e:
            raise self._config.error(e) from None

    @property
    def summary(self):
        """The run's summary (as `stereoguard run --summary`) once every event was read."""
        return self._stream.summary


def run(scenario=None, config=None, **inputs):
    """Runs the pipeline as `stereoguard run` does and iterates over its events (dicts).

    One input: scenario= (built-in name or YAML; default "head-on"), input= (stereo folder),
    left=/right=, sbs=, kitti=, euroc=, camera=[I, J], with calib= or focal=/baseline=/cx=/cy=,
    input_fps=. Options: config= (path or dict), platform=, detector=, workers=, tiles=, tokens=,
    threads=, fps= (pacing), scale=. Errors in the input raise Error here; errors met while
    running raise from the iteration.
    """
    config = _Config(config)
    for key, value in list(inputs.items()):
        if isinstance(value, os.PathLike):
            inputs[key] = os.fspath(value)
    try:
        stream = _stereoguard._run(scenario=scenario, config=config.path, **inputs)
    except Error as e:
        raise config.error(e) from None
    return _Events(stream, config)
