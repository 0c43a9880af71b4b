"""EXR files and error metrics."""

import numpy as np
import pytest

import fppm
from conftest import run_cli


def test_write_and_read_exr_round_trip(tmp_path):
    rng = np.random.default_rng(1)
    image = rng.random((30, 40, 3), dtype=np.float32)
    albedo = rng.random((30, 40, 3), dtype=np.float32)
    depth = rng.random((30, 40), dtype=np.float32)
    path = tmp_path / "x.exr"
    fppm.write_exr(path, image, aovs={"albedo": albedo, "depth": depth}, metadata={"note": "hi"})
    back = fppm.read_exr(path)
    assert back.dtype == np.float32 and back.shape == (30, 40, 3)
    assert np.array_equal(back, image)
    # float64 and non-contiguous arrays are converted.
    fppm.write_exr(path, image.astype(np.float64)[:, ::-1])
    assert np.array_equal(fppm.read_exr(path), image[:, ::-1])


def test_write_exr_refuses_bad_shapes_and_names(tmp_path):
    path = tmp_path / "x.exr"
    with pytest.raises(ValueError, match=r"image has shape \[4, 4\], not height x width x 3"):
        fppm.write_exr(path, np.zeros((4, 4)))
    with pytest.raises(ValueError, match='"colour" is not an aov'):
        fppm.write_exr(path, np.zeros((4, 4, 3)), aovs={"colour": np.zeros((4, 4))})
    with pytest.raises(ValueError, match="aov depth is 2x2 but the image is 4x4"):
        fppm.write_exr(path, np.zeros((4, 4, 3)), aovs={"depth": np.zeros((2, 2))})
    with pytest.raises(TypeError, match="image is not an array of numbers"):
        fppm.write_exr(path, "pixels")
    with pytest.raises(OSError, match="cannot write file"):
        fppm.write_exr(tmp_path / "no" / "such" / "dir.exr", np.zeros((4, 4, 3)))


def test_read_exr_errors(tmp_path):
    with pytest.raises(OSError, match="cannot read exr"):
        fppm.read_exr(tmp_path / "missing.exr")
    (tmp_path / "bad.exr").write_bytes(b"not an exr")
    with pytest.raises(OSError, match="bad.exr: cannot read exr"):
        fppm.read_exr(tmp_path / "bad.exr")


def test_diff_is_the_commands(tmp_path):
    rng = np.random.default_rng(2)
    a = rng.random((20, 30, 3), dtype=np.float32)
    b = (a + rng.normal(0, 0.05, a.shape)).astype(np.float32)
    fppm.write_exr(tmp_path / "a.exr", a)
    fppm.write_exr(tmp_path / "b.exr", b)
    import json

    expected = json.loads(run_cli("diff", str(tmp_path / "a.exr"), str(tmp_path / "b.exr"), "--json").stdout)
    for got in (fppm.diff(a, b), fppm.diff(tmp_path / "a.exr", str(tmp_path / "b.exr"))):
        assert got == expected
    assert fppm.diff(a, a)["rmse"] == 0
    with pytest.raises(ValueError, match="image is 30x20 but the reference is 2x2"):
        fppm.diff(a, np.zeros((2, 2, 3)))
    assert np.isnan(fppm.diff(a, np.zeros_like(a))["mean_ratio"])
