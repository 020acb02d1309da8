"""Methods' options on a command line: the flags each method declares, ``--set``, and the
configs they make.

``metrics`` names no method: every flag here comes from a method's ``options``
(:class:`envelope.method.Method`), typed by its config's fields
(:mod:`envelope.method_options`), and ``--set METHOD.KEY=VALUE`` reaches any
field of any method's config. A method's config is its config type's default,
then its ``short_run`` values (the built-in default run, the robustness study),
then its flags, then ``--set`` (a later ``--set`` wins).
"""

from __future__ import annotations

import argparse
import sys
from collections.abc import Callable, Mapping, Sequence
from typing import Any

from envelope.method import Method
from envelope.method_options import (
    NONE_TEXT,
    Option,
    choices,
    default_value,
    parse_value,
    with_settings,
)


def add_method_options(parser: argparse.ArgumentParser, methods: Mapping[str, Method],
                       warn: Callable[[str], None] | None = None) -> None:
    """Add ``--set`` and, in one group per method, the flags each of ``methods`` declares.

    A flag that another option already uses, or whose help cannot be made (its config
    type fails to build), is skipped with a line to ``warn`` (stderr by default): a
    plugin cannot break the command.
    """
    warn = warn or (lambda line: print(line, file=sys.stderr))
    parser.add_argument(
        "--set", action="append", default=[], metavar="METHOD.KEY=VALUE",
        help="set any field of a method's config (repeatable; a later one wins, and it wins "
        "over the method's own flags): KEY is a field of the config dataclass, dotted for a "
        f"nested config's field; VALUE is read by the field's type ('{NONE_TEXT}' for an "
        "optional field, true/false for a switch)")
    for method in methods.values():
        if not method.options:
            continue
        group = parser.add_argument_group(f"{method.name} options",
                                          _escaped(method.description) or None)
        for option in method.options:
            try:
                group.add_argument(option.flag, dest=_dest(method, option),
                                   type=_reader(method, option.key),
                                   metavar=_metavar(method, option.key),
                                   help=_escaped(_help(method, option)))
            except argparse.ArgumentError as exc:
                warn(f"option {option.flag} of method {method.name} skipped: {exc}")
            except Exception as exc:  # a broken plugin must not stop the command
                warn(f"option {option.flag} of method {method.name} skipped: "
                     f"{type(exc).__name__}: {exc}")


def method_configs(args: argparse.Namespace, methods: Mapping[str, Method],
                   names: Sequence[str], *, short_run: bool, runs_here: bool) -> dict[str, Any]:
    """The config of each method of ``names`` that ``methods`` holds (the others are left
    to :func:`metrics.run.methods.method_specs`, which names them), from its flags and
    ``--set`` in ``args`` (parsed by a parser that :func:`add_method_options` made), on
    top of its ``short_run`` values when ``short_run``; each is checked by the method's
    ``check_config`` (``runs_here``: it will run in this process).

    Raises
    ------
    ValueError
        If a ``--set`` is malformed or names an unknown method or field, or a value is
        refused by the config or the method's check.
    """
    sets = parse_sets(args.set, methods)
    configs = {}
    for name in names:
        method = methods.get(name)
        if method is None:
            continue
        flags = {o.key: getattr(args, _dest(method, o), None) for o in method.options}
        settings = {**(method.short_run if short_run else {}),
                    **{k: v for k, v in flags.items() if v is not None}, **sets.get(name, {})}
        config = with_settings(method.config_type(), settings)
        if method.check_config is not None:
            method.check_config(config, runs_here)
        configs[name] = config
    return configs


def parse_sets(texts: Sequence[str], methods: Mapping[str, Method]) -> dict[str, dict[str, Any]]:
    """``METHOD.KEY=VALUE`` texts as typed settings per method name (a later text wins).

    Raises
    ------
    ValueError
        If a text is not ``METHOD.KEY=VALUE``, names no known method or no field of its
        config, or its value is not of the field's type.
    """
    longest_first = sorted(methods, key=len, reverse=True)  # a name may hold a dot
    settings: dict[str, dict[str, Any]] = {}
    for text in texts:
        target, sep, value = text.partition("=")
        name = next((n for n in longest_first if target.startswith(n + ".")), None)
        if not sep or "." not in target:
            raise ValueError(f"--set {text!r}: expected METHOD.KEY=VALUE")
        if name is None:
            raise ValueError(f"--set {text}: no method {target.partition('.')[0]!r}; choose "
                             f"from {', '.join(methods)} (`--list-methods`)")
        key = target[len(name) + 1:]
        try:
            settings.setdefault(name, {})[key] = parse_value(methods[name].config_type, key,
                                                             value)
        except ValueError as exc:
            raise ValueError(f"--set {text}: {name}: {exc}") from None
    return settings


def _dest(method: Method, option: Option) -> str:
    return f"{method.name}:{option.key}"


def _reader(method: Method, key: str) -> Callable[[str], Any]:
    """argparse's ``type`` of a flag: the field's value, or argparse's error."""
    def read(text: str) -> Any:
        try:
            return parse_value(method.config_type, key, text)
        except ValueError as exc:
            raise argparse.ArgumentTypeError(str(exc)) from None
    return read


def _metavar(method: Method, key: str) -> str:
    allowed = choices(method.config_type, key)
    return "{" + ",".join(map(str, allowed)) + "}" if allowed else key.rsplit(".", 1)[-1].upper()


def _help(method: Method, option: Option) -> str:
    """The option's help with its default and its short-run value."""
    notes = []
    default = default_value(method.config_type, option.key)
    if default is not None:
        notes.append(f"default: {default:g}" if isinstance(default, float) else
                     f"default: {default}")
    if option.key in method.short_run:
        notes.append("the built-in default run and the robustness study use "
                     f"{method.short_run[option.key]}")
    return "; ".join((option.help, *notes))


def _escaped(text: str) -> str:
    return text.replace("%", "%%")
