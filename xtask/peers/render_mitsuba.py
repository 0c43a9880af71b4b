"""Render a Mitsuba 3 scene for a wall-clock budget (used by `cargo xtask peers`).

usage: render_mitsuba.py SCENE.xml INTEGRATOR BUDGET OUT.exr THREADS SEED [VARIANT]

BUDGET is seconds, or spp=N for a fixed number of samples per pixel (for `ptracer`, N times the
pixel count light paths). Renders in chunks of samples with distinct seeds, each chunk sized to
take about a second, and stops before the next chunk would pass the budget (or at N samples); the image is the sample-weighted mean
of the chunks (the same estimator as one render with all the samples). Prints one JSON line:
seconds, samples per pixel, chunks, variant.
"""
import json
import os
import sys
import time

import drjit as dr
import mitsuba as mi
import numpy as np


def main() -> None:
    scene_path, integrator, budget, out, threads, seed = sys.argv[1:7]
    variant = sys.argv[7] if len(sys.argv) > 7 else "llvm_ad_rgb"
    threads, seed = int(threads), int(seed)
    if budget.startswith("spp="):
        seconds, spp_budget = float("inf"), int(budget[4:])
    else:
        seconds, spp_budget = float(budget), None
    start = time.perf_counter()
    mi.set_variant(variant)
    # fppm's glossy coat over a diffuse base, which the exported scenes refer to as `fppmglossy`.
    sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
    import fppm_glossy  # noqa: F401
    dr.set_thread_count(threads)
    scene = mi.load_file(scene_path, integrator=integrator)
    total = None
    spp_done = 0
    chunks = 0
    chunk = 1
    while True:
        t0 = time.perf_counter()
        image = np.array(mi.render(scene, spp=chunk, seed=seed * 1_000_003 + chunks), dtype=np.float64)
        took = time.perf_counter() - t0
        total = image * chunk if total is None else total + image * chunk
        spp_done += chunk
        chunks += 1
        elapsed = time.perf_counter() - start
        rate = chunk / max(took, 1e-6)
        if spp_budget is not None:
            if spp_done >= spp_budget:
                break
            chunk = max(1, min(int(rate), 4096, spp_budget - spp_done))
            continue
        remaining = seconds - elapsed
        if remaining <= 0:
            break
        chunk = max(1, min(int(rate * min(1.0, remaining)), 4096))
        if chunk / rate > remaining * 1.05 + 0.05:
            break
    result = (total / spp_done).astype(np.float32)
    mi.Bitmap(result[:, :, :3]).write(out)
    print(json.dumps({"seconds": time.perf_counter() - start, "spp": spp_done, "chunks": chunks,
                      "variant": variant}))


if __name__ == "__main__":
    main()
