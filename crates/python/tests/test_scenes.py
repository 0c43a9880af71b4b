"""Loading every format the command opens, and the scene's report."""

import pytest

import fppm
from conftest import SCENES, SHARED, run_cli

FILES = [
    *(sorted(SCENES.glob("*.toml")) + sorted((SCENES / "peers").glob("*.toml"))),
    SHARED / "cornell_box" / "CornellBox-Original.obj",
    SHARED / "gltf" / "EmissiveStrengthTest" / "glTF" / "EmissiveStrengthTest.gltf",
    SHARED / "gltf" / "EmissiveStrengthTest" / "glTF-Binary" / "EmissiveStrengthTest.glb",
    SHARED / "mitsuba3" / "scenes" / "cbox" / "cbox.xml",
    SHARED / "pbrt-v4" / "veach-mis" / "veach-mis.pbrt",
]


def test_every_format_is_in_the_list():
    assert {p.suffix for p in FILES} == {".toml", ".obj", ".gltf", ".glb", ".xml", ".pbrt"}
    assert len([p for p in FILES if p.suffix == ".toml"]) >= 2


@pytest.mark.parametrize("path", FILES, ids=lambda p: p.name)
def test_loads_and_reports_as_fppm_info(path):
    assert path.exists(), f"{path} is missing (../shared beside the checkout?)"
    scene = fppm.load(path)
    info = scene.info()
    assert info["emitters"] >= 1
    assert info["triangles"] + info["spheres"] + info["cylinders"] > 0
    assert info["film"] == [scene.width, scene.height]
    assert scene.source == str(path)
    # str(scene) is what `fppm info` prints, line for line.
    assert str(scene) == run_cli("info", str(path)).stdout


def test_load_accepts_str_and_pathlib_and_film_and_env():
    path = SHARED / "cornell_box" / "CornellBox-Original.obj"
    assert fppm.load(str(path)).width == fppm.load(path).width
    scene = fppm.load(path, width=64)
    assert (scene.width, scene.height) == (64, 64)
    scene = fppm.load(path, width=40, height=30)
    assert (scene.width, scene.height) == (40, 30)
    museum = SHARED / "mitsuba3" / "common" / "textures" / "museum.exr"
    lit = fppm.load(SCENES / "glass-caustic.toml", env=museum)
    assert lit.info()["environment"] is not None


def test_default_scene_is_the_commands():
    scene = fppm.default_scene()
    assert (scene.width, scene.height) == (512, 384)
    assert str(scene) == run_cli("info").stdout


def test_load_string_toml_and_obj_with_files():
    text = (SCENES / "glass-caustic.toml").read_text()
    scene = fppm.load_string(text, base_dir=SCENES)
    assert scene.info()["triangles"] == fppm.load(SCENES / "glass-caustic.toml").info()["triangles"]
    # An OBJ held in memory with its MTL given as a file, and a TOML scene that refers to it.
    obj_dir = SHARED / "cornell_box"
    obj = (obj_dir / "CornellBox-Original.obj").read_text()
    mtl = (obj_dir / "CornellBox-Original.mtl").read_bytes()
    scene = fppm.load_string(obj, "obj", files={"CornellBox-Original.mtl": mtl}, base_dir="/nowhere")
    assert scene.info()["emitters"] == fppm.load(obj_dir / "CornellBox-Original.obj").info()["emitters"]
    toml = 'format = 1\n[[shapes]]\ntype = "mesh"\nfile = "box.obj"\n'
    scene = fppm.load_string(
        toml, files={"box.obj": obj, "CornellBox-Original.mtl": mtl}, base_dir="/mem", name="s.toml"
    )
    assert scene.source == "/mem/s.toml"
    assert scene.info()["emitters"] >= 1


def test_load_string_unknown_format():
    with pytest.raises(ValueError, match="is not one of toml, obj, gltf, xml, pbrt"):
        fppm.load_string("", "blend")


def test_render_defaults_of_a_scene():
    scene = fppm.load(SCENES / "bunny-box.toml")
    assert isinstance(scene.render_defaults, dict)
    assert scene.passes is None or scene.passes >= 1

