"""The Python module's overhead (docs/python.md, "Overhead"):

1. time per pass of `Renderer.iterate()` against the `fppm` command's on the built-in default
   scene (512 x 384, the default method and parameters), in paired runs: each pair runs the
   command (`fppm --passes N --json`, per-pass times from its `elapsed_seconds`) and then the
   module for the same passes, alternating which goes first;
2. `Renderer.image()` of a 1920 x 1080 film (median of repeated calls).

    python crates/python/examples/overhead.py [--pairs 6] [--passes 16] [--fppm target/release/fppm]
"""

import argparse
import json
import pathlib
import statistics
import subprocess
import tempfile
import time

import fppm

REPO = pathlib.Path(__file__).resolve().parents[3]


def cli_pass_seconds(binary: pathlib.Path, passes: int) -> float:
    """Mean wall-clock seconds per pass of the command, from its --json pass lines."""
    with tempfile.TemporaryDirectory() as out:
        done = subprocess.run(
            [str(binary), "--passes", str(passes), "--json", "--quiet", "-o", f"{out}/x.exr"],
            capture_output=True, text=True, check=True,
        )
    lines = [json.loads(l) for l in done.stdout.splitlines()]
    elapsed = [l["elapsed_seconds"] for l in lines if l.get("event") == "pass"]
    assert len(elapsed) == passes
    return elapsed[-1] / passes


def python_pass_seconds(scene: fppm.Scene, passes: int) -> float:
    """Mean wall-clock seconds per `iterate()` call, the call's own time included."""
    r = fppm.Renderer(scene)
    start = time.perf_counter()
    for _ in range(passes):
        r.iterate()
    return (time.perf_counter() - start) / passes


def main() -> None:
    p = argparse.ArgumentParser()
    p.add_argument("--pairs", type=int, default=6)
    p.add_argument("--passes", type=int, default=16)
    p.add_argument("--fppm", type=pathlib.Path, default=REPO / "target" / "release" / "fppm")
    p.add_argument("--image-calls", type=int, default=30)
    args = p.parse_args()

    scene = fppm.default_scene()
    ratios = []
    for pair in range(args.pairs):
        if pair % 2 == 0:
            cli = cli_pass_seconds(args.fppm, args.passes)
            py = python_pass_seconds(scene, args.passes)
        else:
            py = python_pass_seconds(scene, args.passes)
            cli = cli_pass_seconds(args.fppm, args.passes)
        ratios.append(py / cli)
        print(f"pair {pair + 1}: command {cli * 1e3:.1f} ms/pass, module {py * 1e3:.1f} ms/pass, ratio {py / cli:.4f}")
    print(
        f"iterate(): median ratio module/command {statistics.median(ratios):.4f} "
        f"(min {min(ratios):.4f}, max {max(ratios):.4f}) over {args.pairs} pairs of {args.passes} passes"
    )

    big = fppm.Renderer(fppm.default_scene(width=1920, height=1080), photons_per_pass="100k")
    big.iterate(2)
    big.image()  # warm
    times = []
    for _ in range(args.image_calls):
        start = time.perf_counter()
        image = big.image()
        times.append(time.perf_counter() - start)
    assert image.shape == (1080, 1920, 3)
    print(
        f"image() 1920x1080 ({big.method}): median {statistics.median(times) * 1e3:.1f} ms, "
        f"min {min(times) * 1e3:.1f} ms, max {max(times) * 1e3:.1f} ms over {args.image_calls} calls"
    )


if __name__ == "__main__":
    main()
