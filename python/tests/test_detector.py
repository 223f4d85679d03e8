"""sg.Detector: the same detections as sg.run, arrays in and out, clear errors."""
import numpy as np
import pytest

import stereoguard as sg
from conftest import read_pairs, strip_timing


@pytest.fixture(scope="module")
def pairs(folder):
    return list(read_pairs(folder))


def fps_of(folder):
    for line in open(folder / "camera.yaml"):
        if line.startswith("fps:"):
            return float(line.split(":")[1])
    raise AssertionError("camera.yaml without fps")


def test_process_matches_run_on_the_same_frames(folder, pairs):
    expected = [strip_timing(e) for e in sg.run(input=str(folder))]
    det = sg.Detector(camera=str(folder / "camera.yaml"))
    fps = fps_of(folder)
    got = [det.process(l, r, i / fps) for i, (l, r) in enumerate(pairs)]
    assert len(got) == len(expected) == len(pairs)
    for ours, theirs in zip(got, expected):
        assert ours == theirs, ours["frame"]
    assert any(e["signal"] for e in got)


def test_disparity_and_flow_arrays(folder, pairs):
    det = sg.Detector(camera=str(folder / "camera.yaml"))
    assert det.disparity is None and det.flow is None
    (l0, r0), (l1, r1) = pairs[0], pairs[1]
    det.process(l0, r0, 0.0)
    h, w = l0.shape
    d = det.disparity
    assert d.dtype == np.float32 and d.shape == (h, w)
    valid = d >= 0
    assert valid.mean() > 0.3 and np.isfinite(d[valid]).all() and d[valid].max() > 1
    assert det.flow is None  # nothing to compare the first frame with
    det.process(l1, r1, 0.05)
    f = det.flow
    assert f.dtype == np.float32 and f.shape == (h, w, 2) and np.isfinite(f).all()
    assert not np.shares_memory(d, det.disparity)  # a new map per frame; the old one stays valid
    assert np.isfinite(d[valid]).all()


def test_disparity_is_a_view_not_a_copy(folder, pairs):
    det = sg.Detector(camera=str(folder / "camera.yaml"))
    det.process(*pairs[0], 0.0)
    a, b = det.disparity, det.disparity
    assert np.shares_memory(a, b)


def test_gray_and_bgr_give_the_same_result(folder, pairs):
    gray = sg.Detector(camera=str(folder / "camera.yaml"))
    bgr = sg.Detector(camera=str(folder / "camera.yaml"))
    for i, (l, r) in enumerate(pairs[:12]):
        a = gray.process(l, r, i / 30)
        b = bgr.process(np.dstack([l, l, l]), np.dstack([r, r, r]), i / 30)
        assert a == b
        assert np.array_equal(gray.disparity, bgr.disparity)


def test_camera_dict_equals_camera_file(folder, pairs):
    fields = {}
    for line in open(folder / "camera.yaml"):
        key, _, value = line.partition(":")
        if key in ("focal_px", "baseline_m", "cx", "cy", "fps"):
            fields[key] = float(value)
    h, w = pairs[0][0].shape
    by_dict = sg.Detector(camera=dict(fields, width=w, height=h))
    by_file = sg.Detector(camera=str(folder / "camera.yaml"))
    for i, (l, r) in enumerate(pairs[:8]):
        assert by_dict.process(l, r, i / 30) == by_file.process(l, r, i / 30)


def test_non_contiguous_input_is_accepted(folder, pairs):
    l, r = pairs[0]
    det = sg.Detector(camera=str(folder / "camera.yaml"))
    wide_l = np.zeros((l.shape[0], l.shape[1] * 2), np.uint8)
    wide_l[:, ::2] = l
    ref = sg.Detector(camera=str(folder / "camera.yaml")).process(l, r, 0.0)
    assert det.process(wide_l[:, ::2], r, 0.0) == ref


@pytest.mark.parametrize("bad, what", [
    (lambda l: l.astype(np.float32), "float32"),
    (lambda l: l[:, :, None].repeat(4, axis=2), "(H, W, 3)"),
    (lambda l: l.ravel(), "(H, W)"),
])
def test_bad_array_raises_value_error(folder, pairs, bad, what):
    det = sg.Detector(camera=str(folder / "camera.yaml"))
    l, r = pairs[0]
    with pytest.raises(ValueError, match="left: expected") as e:
        det.process(bad(l), r, 0.0)
    assert what in str(e.value)


def test_mismatched_sizes_raise_value_error(folder, pairs):
    det = sg.Detector(camera=str(folder / "camera.yaml"))
    l, r = pairs[0]
    with pytest.raises(ValueError, match="differ in size"):
        det.process(l, r[:-2], 0.0)


def test_frame_size_other_than_the_camera_raises_error(pairs):
    h, w = pairs[0][0].shape
    det = sg.Detector(camera=dict(focal_px=500, baseline_m=0.12, width=w + 16, height=h))
    with pytest.raises(sg.Error):
        det.process(*pairs[0], 0.0)


def test_missing_camera_file_raises_error(tmp_path):
    missing = tmp_path / "camera.yaml"
    with pytest.raises(sg.Error, match="missing camera file") as e:
        sg.Detector(camera=str(missing))
    assert isinstance(e.value, ValueError) and str(missing) in str(e.value)


def test_bad_camera_dict_raises_error():
    with pytest.raises(sg.Error, match="camera.baseline_m: missing"):
        sg.Detector(camera=dict(focal_px=500))
    with pytest.raises(sg.Error, match="camera.focal: unknown key"):
        sg.Detector(camera=dict(focal=500, baseline_m=0.1))


def test_bad_config_dict_raises_error_naming_the_key():
    with pytest.raises(sg.Error, match="no_such_key") as e:
        sg.Detector(camera=dict(focal_px=500, baseline_m=0.12), config={"no_such_key": 1})
    assert "config dict" in str(e.value)


def test_unknown_platform_raises_error():
    det = sg.Detector(camera=dict(focal_px=500, baseline_m=0.12), platform="boat")
    with pytest.raises(sg.Error, match="boat"):
        det.process(np.zeros((48, 64), np.uint8), np.zeros((48, 64), np.uint8), 0.0)
