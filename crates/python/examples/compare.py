"""Compare sppm and freq-sppm at equal time: relMSE against render time, plotted.

    python crates/python/examples/compare.py                      # the built-in default scene
    python crates/python/examples/compare.py scenes/glass-caustic.toml --time 60

Each method renders for --time seconds; after every pass whose time passes the next of a
log-spaced set of checkpoints, its image is compared with a reference (relMSE, as `fppm diff`
computes it). The reference is a long render (--reference-time seconds) of --reference-method
with another seed, so that neither curve is measured against its own noise; it is written to
--reference (an EXR) and read from there next time. Both methods converge to the same image, so
the reference's method does not favour either at the times compared here as long as the
reference is much longer than --time. Needs matplotlib (`pip install matplotlib`).
"""

import argparse
import math
import pathlib
import time

import matplotlib

matplotlib.use("Agg")  # a file, no window
import matplotlib.pyplot as plt  # noqa: E402
import matplotlib.ticker  # noqa: E402

import fppm  # noqa: E402


def arguments() -> argparse.Namespace:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("scene", nargs="?", help="scene file (default: the built-in default scene)")
    p.add_argument("--width", type=int, default=256, help="film width (default 256)")
    p.add_argument("--height", type=int, help="film height (default: the scene's aspect ratio)")
    p.add_argument("--time", type=float, default=20.0, help="seconds per method (default 20)")
    p.add_argument("--reference-time", type=float, default=120.0, help="seconds of the reference (default 120)")
    p.add_argument("--reference-method", default="sppm", help="method of the reference (default sppm)")
    p.add_argument("--reference", type=pathlib.Path, default=pathlib.Path("compare-reference.exr"))
    p.add_argument("--methods", nargs="+", default=["sppm", "freq-sppm"])
    p.add_argument("--photons-per-pass", default="100k")
    p.add_argument("-o", "--output", type=pathlib.Path, default=pathlib.Path("compare.png"))
    return p.parse_args()


def load(args: argparse.Namespace) -> fppm.Scene:
    if args.scene:
        return fppm.load(args.scene, width=args.width, height=args.height)
    return fppm.default_scene(width=args.width, height=args.height)


def reference(scene: fppm.Scene, args: argparse.Namespace):
    if args.reference.exists():
        image = fppm.read_exr(args.reference)
        if image.shape == (scene.height, scene.width, 3):
            print(f"reference: {args.reference} (delete it to render a new one)")
            return image
    print(f"reference: {args.reference_method}, {args.reference_time:.0f} s ...", flush=True)
    r = fppm.Renderer(scene, args.reference_method, seed=1_000_003, photons_per_pass=args.photons_per_pass)
    r.render(time=args.reference_time)
    r.write_exr(args.reference)
    return r.image()


def curve(scene: fppm.Scene, method: str, ref, args: argparse.Namespace):
    """(seconds, relMSE) after the passes that cross log-spaced checkpoints."""
    r = fppm.Renderer(scene, method, seed=1, photons_per_pass=args.photons_per_pass)
    checkpoints = [args.time * 2.0 ** (-k / 2) for k in range(16, -1, -1)]
    points = []
    while r.stats()["seconds"] < args.time:
        r.iterate()
        seconds = r.stats()["seconds"]  # time in passes only, not in the comparisons
        if checkpoints and seconds >= checkpoints[0]:
            while checkpoints and seconds >= checkpoints[0]:
                checkpoints.pop(0)
            points.append((seconds, fppm.diff(r.image(), ref)["rel_mse"]))
    print(f"{method:>10}: {r.passes} passes in {r.stats()['seconds']:.1f} s, relMSE {points[-1][1]:.4g}")
    return points


def main() -> None:
    args = arguments()
    scene = load(args)
    ref = reference(scene, args)
    started = time.monotonic()
    curves = {method: curve(scene, method, ref, args) for method in args.methods}
    fig, ax = plt.subplots(figsize=(6, 4.5))
    for method, points in curves.items():
        ax.loglog([t for t, _ in points], [e for _, e in points], marker="o", label=method)
    ax.set_xlabel("render time (s)")
    ax.set_ylabel("relMSE against the reference")
    name = pathlib.Path(args.scene).name if args.scene else "built-in default scene"
    ax.set_title(f"{name}, {scene.width}x{scene.height}, {args.photons_per_pass} photons/pass")
    ax.xaxis.set_minor_formatter(matplotlib.ticker.NullFormatter())
    ax.grid(True, which="both", alpha=0.3)
    ax.legend()
    fig.tight_layout()
    fig.savefig(args.output, dpi=120)
    final = {m: p[-1][1] for m, p in curves.items() if p}
    if len(final) == 2 and all(v > 0 and math.isfinite(v) for v in final.values()):
        (a, ea), (b, eb) = final.items()
        print(f"at {args.time:.0f} s: {b} / {a} relMSE = {eb / ea:.3f}")
    print(f"wrote {args.output} ({time.monotonic() - started:.0f} s)")


if __name__ == "__main__":
    main()
