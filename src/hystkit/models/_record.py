"""The base of every family's frozen ``Structure`` / ``Params`` dataclass: JSON round trips and
equality written once (:class:`Record`), and the count of numbers in a parameter record.
"""

from __future__ import annotations

import dataclasses
from typing import Any

import numpy as np


class Record:
    """Mixin for a family's frozen ``Structure`` / ``Params`` dataclasses.

    ``to_dict`` gives JSON-safe values (arrays and tuples as lists), ``from_dict`` rebuilds from
    the ``__init__`` fields, ``==`` compares every ``__init__`` field (arrays element-wise).
    Derived fields (``field(init=False)``) are left out of all three. Declare array-holding
    classes ``@dataclass(frozen=True, eq=False)`` so that this ``==`` is used; a structure of
    scalars and tuples may keep the dataclass's own ``==`` and hash.
    """

    @classmethod
    def _init_fields(cls) -> list[str]:
        return [f.name for f in dataclasses.fields(cls) if f.init]

    def to_dict(self) -> dict:
        return {name: _jsonable(getattr(self, name)) for name in self._init_fields()}

    @classmethod
    def from_dict(cls, d: dict):
        missing = [name for name in cls._init_fields() if name not in d
                   and _required(cls, name)]
        if missing:
            raise KeyError(f"{cls.__name__} needs {', '.join(missing)}")
        return cls(**{name: d[name] for name in cls._init_fields() if name in d})

    def __eq__(self, other: object) -> bool:
        if type(other) is not type(self):
            return NotImplemented
        return all(_same(getattr(self, name), getattr(other, name))
                   for name in self._init_fields())

    __hash__ = None


def _required(cls: type, name: str) -> bool:
    f = next(f for f in dataclasses.fields(cls) if f.name == name)
    return f.default is dataclasses.MISSING and f.default_factory is dataclasses.MISSING


def _jsonable(value: Any) -> Any:
    if isinstance(value, np.ndarray):
        return value.tolist()
    if isinstance(value, tuple | list):
        return [_jsonable(v) for v in value]
    if isinstance(value, np.generic):
        return value.item()
    return value


def _count_numbers(value: Any) -> int:
    if isinstance(value, dict):
        return sum(_count_numbers(v) for v in value.values())
    if isinstance(value, list | tuple):
        return sum(_count_numbers(v) for v in value)
    return int(isinstance(value, int | float) and not isinstance(value, bool))


def _same(a: Any, b: Any) -> bool:
    if isinstance(a, np.ndarray | list | tuple) or isinstance(b, np.ndarray | list | tuple):
        a, b = np.asarray(a), np.asarray(b)
        return a.shape == b.shape and bool(np.array_equal(a, b))
    return bool(a == b)
