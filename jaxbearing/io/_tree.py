"""Pytrees in a data-only file: arrays in `.npz` (read with `allow_pickle=False`) and the
structure as strict JSON. Nothing in such a file can run code when it is read back.

`save_tree(path, tree)` writes, atomically (`atomic_write`), one `.npz` archive holding every
array leaf as `leaf_<i>` and the tree's structure as the JSON text of the array `__tree__`:
containers (dict with any keys, list, tuple), None, booleans, integers, floats (non-finite
ones tagged), strings, numpy arrays and scalars (by reference to their `leaf_<i>`, dtype
kept), and nodes of a pytree class (an `equinox.Module`, a dataclass or a named tuple), named
by module and qualified name with their fields.

`load_tree(path, what=...)` reads it back. A node's class is looked up among the modules
already imported (`sys.modules`, never importing one) of jaxbearing, optimise and optax
(`TRUSTED_PACKAGES`: an optimiser's state) and must be an `equinox.Module`, a dataclass or a named tuple; it is rebuilt from its fields without calling its `__init__`.
Anything else (a pickle, another archive, damaged JSON, an unknown class, an array of Python
objects) raises `TreeFileError`, one line naming the file. `check_like(tree, template)`
compares a loaded tree with a template: the same pytree structure and the same shape and
dtype kind of every array leaf.
"""

from __future__ import annotations

import dataclasses
import io
import json
import math
import os
import sys
import zipfile
from typing import Any

import numpy as np

from .._errors import UserInputError
from ._files import atomic_write

#: version of the layout (`__format__` in the JSON)
TREE_FORMAT = 1
_STRUCTURE = "__tree__"
#: a node's class must come from one of these packages (a file cannot name any other class)
TRUSTED_PACKAGES = ("jaxbearing", "optimise", "optax")


class TreeFileError(UserInputError):
    """A file that is not a data-only pytree file of the expected kind (one line, names it)."""


def _class_name(cls: type) -> str:
    return f"{cls.__module__}:{cls.__qualname__}"


def _is_namedtuple(cls: type) -> bool:
    return issubclass(cls, tuple) and hasattr(cls, "_fields")


def _is_module(cls: type) -> bool:
    import equinox as eqx

    return isinstance(cls, type) and issubclass(cls, eqx.Module)


def _is_jax_array(x: Any) -> bool:
    jax = sys.modules.get("jax")
    return jax is not None and isinstance(x, jax.Array)


def _encode(x: Any, arrays: list) -> Any:
    if x is None or isinstance(x, (bool, str)):
        return x
    if isinstance(x, int) and not isinstance(x, np.integer):
        return x
    if isinstance(x, float) and not isinstance(x, np.floating):
        return x if math.isfinite(x) else {"t": "float", "v": repr(x)}
    if isinstance(x, (np.ndarray, np.generic)) or _is_jax_array(x):
        a = np.asarray(x)
        if a.dtype.kind not in "biufc":
            raise TypeError(f"an array of dtype {a.dtype} cannot be stored as data")
        arrays.append(a)
        return {"t": "array", "i": len(arrays) - 1, "scalar": isinstance(x, np.generic)}
    cls = type(x)
    if _is_namedtuple(cls):
        return {
            "t": "node",
            "c": _class_name(cls),
            "v": {f: _encode(getattr(x, f), arrays) for f in cls._fields},
        }
    if isinstance(x, tuple):
        return {"t": "tuple", "v": [_encode(v, arrays) for v in x]}
    if isinstance(x, list):
        return {"t": "list", "v": [_encode(v, arrays) for v in x]}
    if isinstance(x, dict):
        return {"t": "dict", "v": [[_encode(k, arrays), _encode(v, arrays)] for k, v in x.items()]}
    if dataclasses.is_dataclass(x) and not isinstance(x, type):
        fields = {f.name: _encode(getattr(x, f.name), arrays) for f in dataclasses.fields(x)}
        return {"t": "node", "c": _class_name(cls), "v": fields}
    raise TypeError(f"a {cls.__qualname__} cannot be stored as data")


def tree_bytes(tree: Any) -> bytes:
    """The `.npz` bytes of `tree` (module docstring); TypeError for what is not plain data."""
    arrays: list = []
    structure = {"__format__": TREE_FORMAT, "tree": _encode(tree, arrays)}
    text = json.dumps(structure, allow_nan=False)
    buf = io.BytesIO()
    leaves = {f"leaf_{i}": a for i, a in enumerate(arrays)}
    np.savez(buf, **leaves, **{_STRUCTURE: np.frombuffer(text.encode(), dtype=np.uint8)})
    return buf.getvalue()


def save_tree(path: str | os.PathLike, tree: Any) -> None:
    """Write `tree` as a data-only file (module docstring), whole or absent (`atomic_write`)."""
    data = tree_bytes(tree)
    atomic_write(path, lambda f: f.write(data))


