"""fppm: frequency-guided progressive photon mapping (type stubs of the compiled module).

Load a scene with `load` (TOML, OBJ, glTF, Mitsuba 3 XML, pbrt-v4), `load_string` or
`default_scene`; render it with `Renderer`; read images as NumPy arrays; write, read and
compare EXR files. The render parameters are those of the `fppm` command and of a scene's
`[render]` table, by name (`parameters()`).
"""

import os
from typing import Any, Literal, Mapping, Sequence, TypedDict, final

import numpy as np
import numpy.typing as npt

__all__ = [
    "SceneError",
    "InternalError",
    "__version__",
    "AOVS",
    "Scene",
    "Renderer",
    "load",
    "load_string",
    "default_scene",
    "parameters",
    "write_exr",
    "read_exr",
    "diff",
    "_internal_error_for_tests",
]

__version__: str

AOVS: list[str]
"""Every AOV name: radius, count, freq.radius, freq.held, pool.width, albedo, normal, depth."""

StrPath = str | os.PathLike[str]
ParamValue = str | int | float | bool
Method = Literal["freq-sppm", "sppm", "freq", "ppm", "appm", "path", "light", "vcm", "bdpt"]
Format = Literal["toml", "obj", "gltf", "xml", "pbrt"]

class SceneError(Exception):
    """A scene that cannot be loaded or built: malformed or out-of-range content, an
    unsupported format, no emitter. A file that cannot be read raises OSError instead."""

class InternalError(RuntimeError):
    """A bug inside fppm (a Rust panic), caught before it reached Python."""

class Timings(TypedDict):
    camera: float
    index: float
    trace: float
    gather: float
    update: float
    frequency: float
    total: float

# One pass, as `fppm render --json` reports it ("pass" is a keyword, hence this form).
PassStats = TypedDict(
    "PassStats",
    {
        "pass": int,
        "camera_paths": int,
        "photons_traced": int,
        "frequency_photons": int,
        "photons_deposited": int,
        "hitpoints_hit": int,
        "hitpoints_valid": int,
        "mean_radius": float | None,
        "min_radius": float | None,
        "max_radius": float | None,
        "frequency_held": float | None,
        "photons_stored": int,
        "light_connections": int,
        "non_finite": int,
        "timings": Timings,
    },
)

class Stats(TypedDict):
    passes: int
    photons_emitted: int
    seconds: float
    non_finite: int
    method: str
    memory: dict[str, int] | None
    last_pass: PassStats | None

class Metrics(TypedDict):
    rmse: float
    rel_mse: float
    mean_ratio: float
    width: int
    height: int

class ParameterInfo(TypedDict):
    help: str
    default: str
    choices: list[str]
    switch: bool

@final
class Scene:
    """A loaded scene, ready to render; immutable, shareable between renderers."""

    @property
    def source(self) -> str:
        """The scene file (or the name a scene given as text was loaded under)."""
    @property
    def width(self) -> int:
        """Film width in pixels."""
    @property
    def height(self) -> int:
        """Film height in pixels."""
    @property
    def passes(self) -> int | None:
        """The passes the scene's `[render]` table asks for, if it does."""
    @property
    def render_defaults(self) -> dict[str, str]:
        """The scene's `[render]` table: render parameters by name, as text."""
    def info(self) -> dict[str, Any]:
        """What `fppm info` prints, as a dict (counts, emitters, materials, camera, film,
        bounds, warnings, textures)."""
    def __str__(self) -> str:
        """What `fppm info` prints, as text."""

def load(
    path: StrPath,
    *,
    env: StrPath | None = None,
    width: int | None = None,
    height: int | None = None,
) -> Scene:
    """Loads a scene file (.toml, .obj, .gltf, .glb, .xml, .pbrt) as `fppm render` does.

    `env` lights it with an environment map (`--env`); `width`/`height` set the film
    (`--width`/`--height`; one alone keeps the aspect ratio).

    Raises FileNotFoundError/OSError (a file cannot be read), SceneError (bad content),
    ValueError (film size outside [1, 16384]).
    """

