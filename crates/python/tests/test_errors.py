"""Bad input raises an ordinary exception with the command's one-line message."""

import pytest

import fppm
from conftest import REPO, SHARED


def test_missing_file_is_file_not_found(tmp_path):
    with pytest.raises(FileNotFoundError) as caught:
        fppm.load(tmp_path / "missing.toml")
    assert str(caught.value).startswith(str(tmp_path / "missing.toml"))
    assert "\n" not in str(caught.value)
    assert isinstance(caught.value, OSError)


def test_a_missing_mesh_is_an_os_error(tmp_path):
    scene = tmp_path / "s.toml"
    scene.write_text('format = 1\n[[shapes]]\ntype = "mesh"\nfile = "nope.obj"\n')
    with pytest.raises(OSError, match="nope.obj"):
        fppm.load(scene)


@pytest.mark.parametrize(
    "text, message",
    [
        ("format = 1\n[camera\n", r"<string>.toml: line 2, column 8: invalid toml"),
        ("format = 7\n", r"format"),
        ("format = 1\n", r"<string>.toml"),
        ('format = 1\n[[shapes]]\ntype = "sphere"\ncenter = [0, 0, 0]\nradius = nan\n', r'missing required key "material"'),
    ],
)
def test_malformed_scenes_are_scene_errors(text, message):
    with pytest.raises(fppm.SceneError, match=message) as caught:
        fppm.load_string(text)
    assert "\n" not in str(caught.value)


def test_every_format_refuses_garbage(tmp_path):
    for suffix in ("toml", "obj", "gltf", "glb", "xml", "pbrt"):
        path = tmp_path / f"bad.{suffix}"
        path.write_bytes(b"\x00\xff garbage { [ <")
        with pytest.raises(fppm.SceneError) as caught:
            fppm.load(path)
        assert str(path) in str(caught.value)


def test_unknown_extension_and_no_emitter(tmp_path):
    (tmp_path / "x.blend").write_text("")
    with pytest.raises(fppm.SceneError, match="x.blend"):
        fppm.load(tmp_path / "x.blend")
    box = SHARED / "gltf" / "Box" / "glTF" / "Box.gltf"
    with pytest.raises(fppm.SceneError, match="emitter"):
        fppm.load(box)


def test_scene_error_is_an_exception_and_panics_are_runtime_errors():
    assert issubclass(fppm.SceneError, Exception)
    assert issubclass(fppm.InternalError, RuntimeError)
    with pytest.raises(fppm.InternalError, match="internal error in fppm .*on purpose"):
        fppm._internal_error_for_tests()
    # The interpreter goes on.
    assert fppm.default_scene(width=8, height=8).width == 8


def test_bad_film_sizes():
    with pytest.raises(ValueError, match=r"width 0 is outside \[1, 16384\]"):
        fppm.default_scene(width=0)
    with pytest.raises(OverflowError):
        fppm.default_scene(height=-1)
    assert REPO.exists()


def test_a_renderer_that_panicked_refuses_every_later_call():
    r = fppm.Renderer(fppm.default_scene(width=8, height=8), photons_per_pass="1k")
    r.iterate()
    with pytest.raises(fppm.InternalError, match="on purpose"):
        r._internal_error_for_tests()
    for call in (r.iterate, r.image, r.stats, r.save_state, lambda: r.passes):
        with pytest.raises(fppm.InternalError, match="cannot be used any more"):
            call()
