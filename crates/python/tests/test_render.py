"""Rendering: parameters, bit-identity with the command, AOVs, statistics, resume, threads."""

import _thread
import threading
import time

import numpy as np
import pytest

import fppm
from conftest import SCENES, SHARED, run_cli

SMALL = dict(width=64, height=48)
CORNELL = SHARED / "cornell_box" / "CornellBox-Original.obj"


@pytest.fixture(scope="module")
def scene():
    return fppm.default_scene(**SMALL)


# --- parameters ------------------------------------------------------------------------------


def test_every_parameter_by_name_with_its_default(scene):
    params = fppm.parameters()
    assert "seed" in params and "photons_per_pass" in params and "method" in params
    for name, entry in params.items():
        value = entry["default"]
        if entry["switch"]:
            value = value == "on"
        r = fppm.Renderer(scene, **{name: value})
        # An automatic photon count is settled for the film when the renderer is built, and the
        # renderer reports the number it uses (100k on this small film).
        expected = "100000" if name == "photons_per_pass" else entry["default"]
        assert r.params()[name] == expected, name


def test_parameters_reach_the_renderer(scene):
    r = fppm.Renderer(
        scene, "sppm", photons_per_pass="20k", alpha=0.5, seed=7, light_tracing=False
    )
    p = r.params()
    assert (p["method"], p["photons_per_pass"], p["alpha"], p["seed"]) == ("sppm", "20000", "0.5", "7")
    assert p["light_tracing"] == "off"
    assert r.method == "sppm"
    stats = r.iterate()
    assert stats["photons_traced"] == 20000


def test_method_defaults_to_the_scenes_then_freq_sppm(scene):
    assert fppm.Renderer(scene).method == "freq-sppm"


@pytest.mark.parametrize(
    "kwargs, message",
    [
        (dict(alpha=1.5), r"^alpha 1.5 is outside \(0, 1\]$"),
        (dict(colour="red"), r"^colour is not a render parameter$"),
        (dict(method="mlt"), r"^method mlt is not one of "),
        (dict(photons_per_pass=0), r"^photons_per_pass 0 must be positive$"),
        (dict(photons_per_pass="lots"), r"^photons_per_pass lots is not a whole number"),
        (dict(seed=None), r"^seed None is not a value"),
    ],
)
def test_bad_parameters_raise_value_error_with_the_commands_message(scene, kwargs, message):
    with pytest.raises(ValueError, match=message):
        fppm.Renderer(scene, **kwargs)


def test_the_same_messages_as_the_command(scene):
    done = run_cli_fail("--alpha", "1.5", "--passes", "1")
    with pytest.raises(ValueError) as caught:
        fppm.Renderer(scene, alpha=1.5)
    assert done.replace("--alpha", "alpha") == str(caught.value)


def run_cli_fail(*args):
    import subprocess

    from conftest import REPO, fppm_bin

    done = subprocess.run([str(fppm_bin()), *args], capture_output=True, text=True, cwd=REPO)
    assert done.returncode == 2
    return done.stderr.strip().removeprefix("fppm: ")


def test_nan_and_infinity_raise_value_error_for_every_number(scene):
    numbers = [
        name
        for name, entry in fppm.parameters().items()
        if not entry["switch"] and not entry["choices"] and name != "method"
    ]
    assert "alpha" in numbers and "seed" in numbers
    for name in numbers:
        # connect_below's range is [0, inf]: infinity is one of its values.
        infinite = (-float("inf"),) if name == "connect_below" else (float("inf"), -float("inf"))
        for bad in (float("nan"), *infinite):
            with pytest.raises(ValueError, match=f"^{name} "):
                fppm.Renderer(scene, **{name: bad})


def test_wrong_types_raise_type_error(scene):
    with pytest.raises(TypeError, match="alpha must be a str, int, float or bool"):
        fppm.Renderer(scene, alpha=[0.5])


def test_threads_and_memory_limits(scene):
    with pytest.raises(ValueError, match=r"threads 0 is outside \[1, 4096\]"):
        fppm.Renderer(scene, threads=0)
    with pytest.raises(ValueError, match="the render needs about"):
        fppm.Renderer(scene, max_memory=1024)
    with pytest.raises(ValueError, match="max_memory"):
        fppm.Renderer(scene, max_memory=-3)
    # Too many photons for this machine: refused before anything is allocated.
    with pytest.raises(ValueError, match="the render needs about"):
        fppm.Renderer(scene, photons_per_pass="4G")
    fppm.Renderer(scene, max_memory="none")


