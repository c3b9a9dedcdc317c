"""Type stubs of blutrace (the classes and functions of its Rust extension module)."""

from os import PathLike
from typing import Any, Callable, Dict, List, Mapping, Optional, Sequence, Tuple, Union

import numpy as np
import numpy.typing as npt

from . import scenes as scenes

__version__: str

_Path = Union[str, "PathLike[str]"]
_Count = Union[int, float]
_TraceProgress = Union[bool, None, Callable[[int, int], Any]]
_SearchProgress = Union[bool, None, Callable[[Dict[str, Any]], Any]]

class BlutraceError(Exception):
    """Base class of blutrace's errors (a run or a write that failed, an internal error)."""

class SceneError(BlutraceError):
    """A scene file, or a file it names, is wrong: the message names the file and field."""

class Scene:
    """A validated, traceable scene: a value (``copy()`` gives an independent one)."""

    @staticmethod
    def load(path: _Path) -> Scene:
        """Load and validate a scene file, or ``scene.toml`` in a folder."""
    @staticmethod
    def from_toml(text: str, path: _Path) -> Scene:
        """A scene from the text of a scene file; geometry relative to ``path``'s folder."""
    def to_toml(self) -> str:
        """The scene file as TOML text (with any ``set`` applied)."""
    @property
    def name(self) -> str: ...
    @property
    def path(self) -> str: ...
    @property
    def warnings(self) -> List[str]: ...
    @property
    def default_photons(self) -> int: ...
    @property
    def default_seed(self) -> int: ...
    @property
    def content_hash(self) -> str: ...
    @property
    def source(self) -> Dict[str, Any]:
        """The scene file as a dict (with any ``set`` applied)."""
    def get(self, key: str) -> Any:
        """The value at a key path such as ``sources.0.center.2``; with ``*``, the value every
        element holds, or the list of their values when they differ."""
    def set(self, key: str, value: Any) -> None:
        """Set the value at a key path (numpy arrays and scalars too); the scene is loaded
        again (``SceneError`` if bad)."""
    def copy(self) -> Scene:
        """An independent copy."""
    def __copy__(self) -> Scene: ...
    def __deepcopy__(self, memo: Any) -> Scene: ...
    def check(self) -> Dict[str, Any]:
        """What ``blutrace check --json`` prints."""
    def trace(
        self,
        photons: Optional[_Count] = None,
        seed: Optional[int] = None,
        threads: Optional[int] = None,
        estimator: str = "analog",
        target_error: Optional[float] = None,
        target_metric: str = "mean",
        max_time: Optional[float] = None,
        progress: _TraceProgress = None,
        shard: Optional[Tuple[int, int]] = None,
        backend: str = "auto",
        luminance_estimator: str = "meter",
    ) -> Run:
        """Trace the scene (the GIL is released; Ctrl-C raises KeyboardInterrupt)."""
    def optimize(
        self,
        method: Optional[str] = None,
        vary: Optional[Mapping[str, Tuple[float, float]]] = None,
        *,
        objective: str = ...,
        grid_points: int = ...,
        photons: _Count = ...,
        seed: int = ...,
        max_iter: int = ...,
        target_cv: Optional[float] = ...,
        degree: Optional[int] = ...,
        min_density: float = ...,
        max_density: Optional[float] = ...,
        tag: Optional[str] = ...,
        initial_step: float = ...,
        simplex_tol: float = ...,
        alpha: float = ...,
        smoothing: float = ...,
        dims: int = ...,
        cells: Optional[Tuple[int, int]] = ...,
        strips: Optional[int] = ...,
        edge_margin_mm: float = ...,
        verify_photons: _Count = ...,
        verify_seed: Optional[int] = ...,
        threads: Optional[int] = ...,
        estimator: str = ...,
        backend: str = ...,
        export_placement: Optional[str] = ...,
        progress: _SearchProgress = ...,
    ) -> Optimization:
        """Optimize the dot density, or with ``vary`` the numbers its key paths name; Ctrl-C
        returns the designs traced so far (``interrupted`` True)."""
    def characterise(
        self,
        tag: str,
        photons: Optional[_Count] = None,
        aoi: Optional[Sequence[float]] = None,
        rotations: Optional[Sequence[float]] = None,
        radial_step: float = 2.0,
        azimuth_step: float = 10.0,
        u_axis: Optional[Tuple[float, float, float]] = None,
        seed: Optional[int] = None,
        progress: _TraceProgress = None,
    ) -> Characterisation:
        """The part at ``tag`` as an IS BSDF table, as ``blutrace bsdf`` makes it."""

