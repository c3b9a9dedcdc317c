"""blutrace: Monte Carlo photon tracing and optimization of LCD backlight units.

>>> import blutrace as bt
>>> scene = bt.Scene.load("scenes/notebook14")      # a folder or a scene.toml
>>> scene.set("surfaces.lgp_back.ink_albedo", 0.8)  # key paths as `optimize --vary`
>>> run = scene.trace(photons=1_000_000, seed=1)
>>> run.flux.shape, run.efficiency                   # numpy (ny, nx) W/mm^2; (value, stderr)
>>> run.x_mm, run.y_mm                               # bin centres (mm from the detector origin)
>>> df = bt.sweep(scene, {"sources.*.center.2": [5, 8, 11]}, photons=1e5)  # pandas
>>> bt.Scene.load(bt.scenes.path("notebook14"))      # the bundled scenes, installed

Array conventions: ``Run.flux``, ``flux_stderr`` and ``hits`` have shape ``(ny, nx)``:
row ``iy`` is the ``iy``-th bin along the detector's ``v`` from its origin, column ``ix``
along ``u``; ``flux`` is irradiance in W/mm^2 per bin. ``Run.angular`` and
``angular_stderr`` have shape ``(n_theta, n_phi)``, radiant intensity in W/sr per bin.
The same seed and photons give the same arrays bit for bit on any thread count, and the
same as the command line's ``flux.exr`` (stored there as float32).

Tracing releases the GIL; Ctrl-C (``KeyboardInterrupt``) stops a trace within a second
and raises, writing nothing; it stops ``Scene.optimize`` too, which then returns the
outcome of the designs traced before it (``Optimization.interrupted``). Errors are
exceptions: ``SceneError`` for a scene file (the message names the file and the field),
``ValueError`` (a bad value) or ``TypeError`` (a wrong type) for an argument, the message
naming it, and ``BlutraceError`` for anything else (an internal error included). Values
of reports (``summary``, ``history``) that are undefined, such as a metric of a design
that put no light on the target, are None, as ``null`` in the JSON files.
"""

from __future__ import annotations

from ._native import (
    BlutraceError,
    Characterisation,
    Optimization,
    Run,
    Scene,
    SceneError,
    __version__,
    merge,
    read_exr,
)
from . import scenes
from ._study import sweep

__all__ = [
    "BlutraceError",
    "Characterisation",
    "Optimization",
    "Run",
    "Scene",
    "SceneError",
    "__version__",
    "merge",
    "read_exr",
    "scenes",
    "sweep",
]
