"""The type stubs (blutrace/__init__.pyi) say what the extension module has: every public
class, method, property and function, and each callable's parameters in order."""

from __future__ import annotations

import ast
import inspect
import pathlib

import blutrace as bt

STUBS = pathlib.Path(bt.__file__).with_name("__init__.pyi")


def stubs():
    """Classes (name -> {member: def}) and functions (name -> def) of the stub file."""
    tree = ast.parse(STUBS.read_text())
    classes, functions = {}, {}
    for node in tree.body:
        if isinstance(node, ast.ClassDef):
            members = (n for n in node.body if isinstance(n, ast.FunctionDef))
            classes[node.name] = {n.name: n for n in members}
        elif isinstance(node, ast.FunctionDef):
            functions[node.name] = node
    return classes, functions


def stub_params(fn: ast.FunctionDef) -> list:
    a = fn.args
    return [x.arg for x in a.posonlyargs + a.args + a.kwonlyargs if x.arg != "self"]


def native_params(fn) -> tuple:
    """The named parameters and whether there is a ``**options``."""
    ps = [p for p in inspect.signature(fn).parameters.values() if p.name not in ("self", "$self")]
    named = [p.name for p in ps if p.kind is not p.VAR_KEYWORD]
    return named, any(p.kind is p.VAR_KEYWORD for p in ps)


def check_params(where: str, native, stub: ast.FunctionDef) -> None:
    named, options = native_params(native)
    declared = stub_params(stub)
    if options:  # **options: the stub spells them out after the named ones
        assert declared[: len(named)] == named, where
    else:
        assert declared == named, where


def test_the_stubs_name_every_public_member_with_its_parameters():
    classes, functions = stubs()
    for name in bt.__all__:
        obj = getattr(bt, name)
        if inspect.isclass(obj):
            if issubclass(obj, BaseException):
                assert name in classes, name
                continue
            public = {n for n in dir(obj) if not n.startswith("_")}
            declared = {n for n in classes[name] if not n.startswith("_")}
            assert public == declared, f"{name}: missing {public - declared}, extra {declared - public}"
            for m in sorted(public):
                if not isinstance(inspect.getattr_static(obj, m), property) and callable(getattr(obj, m)):
                    check_params(f"{name}.{m}", getattr(obj, m), classes[name][m])
        elif callable(obj):
            assert name in functions, name
            check_params(name, obj, functions[name])
