"""Result dataclasses as JSON records: one ``to_dict`` / ``from_dict`` and one save / load pair.

A frozen dataclass that subclasses [`JsonRecord`][physgs.records.JsonRecord] writes its fields
as a JSON object (arrays as lists) and reads them back cast by each field's annotation: an
``np.ndarray`` field becomes an array again (of the dtype its field's metadata names, see
[`floats`][physgs.records.floats]; else the dtype JSON's values give), ``int`` / ``float`` fields
are cast, anything else is kept as JSON gives it. A field absent from the object, or ``None`` in
it, takes its default or ``None`` where its annotation allows one; keys that are no field are
ignored.
"""

from __future__ import annotations

import dataclasses
import types
import typing

import numpy as np

from physgs.atomic import write_json
from physgs.intermediate import read_json, refuse


def floats(**kwargs) -> dataclasses.Field:
    """A dataclass field read back as a float array (``np.asarray(value, float)``).

    Args:
        **kwargs (Any): passed on to ``dataclasses.field`` (e.g. ``default=None``).

    Returns:
        The field.
    """
    return dataclasses.field(metadata={"dtype": float}, **kwargs)


class JsonRecord:
    """Mixin for a frozen result dataclass: JSON-ready ``to_dict``, ``from_dict``, save and load."""

    #: what a record is, in the error that refuses a file which is not one
    RECORD_NAME: typing.ClassVar[str] = "record"

    def to_dict(self) -> dict:
        """The record as a JSON-ready dict (arrays as lists).

        Returns:
            Field name -> value, arrays as lists.
        """
        return {
            k: (v.tolist() if isinstance(v, np.ndarray) else v)
            for k, v in dataclasses.asdict(self).items()
        }

    @classmethod
    def from_dict(cls, d: dict):
        """The record that ``to_dict`` wrote, each field cast by its annotation.

        Args:
            d: field name -> value (arrays as lists; keys that are no field are ignored).

        Returns:
            (JsonRecord): The record.
        """
        hints = typing.get_type_hints(cls)
        kw = {}
        for f in dataclasses.fields(cls):
            if f.name not in d and f.default is not dataclasses.MISSING:
                continue
            kw[f.name] = _cast(d[f.name], hints[f.name], f.metadata.get("dtype"))
        return cls(**kw)

    def save(self, path) -> None:
        """Write the record to ``path`` as JSON, atomically.

        Args:
            path (str | os.PathLike): the ``.json`` file to write.
        """
        write_json(path, self.to_dict())

    @classmethod
    def load(cls, path, *, rule: str):
        """Read the record that [save][physgs.records.JsonRecord.save] wrote.

        Args:
            path (str | os.PathLike): the ``.json`` file.
            rule: the workflow rule that writes it (named in the error).

        Returns:
            (JsonRecord): The record.

        Raises:
            IntermediateFileError: the file is missing, unreadable or not such a record (it is
                removed, so ``rule`` rebuilds it).
        """
        d = read_json(path, rule=rule)
        try:
            return cls.from_dict(d)
        except (KeyError, TypeError, ValueError) as e:
            what = f"is not a {cls.RECORD_NAME} ({type(e).__name__}: {e})"
            raise refuse(path, what, rule) from None


def _cast(value, hint, dtype):
    """``value`` as JSON gave it, cast to the annotation ``hint`` (``None`` kept where allowed)."""
    if isinstance(hint, types.UnionType) or typing.get_origin(hint) is typing.Union:
        if value is None:
            return None
        hint = next(h for h in typing.get_args(hint) if h is not type(None))
    if hint is np.ndarray:
        return np.asarray(value, dtype)
    if hint in (int, float):
        return hint(value)
    return value