class Run:
    """A finished trace, the merge of shard runs, or a run read from an output folder."""

    @property
    def flux(self) -> npt.NDArray[np.float64]:
        """Irradiance (W/mm^2 per bin), shape (ny, nx), row iy along v from the origin."""
    @property
    def flux_stderr(self) -> npt.NDArray[np.float64]: ...
    @property
    def hits(self) -> npt.NDArray[np.uint64]: ...
    @property
    def angular(self) -> npt.NDArray[np.float64]:
        """Radiant intensity (W/sr per bin), shape (n_theta, n_phi)."""
    @property
    def angular_stderr(self) -> npt.NDArray[np.float64]: ...
    @property
    def angular_hits(self) -> npt.NDArray[np.uint64]: ...
    @property
    def x_mm(self) -> npt.NDArray[np.float64]:
        """Centres of the flux map's columns (mm along u from the detector's origin)."""
    @property
    def y_mm(self) -> npt.NDArray[np.float64]:
        """Centres of the flux map's rows (mm along v from the detector's origin)."""
    @property
    def theta_deg(self) -> npt.NDArray[np.float64]:
        """Centres of the angular maps' rows (degrees from the normal)."""
    @property
    def phi_deg(self) -> npt.NDArray[np.float64]:
        """Centres of the angular maps' columns (degrees from u towards v)."""
    @property
    def luminance(self) -> Optional[npt.NDArray[np.float64]]:
        """Luminance within the detector's cone (cd/m^2), (ny, nx): the normal view."""
    @property
    def luminance_stderr(self) -> Optional[npt.NDArray[np.float64]]: ...
    @property
    def luminance_views(self) -> Optional[npt.NDArray[np.float64]]:
        """Every view's luminance map (cd/m^2), (n_views, ny, nx); the first is ``luminance``."""
    @property
    def luminance_views_stderr(self) -> Optional[npt.NDArray[np.float64]]: ...
    @property
    def views_deg(self) -> List[List[float]]:
        """The views of ``luminance_views``: [theta_deg, phi_deg] each."""
    @property
    def luminance_hits(self) -> Optional[npt.NDArray[np.uint64]]: ...
    @property
    def angular_luminance(self) -> Optional[npt.NDArray[np.float64]]:
        """Luminance averaged over the target (cd/m^2), (n_theta, n_phi)."""
    @property
    def angular_luminance_stderr(self) -> Optional[npt.NDArray[np.float64]]: ...
    @property
    def X(self) -> Optional[npt.NDArray[np.float64]]:
        """CIE 1931 X per flux bin (lux-scaled), spectral scenes."""
    @property
    def X_stderr(self) -> Optional[npt.NDArray[np.float64]]: ...
    @property
    def Y(self) -> Optional[npt.NDArray[np.float64]]:
        """CIE 1931 Y per flux bin: illuminance (lux), spectral scenes."""
    @property
    def Y_stderr(self) -> Optional[npt.NDArray[np.float64]]: ...
    @property
    def Z(self) -> Optional[npt.NDArray[np.float64]]: ...
    @property
    def Z_stderr(self) -> Optional[npt.NDArray[np.float64]]: ...
    @property
    def u_prime(self) -> Optional[npt.NDArray[np.float64]]:
        """CIE 1976 u' per flux bin (NaN without light), spectral scenes."""
    @property
    def u_prime_stderr(self) -> Optional[npt.NDArray[np.float64]]: ...
    @property
    def v_prime(self) -> Optional[npt.NDArray[np.float64]]: ...
    @property
    def v_prime_stderr(self) -> Optional[npt.NDArray[np.float64]]: ...
    @property
    def stokes(self) -> Optional[npt.NDArray[np.float64]]:
        """Stokes S0..S3 (W/mm^2), (4, ny, nx), when polarization is traced."""
    @property
    def stokes_stderr(self) -> Optional[npt.NDArray[np.float64]]: ...
    @property
    def folder(self) -> Optional[str]:
        """The output folder of a run read by ``Run.load``."""
    @property
    def summary(self) -> Dict[str, Any]:
        """The content of summary.json."""
    @property
    def efficiency(self) -> Tuple[float, float]:
        """Extraction efficiency and its standard error."""
    @property
    def history(self) -> List[Dict[str, Any]]: ...
    @property
    def photons(self) -> int: ...
    @property
    def seed(self) -> int: ...
    @property
    def shard(self) -> Optional[Tuple[int, int]]: ...
    @property
    def stopped_by(self) -> str: ...
    @property
    def runtime_s(self) -> float: ...
    @property
    def scene(self) -> Scene: ...
    def write(self, dir: _Path) -> List[str]:
        """Write the command line's output set into ``dir``, all or nothing (a shard
        run: ``shard.json``)."""
    @staticmethod
    def load(dir: _Path) -> Run:
        """The run of an output folder (the CLI's or ``write``'s), or a shard folder."""
    def to_xarray(self) -> Any:
        """An xarray.Dataset of every map, its errors and hits, coordinates in mm/deg."""

class Optimization:
    """The outcome of ``Scene.optimize``."""

    @property
    def scene(self) -> Scene: ...
    @property
    def history(self) -> List[Dict[str, Any]]: ...
    @property
    def summary(self) -> Dict[str, Any]: ...
    @property
    def interrupted(self) -> bool: ...
    def write(self, dir: _Path) -> List[str]:
        """Write what ``blutrace optimize`` writes into ``dir``, all or nothing."""

class Characterisation:
    """A part characterised into an IS BSDF table (``Scene.characterise``)."""

    @property
    def part(self) -> str: ...
    @property
    def aoi(self) -> List[float]: ...
    @property
    def rotations(self) -> List[float]: ...
    @property
    def fates(self) -> Dict[str, npt.NDArray[np.float64]]:
        """Fractions reflected, transmitted, absorbed, lost: (rotations, aoi) arrays."""
    def to_bsdf(self) -> str:
        """The IS BSDF table's text."""
    def write(self, path: _Path) -> None:
        """Write the table to ``path``, whole or not at all."""

def sweep(
    scene: Scene,
    vary: Mapping[str, Sequence[Any]],
    photons: Optional[_Count] = None,
    seed: Optional[int] = None,
    executor: Any = None,
    zipped: bool = False,
    threads: Optional[int] = None,
) -> Any:
    """Trace every design of ``vary``: a pandas DataFrame, one row per design."""

def merge(runs: Sequence[Run], partial: bool = False) -> Run:
    """Merge shard runs into the run of all their photons, bit for bit."""

def read_exr(path: _Path) -> Dict[str, npt.NDArray[np.float32]]:
    """The channels of an EXR image blutrace wrote, as (ny, nx) float32 arrays."""
