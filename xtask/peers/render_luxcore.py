"""Render a LuxCore scene for a wall-clock budget (used by `cargo xtask peers`).

usage: render_luxcore.py SCENE.scn SECONDS OUT.exr THREADS SEED [ENGINE]

SCENE.scn and the render.cfg beside it are what `xtask/src/luxcore.rs` writes (render.cfg holds
the film and the caustic cache's radii, sized to the scene). ENGINE is `path-caustic` (default):
LuxCore's path tracer with its PhotonGI caustic cache, which merges photons at the diffuse
vertices that follow specular ones (caustics seen directly, in a mirror, through water), with a
lookup radius that shrinks by 0.96 every 4 samples per pixel, re-tracing the photons, down to
the floor render.cfg sets; or `bidirvm`, LuxCore's vertex connection and merging (on
box-glass-mirror it read the indirectly lit ceiling 20 % brighter than Mitsuba's `path` and
LuxCore's own path tracer, which agree within 0.1 %: not used for references). Paths end at 64
vertices, with Russian roulette before (BIDIRVM stores light vertices up to its depth, and at
1024 it does not start). Writes the film's linear RGB radiance (LuxCore's `RGB` output) as an
EXR, and prints one JSON line: seconds, passes, engine.
"""
import json
import os
import sys
import time

import pyluxcore

ENGINES = {
    "path-caustic": """
        renderengine.type = "PATHCPU"
        sampler.type = "SOBOL"
        path.pathdepth.total = 64
        path.pathdepth.diffuse = 64
        path.pathdepth.glossy = 64
        path.pathdepth.specular = 64
        path.photongi.sampler.type = "RANDOM"
        path.photongi.photon.maxcount = 1000000
        path.photongi.photon.maxdepth = 64
        path.photongi.caustic.enabled = 1
        path.photongi.caustic.maxsize = 500000
        path.photongi.caustic.updatespp = 4
        path.photongi.caustic.updatespp.radiusreduction = 0.96
    """,
    "bidirvm": """
        renderengine.type = "BIDIRVMCPU"
        path.maxdepth = 64
        light.maxdepth = 64
    """,
}


def main() -> None:
    scene_path, seconds, out, threads, seed = sys.argv[1:6]
    engine = sys.argv[6] if len(sys.argv) > 6 else "path-caustic"
    seconds, threads, seed = float(seconds), int(threads), int(seed)
    start = time.perf_counter()
    # LuxCore's own log handler: a Python callback deadlocks Stop(), which waits for render
    # threads that wait for the interpreter lock to log.
    pyluxcore.Init()
    config = pyluxcore.Properties(os.path.join(os.path.dirname(scene_path), "render.cfg"))
    config.SetFromString(
        ENGINES[engine]
        + f"""
        renderengine.seed = {seed}
        native.threadcount = {threads}
        film.outputs.0.type = "RGB"
        film.outputs.0.filename = "{out}"
        batch.halttime = {max(1, round(seconds))}
        """
    )
    scene = pyluxcore.Scene()
    scene.Parse(pyluxcore.Properties(scene_path))
    session = pyluxcore.RenderSession(pyluxcore.RenderConfig(config, scene))
    session.Start()
    # `batch.halttime` ends the render; the session is stopped only after it says so (a Stop
    # during the engine's start-up does not return).
    while True:
        time.sleep(0.2)
        session.UpdateStats()
        if session.HasDone():
            break
    session.Stop()
    stats = session.GetStats()
    # LuxCore writes the EXR itself (by OpenImageIO): its allocator (TBB's malloc proxy)
    # does not live with another EXR library in the same process.
    session.GetFilm().SaveOutputs()
    print(json.dumps({
        "seconds": time.perf_counter() - start,
        "passes": stats.Get("stats.renderengine.pass").GetInt(),
        "engine": engine,
    }))


if __name__ == "__main__":
    main()
