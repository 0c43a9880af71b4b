"""The Python module's overhead (docs/python.md, "Overhead"):

1. time per pass of `Renderer.iterate()` against the `fppm` command's on the built-in default
   scene (512 x 384, the default method and parameters), in paired runs: each pair runs the
   command (`fppm --passes N --json`, per-pass times from its `elapsed_seconds`) and then the
   module for the same passes, alternating which goes first, and compares the median pass of
   each;
2. `Renderer.image()` of a 1920 x 1080 film (median of repeated calls), pooled (the default) and not.

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
# The phases of a pass; the wall-clock time of a pass outside them is the driver's overhead.
PHASES = ("camera", "index", "trace", "gather", "update")
OUTSIDE: dict[str, list[float]] = {"command": [], "module": []}
# Median time in the phases of a pass, per run.
INSIDE: dict[str, list[float]] = {"command": [], "module": []}


def cli_pass_seconds(binary: pathlib.Path, passes: int) -> float:
    """Median wall-clock seconds of the command's passes, from its --json pass lines (the
    median, so that a pass slowed by another process on the machine does not count)."""
    with tempfile.TemporaryDirectory() as out:
        done = subprocess.run(
            [str(binary), "--passes", str(passes), "--json", "--quiet", "-o", f"{out}/x.exr"],
            capture_output=True, text=True, check=True,
        )
    lines = [json.loads(l) for l in done.stdout.splitlines()]
    elapsed = [l["elapsed_seconds"] for l in lines if l.get("event") == "pass"]
    assert len(elapsed) == passes
    phases = [l["timings"] for l in lines if l.get("event") == "pass"]
    walls = [b - a for a, b in zip([0.0, *elapsed], elapsed)]
    OUTSIDE["command"].extend(w - sum(t[k] for k in PHASES) for w, t in zip(walls, phases))
    INSIDE["command"].append(statistics.median(sum(t[k] for k in PHASES) for t in phases))
    return statistics.median(walls)


def python_pass_seconds(scene: fppm.Scene, passes: int) -> float:
    """Median wall-clock seconds of an `iterate()` call, the call's own time included."""
    r = fppm.Renderer(scene)
    times, inside = [], []
    for _ in range(passes):
        start = time.perf_counter()
        stats = r.iterate()
        times.append(time.perf_counter() - start)
        inside.append(sum(stats["timings"][k] for k in PHASES))
        OUTSIDE["module"].append(times[-1] - inside[-1])
    INSIDE["module"].append(statistics.median(inside))
    return statistics.median(times)


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

    phase_ratios = [m / c for m, c in zip(INSIDE["module"], INSIDE["command"])]
    print(f"time in the phases of a pass: median ratio module/command {statistics.median(phase_ratios):.4f}")
    for who, values in OUTSIDE.items():
        print(f"time of a pass outside its phases, {who}: median {statistics.median(values) * 1e3:.2f} ms")

    # The default read-out pools neighbouring pixels (`pool`, docs/integrators.md), whose cost
    # grows with the film; `pool="off"` is the read-out of the pixels' own estimates.
    for pool in ("freq", "off"):
        big = fppm.Renderer(
            fppm.default_scene(width=1920, height=1080), photons_per_pass="100k", pool=pool
        )
        big.iterate(2)
        big.image()  # warm
        times = []
        for _ in range(args.image_calls):
            start = time.perf_counter()
            image = big.image()
            times.append(time.perf_counter() - start)
        assert image.shape == (1080, 1920, 3)
        print(
            f"image() 1920x1080 ({big.method}, pool {pool}): median {statistics.median(times) * 1e3:.1f} ms, "
            f"min {min(times) * 1e3:.1f} ms, max {max(times) * 1e3:.1f} ms over {args.image_calls} calls"
        )


if __name__ == "__main__":
    main()
