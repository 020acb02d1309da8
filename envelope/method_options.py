"""A method's settings from text: the flags it declares and ``--set METHOD.KEY=VALUE``.

A method's config is a frozen dataclass (:class:`envelope.method.Method`). An
:class:`Option` maps one command-line flag onto one of its fields; the field's
annotation gives the value's type (``int``, ``float``, ``str``, ``bool``, ``Path``, a
``Literal`` of choices, any of them ``| None``) and its default the flag's default.
:func:`parse_value` reads a value for any field from text, a dotted key reaching a
field of a nested config (``isolation.wall_tolerance_m``); :func:`with_settings` returns
the config with typed values set, so that the config's own checks run on them.
"""

from __future__ import annotations

import dataclasses
import types
import typing
from collections.abc import Mapping
from pathlib import Path
from typing import Any, Literal, Union

NONE_TEXT = "none"  # the text that sets an optional field to None
_BOOL_TEXT = {"true": True, "yes": True, "1": True, "false": False, "no": False, "0": False}
_SCALARS = {int: "an integer", float: "a number", str: "text", Path: "a path"}


@dataclasses.dataclass(frozen=True)
class Option:
    """A command-line flag of a method: ``flag`` (``"--my-method-noise"``) sets ``key``
    (``"noise"``; dotted for a field of a nested config) of its config; ``help`` says
    what the field means (the command adds its default)."""

    flag: str
    key: str
    help: str

    def __post_init__(self) -> None:
        if not self.flag.startswith("--") or len(self.flag) < 3 or " " in self.flag:
            raise ValueError(f"option flag {self.flag!r} must look like --name")


def field_type(config_type: type, key: str) -> Any:
    """The annotation of field ``key`` of ``config_type`` (dotted: a nested config's field).

    Raises
    ------
    ValueError
        If ``config_type`` is not a dataclass or has no such field (the message lists
        the fields it has).
    """
    owner: Any = config_type
    parts = key.split(".")
    for k, part in enumerate(parts):
        if not dataclasses.is_dataclass(owner):
            where = (owner.__name__ if k == 0 else
                     f"{'.'.join(parts[:k])!r} ({_type_text(owner)})")
            raise ValueError(f"{where} is not a dataclass: it has no field {part!r}")
        hints = typing.get_type_hints(owner)
        names = [f.name for f in dataclasses.fields(owner) if f.init]
        if part not in names:
            raise ValueError(f"{owner.__name__} has no field {part!r}; its fields: "
                             f"{', '.join(names)}")
        owner = hints[part]
    return owner


def default_value(config_type: type, key: str) -> Any:
    """The value of field ``key`` in ``config_type``'s default instance."""
    value: Any = config_type()
    for part in key.split("."):
        value = getattr(value, part)
    return value


def parse_value(config_type: type, key: str, text: str) -> Any:
    """The value of field ``key`` of ``config_type`` that ``text`` spells (``"none"`` for
    ``None`` where the field allows it; ``true``/``false`` for a ``bool``).

    Raises
    ------
    ValueError
        If there is no such field, or ``text`` is not a value of its type.
    """
    hint = field_type(config_type, key)
    if dataclasses.is_dataclass(hint):
        fields = ", ".join(f.name for f in dataclasses.fields(hint) if f.init)
        raise ValueError(f"{key} is a nested config ({hint.__name__}): set one of its fields, "
                         f"{key}.FIELD with FIELD one of {fields}")
    try:
        return _parse(hint, text)
    except ValueError as exc:
        raise ValueError(f"{key} takes {_type_text(hint)}, got {text!r}") from exc


def with_settings(config: Any, settings: Mapping[str, Any]) -> Any:
    """``config`` with each ``key: value`` of ``settings`` set (dotted keys reach nested
    configs); the dataclasses' own checks run, and raise ``ValueError`` on a bad value."""
    top: dict[str, Any] = {}
    nested: dict[str, dict[str, Any]] = {}
    for key, value in settings.items():
        head, _, rest = key.partition(".")
        if rest:
            nested.setdefault(head, {})[rest] = value
        else:
            top[head] = value
    for head, inner in nested.items():
        top[head] = with_settings(top.get(head, getattr(config, head)), inner)
    return dataclasses.replace(config, **top) if top else config


def choices(config_type: type, key: str) -> tuple[Any, ...] | None:
    """The values a ``Literal`` field ``key`` allows (``None`` for any other field)."""
    hint = field_type(config_type, key)
    return typing.get_args(hint) if typing.get_origin(hint) is Literal else None


def _parse(hint: Any, text: str) -> Any:
    origin, args = typing.get_origin(hint), typing.get_args(hint)
    if origin in (Union, types.UnionType):
        if text.lower() == NONE_TEXT and type(None) in args:
            return None
        inner = [a for a in args if a is not type(None)]
        for alternative in inner:
            try:
                return _parse(alternative, text)
            except ValueError:
                continue
        raise ValueError(text)
    if origin is Literal:
        for choice in args:
            if str(choice) == text:
                return choice
        raise ValueError(text)
    if hint is bool:
        if text.lower() not in _BOOL_TEXT:
            raise ValueError(text)
        return _BOOL_TEXT[text.lower()]
    if hint in _SCALARS:
        return hint(text)
    raise ValueError(f"a field of type {_type_text(hint)} is not set from text")


def _type_text(hint: Any) -> str:
    """``hint`` in words, for messages: ``an integer or none``, ``one of mean, median``."""
    origin, args = typing.get_origin(hint), typing.get_args(hint)
    if origin in (Union, types.UnionType):
        words = [_type_text(a) for a in args if a is not type(None)]
        return " or ".join(words + ([NONE_TEXT] if type(None) in args else []))
    if origin is Literal:
        return "one of " + ", ".join(str(a) for a in args)
    if hint is bool:
        return "true or false"
    return _SCALARS.get(hint, getattr(hint, "__name__", str(hint)))