def load_string(
    text: str,
    format: Format = "toml",
    *,
    files: Mapping[StrPath, str | bytes] | None = None,
    base_dir: StrPath | None = None,
    name: str | None = None,
    env: StrPath | None = None,
    width: int | None = None,
    height: int | None = None,
) -> Scene:
    """Loads a scene held in a string, as if read from `base_dir/name`; `files` serves the
    files it refers to (others are read from disk)."""

def default_scene(*, width: int | None = None, height: int | None = None) -> Scene:
    """The `fppm` command's built-in default scene (a caustic in a mirror half-cylinder)."""

def parameters() -> dict[str, ParameterInfo]:
    """Every render parameter by name: help, default, choices, whether it is a switch."""

@final
class Renderer:
    """A progressive render: `iterate`/`render` passes, read `image`/`aov` at any time.

    `method` defaults to the scene's `[render]` method, else freq-sppm. `**params` are the
    render parameters by name (`parameters()`), over the scene's `[render]` table. The same
    scene, parameters and seed give the `fppm` command's image bit for bit.

    Raises ValueError (unknown name, value out of range, NaN, too large for `max_memory`) with
    the command's one-line message, TypeError (a value not str/int/float/bool).
    """

    def __new__(
        cls,
        scene: Scene,
        method: Method | str | None = None,
        *,
        threads: int | None = None,
        max_memory: int | Literal["none"] | None = None,
        **params: ParamValue,
    ) -> Renderer: ...
    @staticmethod
    def restore(scene: Scene, data: bytes, *, threads: int | None = None) -> Renderer:
        """A renderer from `save_state()` bytes or an `fppm render --checkpoint` file's bytes;
        its next passes are those of the saved renderer, bit for bit. ValueError if the bytes
        are not a checkpoint or were made for another scene."""
    def iterate(self, passes: int = 1) -> PassStats | None:
        """Runs `passes` passes without the GIL; returns the last pass's statistics.
        KeyboardInterrupt on Ctrl-C, after the current pass."""
    def render(self, time: float | None = None, passes: int | None = None) -> Stats:
        """Runs passes until `time` seconds or `passes` more passes, whichever first, without
        the GIL. KeyboardInterrupt on Ctrl-C, after the current pass (the passes are kept)."""
    def image(self) -> npt.NDArray[np.float32]:
        """The current image: float32, height × width × 3, linear RGB."""
    def aov(self, name: str) -> npt.NDArray[np.float32]:
        """An auxiliary image (`AOVS`): height × width, or height × width × 3 for albedo and
        normal. ValueError for a name this integrator lacks."""
    def stats(self) -> Stats:
        """passes, photons_emitted, seconds, non_finite, method, memory, last_pass."""
    def save_state(self) -> bytes:
        """The exact state, in the format of `fppm render --checkpoint`."""
    def params(self) -> dict[str, str]:
        """Every render parameter of this render by name, as text."""
    def write_exr(self, path: StrPath, aovs: Sequence[str] = ...) -> None:
        """Writes the image as `fppm render -o` does (AOV channels, parameters as metadata)."""
    def _internal_error_for_tests(self) -> None: ...
    @property
    def passes(self) -> int: ...
    @property
    def photons_emitted(self) -> int: ...
    @property
    def method(self) -> str: ...
    @property
    def scene(self) -> Scene: ...
    @property
    def resolution(self) -> tuple[int, int]:
        """(width, height) in pixels."""

def write_exr(
    path: StrPath,
    image: npt.ArrayLike,
    aovs: Mapping[str, npt.ArrayLike] | None = None,
    metadata: Mapping[str, object] | None = None,
) -> None:
    """Writes linear RGB (height × width × 3) as a float32 EXR, with AOVs by name and
    `fppm.KEY` text metadata. OSError if it cannot be written."""

def read_exr(path: StrPath) -> npt.NDArray[np.float32]:
    """The R, G, B channels of an EXR: float32, height × width × 3."""

def diff(a: npt.ArrayLike | StrPath, b: npt.ArrayLike | StrPath) -> Metrics:
    """`fppm diff a b --json`: rmse, rel_mse, mean_ratio of `a` against the reference `b`."""

def _internal_error_for_tests() -> None: ...
