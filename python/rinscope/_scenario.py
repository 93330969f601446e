"""A scenario as a validated, dict-like object that reads and writes like its TOML."""
from __future__ import annotations

import copy as _copy
import json as _json
import math
import os
from pathlib import Path
from typing import Any, Iterator

from . import _rinscope


def _dict_of_toml(text: str) -> dict:
    return _json.loads(_rinscope.toml_to_json(text))


def _dotted(path: tuple) -> str:
    """A key's path as rinscope's messages write it: ``turntable.axis[1].swing_half_angle_arcsec``."""
    out = ""
    for key in path:
        out += f"[{key}]" if isinstance(key, int) else (f".{key}" if out else str(key))
    return out


def _plain(value: Any, path: tuple) -> Any:
    """A value as TOML holds it: numpy scalars and arrays, tuples and paths become Python numbers,
    lists and strings; what TOML cannot hold is refused naming the key."""
    if isinstance(value, Section):
        return value.to_dict()
    if isinstance(value, SectionList):
        return value.to_list()
    if isinstance(value, float) and not math.isfinite(value):
        # JSON, which carries the document to the library, has no NaN or infinity.
        raise ValueError(f"`{_dotted(path)}` = {value}: not a finite number")
    if isinstance(value, (bool, int, float, str)):
        return value
    if isinstance(value, dict):
        return {str(k): _plain(v, path + (str(k),)) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [_plain(v, path + (i,)) for i, v in enumerate(value)]
    if isinstance(value, os.PathLike):
        return os.fspath(value)
    if hasattr(value, "tolist"):  # numpy scalars and arrays (a numpy float is a float: above)
        return _plain(value.tolist(), path)
    if value is None:
        raise ValueError(f"`{_dotted(path)}` = None: TOML has no null; to take the default, delete the key (del ...)")
    raise ValueError(f"`{_dotted(path)}` = {value!r}: a {type(value).__name__} is not a TOML value (numbers, strings, booleans, lists, tables)")


def _toml_of_dict(data: dict) -> str:
    return _rinscope.json_to_toml(_json.dumps(data))


def _at(root: "Scenario", path: tuple) -> Any:
    """The table (or array of tables) at `path` in the scenario's document."""
    node = root._doc
    for key in path:
        node = node[key]
    return node


class Section:
    """One table of a scenario (``s["table"]``, ``s.table.inner``): reads and writes its keys as a
    dict and as attributes; every write is validated against the whole scenario and undone if it is
    refused (ValueError with rinscope's message naming the key, value and unit)."""

    __slots__ = ("_root", "_path")

    def __init__(self, root: "Scenario", path: tuple):
        object.__setattr__(self, "_root", root)
        object.__setattr__(self, "_path", path)

    def _node(self) -> dict:
        return _at(self._root, self._path)

    def __getitem__(self, key: str) -> Any:
        return _wrap(self._root, self._path + (key,), self._node()[key])

    def __setitem__(self, key: str, value: Any) -> None:
        self._root._assign(self._path + (key,), value)

    def __delitem__(self, key: str) -> None:
        self._root._assign(self._path + (key,), _DELETE)

    def __getattr__(self, key: str) -> Any:
        try:
            return self[key]
        except KeyError:
            where = _dotted(self._path) or "the scenario"
            raise AttributeError(f"{where} has no key {key!r}; it has: {', '.join(self._node())}") from None

    def __setattr__(self, key: str, value: Any) -> None:
        self[key] = value

    def __delattr__(self, key: str) -> None:
        del self[key]

    def __contains__(self, key: str) -> bool:
        return key in self._node()

    def __iter__(self) -> Iterator[str]:
        return iter(list(self._node()))

    def __len__(self) -> int:
        return len(self._node())

    def __dir__(self):
        return list(self._node())

    def keys(self):
        return list(self._node())

    def items(self):
        return [(k, self[k]) for k in self._node()]

    def get(self, key: str, default: Any = None) -> Any:
        return self[key] if key in self else default

    def update(self, values: dict | None = None, **more: Any) -> None:
        """Sets several keys at once, validated together (for keys that must change together)."""
        changes = dict(values or {}, **more)
        self._root._assign_many([(self._path + (k,), v) for k, v in changes.items()])

    def to_dict(self) -> dict:
        """A deep copy as plain dicts and lists."""
        return _copy.deepcopy(self._node())

    def __eq__(self, other: object) -> bool:
        if isinstance(other, Section):
            return self._node() == other._node()
        return self._node() == other

    def __repr__(self) -> str:
        return f"<rinscope section [{_dotted(self._path)}] {self._node()!r}>"


def _wrap(root: "Scenario", path: tuple, value: Any) -> Any:
    """A table as a Section, an array of tables as a SectionList, a value as a copy."""
    if isinstance(value, dict):
        return Section(root, path)
    if isinstance(value, list) and value and all(isinstance(v, dict) for v in value):
        return SectionList(root, path)
    return _copy.deepcopy(value)


class SectionList:
    """An array of tables (``[[turntable.axis]]``): index it by position or by its tables' ``name``
    (``s.turntable.axis["inner"]``, or ``axis`` for ``[[scheme.rate]]``); each element is a Section,
    so ``s.turntable.axis["inner"].swing_half_angle_arcsec = 450`` is validated like any write."""

    __slots__ = ("_root", "_path")

    def __init__(self, root: "Scenario", path: tuple):
        self._root, self._path = root, path

    def _node(self) -> list:
        return _at(self._root, self._path)

    def _index(self, key: Any) -> int:
        items = self._node()
        if isinstance(key, int):
            if not -len(items) <= key < len(items):
                raise IndexError(f"{_dotted(self._path)}[{key}]: there are {len(items)}")
            return key % len(items)
        for field in ("name", "axis"):
            found = [i for i, t in enumerate(items) if t.get(field) == key]
            if found:
                return found[0]
        names = [t.get("name", t.get("axis")) for t in items]
        raise KeyError(f"{_dotted(self._path)}: no table named {key!r}; they are: {names}")

    def __getitem__(self, key: Any) -> Any:
        i = self._index(key)
        return _wrap(self._root, self._path + (i,), self._node()[i])

    def __setitem__(self, key: Any, value: Any) -> None:
        self._root._assign(self._path + (self._index(key),), value)

    def __len__(self) -> int:
        return len(self._node())

    def __iter__(self):
        return (self[i] for i in range(len(self)))

    def to_list(self) -> list:
        return _copy.deepcopy(self._node())

    def __eq__(self, other: object) -> bool:
        return self._node() == (other._node() if isinstance(other, SectionList) else other)

    def __repr__(self) -> str:
        return f"<rinscope array of tables [[{_dotted(self._path)}]] {self._node()!r}>"


_DELETE = object()


class Scenario(Section):
    """A rinscope scenario: ``rinscope.load(name_or_path)``.

    Reads and writes like its TOML file, as nested dicts or attributes::

        s = rinscope.load("jiang2017-dual-axis")
        s["table"]["inner"]["swing_half_angle_arcsec"] = 450      # or
        s.table.inner.swing_half_angle_arcsec = 450

    Every write is checked by rinscope's own validation, so a typo'd key or an out-of-range value
    raises ValueError at once, with the message ``rinscope check-config`` gives; the scenario is
    left as it was. ``s.toml`` is its TOML text, ``s.save(path)`` writes it, ``s.resolved()`` is
    the scenario with every default filled in.
    """

    __slots__ = ("_doc", "_origin")

    def __init__(self, toml: str, origin: str = "python"):
        _rinscope.check(toml, origin)
        object.__setattr__(self, "_doc", _dict_of_toml(toml))
        object.__setattr__(self, "_origin", origin)
        Section.__init__(self, self, ())

    def _check(self, data: dict) -> None:
        _rinscope.check(_toml_of_dict(data), self._origin)

    def _assign_many(self, changes: list) -> None:
        data = _copy.deepcopy(self._doc)
        for path, value in changes:
            node = data
            for key in path[:-1]:
                node = node[key] if isinstance(node, list) else node.setdefault(key, {})
                if not isinstance(node, (dict, list)):
                    raise ValueError(f"{'.'.join(map(str, path[:-1]))} is a value, not a table")
            if value is _DELETE:
                node.pop(path[-1], None)
            else:
                node[path[-1]] = _plain(value, path)
        try:
            self._check(data)
        except ValueError as e:
            keys = ", ".join(_dotted(p) for p, _ in changes)
            raise ValueError(f"{keys}: {e}") from None
        object.__setattr__(self, "_doc", data)

    def _assign(self, path: tuple, value: Any) -> None:
        self._assign_many([(path, value)])

    @property
    def toml(self) -> str:
        """The scenario as TOML text (what ``save`` writes)."""
        return _toml_of_dict(self._doc)

    @property
    def name(self) -> str:
        return self._doc.get("scenario", {}).get("name", "")

    @property
    def title(self) -> str:
        return self._doc.get("scenario", {}).get("title", "")

    def resolved(self) -> "Scenario":
        """The same scenario with every default written out (rinscope's resolved config)."""
        return Scenario(_rinscope.check(self.toml, self._origin), self._origin)

    def copy(self) -> "Scenario":
        return Scenario(self.toml, self._origin)

    def save(self, path: str | os.PathLike) -> Path:
        """Writes the TOML to ``path`` through the library's atomic writer (``PATH.partial``, then
        renamed): a file that was there is replaced only by a complete one, and a FIFO, a device or
        a folder is refused (OSError naming it)."""
        path = Path(path)
        _rinscope.write_atomically(str(path), self.toml)
        return path

    def __repr__(self) -> str:
        return f"<rinscope scenario {self.name!r}: {self.title}>"