def test_render_needs_a_budget(scene):
    r = fppm.Renderer(scene, photons_per_pass="10k")
    with pytest.raises(ValueError, match="a time .* or a number of passes"):
        r.render()
    with pytest.raises(ValueError, match="time -1 is not a duration"):
        r.render(time=-1.0)
    with pytest.raises(ValueError, match="time NaN is not a duration"):
        r.render(time=float("nan"))


# --- bit-identity with the command -----------------------------------------------------------


@pytest.mark.parametrize(
    "source, method, extra",
    [
        (None, "freq-sppm", {}),
        (None, "sppm", {"alpha": 0.6}),
        (None, "appm", {}),
        (CORNELL, "freq", {"light_tracing": False}),
        (CORNELL, "path", {"spp": 2}),
        (SCENES / "glass-caustic.toml", "light", {}),
    ],
    ids=lambda v: getattr(v, "name", str(v)),
)
def test_images_are_the_commands_bit_for_bit(tmp_path, source, method, extra):
    passes, seed = 3, 11
    # `fppm` alone renders the built-in default scene.
    args = ["render", str(source)] if source else []
    args += ["--width", "48", "--height", "40", "--passes", str(passes), "--seed", str(seed)]
    args += ["--method", method, "--photons-per-pass", "15k", "--quiet", "-o", str(tmp_path / "cli.exr")]
    for name, value in extra.items():
        entry = fppm.parameters()[name]
        if entry["switch"]:
            flag = next(f for f in [name.replace("_", "-"), "no-" + name.replace("_", "-")])
            args.append("--no-" + name.replace("_", "-") if not value else "--" + flag)
        else:
            args += ["--" + name.replace("_", "-"), str(value)]
    run_cli(*args)
    expected = fppm.read_exr(tmp_path / "cli.exr")

    scene = fppm.load(source, width=48, height=40) if source else fppm.default_scene(width=48, height=40)
    r = fppm.Renderer(scene, method, seed=seed, photons_per_pass="15k", **extra)
    r.iterate(passes)
    image = r.image()
    assert image.dtype == np.float32 and image.shape == (40, 48, 3)
    assert image.mean() > 0
    assert np.array_equal(image, expected), f"max difference {np.abs(image - expected).max()}"
    # And through the module's own writer.
    r.write_exr(tmp_path / "py.exr")
    assert np.array_equal(fppm.read_exr(tmp_path / "py.exr"), expected)


def test_thread_count_does_not_change_the_image(scene):
    images = []
    for threads in (1, 2):
        r = fppm.Renderer(scene, seed=2, photons_per_pass="10k", threads=threads)
        r.iterate(2)
        images.append(r.image())
    assert np.array_equal(*images)


# --- AOVs, statistics ------------------------------------------------------------------------


def test_every_aov_of_a_frequency_method(scene, tmp_path):
    r = fppm.Renderer(scene, "freq-sppm", photons_per_pass="10k")
    r.iterate(2)
    assert fppm.AOVS == ["radius", "count", "freq.radius", "freq.held", "pool.width", "albedo", "normal", "depth"]
    for name in fppm.AOVS:
        a = r.aov(name)
        assert a.dtype == np.float32
        assert a.shape == ((48, 64, 3) if name in ("albedo", "normal") else (48, 64)), name
        assert np.isfinite(a).all(), name
    assert r.aov("radius").max() > 0
    assert 0 <= r.aov("freq.held").min() <= r.aov("freq.held").max() <= 1
    r.write_exr(tmp_path / "aovs.exr", aovs=["albedo", "freq.held"])
    assert np.array_equal(fppm.read_exr(tmp_path / "aovs.exr"), r.image())


def test_aovs_an_integrator_lacks(scene):
    r = fppm.Renderer(scene, "path")
    r.iterate()
    assert r.aov("depth").shape == (48, 64)
    with pytest.raises(ValueError, match="the path integrator has no radius output"):
        r.aov("radius")
    with pytest.raises(ValueError, match="the sppm integrator has no freq.radius output"):
        fppm.Renderer(scene, "sppm", photons_per_pass="5k").aov("freq.radius")
    with pytest.raises(ValueError, match='"colour" is not an aov'):
        r.aov("colour")