def _lookup(name: str) -> type:
    module, _, qualname = str(name).partition(":")
    if module.split(".")[0] not in TRUSTED_PACKAGES:
        raise ValueError(f"unknown class {name!r}")
    obj: Any = sys.modules.get(module)
    for part in qualname.split("."):
        if obj is None or part.startswith("__"):
            obj = None
            break
        obj = getattr(obj, part, None)
    if not isinstance(obj, type) or not (
        _is_module(obj) or _is_namedtuple(obj) or dataclasses.is_dataclass(obj)
    ):
        raise ValueError(f"unknown class {name!r}")
    return obj


def _decode(x: Any, arrays) -> Any:
    if x is None or isinstance(x, (bool, int, float, str)):
        return x
    if not isinstance(x, dict):
        raise ValueError(f"unexpected {type(x).__name__} in the structure")
    tag = x.get("t")
    if tag == "float":
        v = float(x["v"])
        if math.isfinite(v):
            raise ValueError("a tagged float must be non-finite")
        return v
    if tag == "array":
        a = arrays(int(x["i"]))
        return a[()] if x.get("scalar") else a
    if tag == "list":
        return [_decode(v, arrays) for v in x["v"]]
    if tag == "tuple":
        return tuple(_decode(v, arrays) for v in x["v"])
    if tag == "dict":
        out = {}
        for k, v in x["v"]:
            k = _decode(k, arrays)
            out[tuple(k) if isinstance(k, list) else k] = _decode(v, arrays)
        return out
    if tag == "node":
        cls = _lookup(x["c"])
        fields = {str(k): _decode(v, arrays) for k, v in dict(x["v"]).items()}
        if _is_namedtuple(cls):
            if set(fields) != set(cls._fields):
                raise ValueError(f"fields of {x['c']} do not match")
            return tuple.__new__(cls, [fields[f] for f in cls._fields])
        names = {f.name for f in dataclasses.fields(cls)}
        if set(fields) != names:
            raise ValueError(f"fields of {x['c']} do not match")
        obj = object.__new__(cls)
        for k, v in fields.items():
            object.__setattr__(obj, k, v)
        return obj
    raise ValueError(f"unknown tag {tag!r}")


def tree_from_bytes(data: bytes) -> Any:
    """The tree of `tree_bytes`; ValueError (or another ordinary exception) when `data` is not one."""
    with np.load(io.BytesIO(data), allow_pickle=False) as z:
        if not hasattr(z, "files") or _STRUCTURE not in z.files:
            raise ValueError("not a jaxbearing data file")
        structure = json.loads(bytes(z[_STRUCTURE]).decode())
        if not isinstance(structure, dict) or structure.get("__format__") != TREE_FORMAT:
            raise ValueError("unknown format")
        cache: dict = {}

        def arrays(i: int):
            if i not in cache:
                cache[i] = z[f"leaf_{i}"]
            return cache[i]

        return _decode(structure["tree"], arrays)


def load_tree(path: str | os.PathLike, what: str = "data file") -> Any:
    """The tree stored at `path` by `save_tree`; `TreeFileError` (one line naming the file and
    `what` was expected) for anything else, a pickle included, which is never unpickled."""
    path = os.fspath(path)
    try:
        with open(path, "rb") as f:
            data = f.read()
    except OSError as exc:
        raise TreeFileError(f"{path}: cannot read the {what}: {exc.strerror or exc}") from None
    try:
        return tree_from_bytes(data)
    except (ValueError, KeyError, TypeError, AttributeError, OSError, EOFError, zipfile.BadZipFile) as exc:
        reason = str(exc).splitlines()[0] if str(exc) else type(exc).__name__
        raise TreeFileError(f"{path}: not a {what} written by jaxbearing ({reason}); not loaded") from None


def check_like(tree: Any, template: Any, path: str | os.PathLike, what: str = "data file") -> None:
    """`TreeFileError` unless `tree` has the pytree structure of `template` and every array leaf
    the shape and dtype kind of the template's."""
    import jax

    try:
        leaves, structure = jax.tree_util.tree_flatten(tree)
        t_leaves, t_structure = jax.tree_util.tree_flatten(template)
    except Exception as exc:  # noqa: BLE001 - a malformed node: refuse the file
        raise TreeFileError(f"{os.fspath(path)}: not a {what} of this search ({exc})") from None
    if structure != t_structure:
        raise TreeFileError(f"{os.fspath(path)}: not a {what} of this search (its structure differs)")
    for a, b in zip(leaves, t_leaves):
        a, b = np.asarray(a), np.asarray(b)
        if a.shape != b.shape or (a.dtype.kind in "biu") != (b.dtype.kind in "biu"):
            raise TreeFileError(
                f"{os.fspath(path)}: not a {what} of this search (an array of shape {a.shape}, "
                f"expected {b.shape})"
            )
