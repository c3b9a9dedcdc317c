"""The scenes bundled with blutrace (the repository's ``scenes/``, packaged in the wheel),
so examples run from an installed package:

>>> import blutrace as bt
>>> scene = bt.Scene.load(bt.scenes.path("notebook14"))
>>> bt.scenes.names()[:3]
['bef-stack', 'bench-box', 'cad-reflector']
"""

from __future__ import annotations

import pathlib

#: Where the bundled scenes are: package data in an installed blutrace (a link to the
#: repository's scenes/ in a checkout).
ROOT = pathlib.Path(__file__).resolve().parent / "_scenes"


def names() -> list[str]:
    """The bundled scenes' names (folders holding a ``scene.toml``), sorted; test scenes
    are ``test/<name>``."""
    return sorted(
        p.parent.relative_to(ROOT).as_posix() for p in ROOT.glob("**/scene.toml")
    )


def path(name: str) -> pathlib.Path:
    """The folder of bundled scene ``name`` (for ``Scene.load``); a name that is none is a
    ValueError listing them."""
    if not isinstance(name, str):
        raise TypeError(f"name must be a str, got {type(name).__name__}")
    folder = ROOT / name
    if ".." in pathlib.PurePosixPath(name).parts or not (folder / "scene.toml").is_file():
        raise ValueError(f"name: no bundled scene {name!r} (bundled: {', '.join(names())})")
    return folder