def test_stats(scene):
    r = fppm.Renderer(scene, "freq-sppm", photons_per_pass="10k")
    s = r.stats()
    assert s["passes"] == 0 and s["last_pass"] is None
    r.iterate(3)
    s = r.stats()
    assert s["passes"] == 3 == r.passes
    assert s["photons_emitted"] == 30000 == r.photons_emitted
    assert s["method"] == "freq-sppm"
    assert s["seconds"] > 0 and s["non_finite"] == 0
    last = s["last_pass"]
    assert last["pass"] == 2 and last["photons_traced"] == 10000
    assert 0 <= last["frequency_held"] <= 1
    assert set(last["timings"]) >= {"camera", "trace", "gather", "update", "total"}
    assert s["memory"]["total"] > 0
    assert r.resolution == (64, 48)


# --- resume ----------------------------------------------------------------------------------


@pytest.mark.parametrize("method", ["freq-sppm", "ppm", "appm", "path"])
def test_restore_gives_the_uninterrupted_image(scene, method):
    whole = fppm.Renderer(scene, method, seed=4, photons_per_pass="10k")
    whole.iterate(4)
    first = fppm.Renderer(scene, method, seed=4, photons_per_pass="10k")
    first.iterate(2)
    data = first.save_state()
    assert isinstance(data, bytes)
    del first
    resumed = fppm.Renderer.restore(scene, data)
    assert resumed.passes == 2 and resumed.method == method
    resumed.iterate(2)
    assert np.array_equal(resumed.image(), whole.image())


def test_restore_a_checkpoint_of_the_command(tmp_path):
    common = ["--width", "48", "--height", "40", "--seed", "9", "--photons-per-pass", "10k", "--quiet"]
    run_cli("render", str(CORNELL), "--passes", "2", "--checkpoint", str(tmp_path / "s.fppm"),
            "-o", str(tmp_path / "half.exr"), *common)
    run_cli("render", str(CORNELL), "--passes", "4", "-o", str(tmp_path / "whole.exr"), *common)
    scene = fppm.load(CORNELL, width=48, height=40)
    r = fppm.Renderer.restore(scene, (tmp_path / "s.fppm").read_bytes())
    r.iterate(2)
    assert np.array_equal(r.image(), fppm.read_exr(tmp_path / "whole.exr"))


def test_restore_refuses_bad_bytes_and_other_scenes(scene):
    with pytest.raises(ValueError, match="^checkpoint: "):
        fppm.Renderer.restore(scene, b"not a checkpoint")
    r = fppm.Renderer(scene, photons_per_pass="5k")
    r.iterate()
    data = bytearray(r.save_state())
    with pytest.raises(ValueError, match="^checkpoint: "):
        fppm.Renderer.restore(fppm.default_scene(width=32, height=24), bytes(data))
    data[len(data) // 2] ^= 0xFF
    with pytest.raises(ValueError, match="^checkpoint: "):
        fppm.Renderer.restore(scene, bytes(data))


# --- the GIL, Ctrl-C, threads ----------------------------------------------------------------


def test_render_releases_the_gil():
    scene = fppm.default_scene(width=128, height=96)
    r = fppm.Renderer(scene, photons_per_pass="50k")
    counts = []
    stop = threading.Event()

    def count():
        n = 0
        while not stop.is_set():
            n += 1
            if n % 1000 == 0:
                counts.append((time.monotonic(), n))

    thread = threading.Thread(target=count)
    thread.start()
    start = time.monotonic()
    stats = r.render(time=1.0)
    end = time.monotonic()
    stop.set()
    thread.join()
    assert stats["passes"] >= 1
    assert end - start >= 1.0
    during = [n for t, n in counts if start + 0.1 <= t <= end]
    # The counter went on through the render: many samples spread over the second.
    assert len(during) >= 20, f"only {len(during)} samples during the render"
    assert during[-1] - during[0] >= 20_000


def test_ctrl_c_stops_after_the_current_pass():
    scene = fppm.default_scene(width=96, height=72)
    r = fppm.Renderer(scene, photons_per_pass="20k")
    timer = threading.Timer(0.5, _thread.interrupt_main)
    timer.start()
    start = time.monotonic()
    with pytest.raises(KeyboardInterrupt):
        r.render(time=60.0)
    assert time.monotonic() - start < 10
    passes = r.passes
    assert passes >= 1
    r.iterate()
    assert r.passes == passes + 1
    assert r.image().mean() > 0


def test_image_from_another_thread_during_a_render(scene):
    r = fppm.Renderer(scene, photons_per_pass="10k")
    r.iterate()
    images = []
    thread = threading.Thread(target=lambda: images.extend(r.image() for _ in range(5)))
    thread.start()
    r.render(passes=10)
    thread.join()
    assert len(images) == 5 and all(i.shape == (48, 64, 3) for i in images)
    assert r.passes == 11
