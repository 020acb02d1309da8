"""The report's jinja2 templates (``metrics/report/templates/``, package data), autoescaped.

:func:`render` gives a template's HTML as :class:`markupsafe.Markup`, so a section rendered
by one template goes into another unescaped once and only once; every other value a
template prints is escaped. Two filters and one global:

- ``script_json``: JSON text for a ``<script>`` element (``<``, ``>``, ``&`` as ``\\u``
  escapes; not HTML-escaped: a script's text is not HTML);
- ``script``: a script (plotly.js) for a ``<script>`` element, unescaped (one holding
  ``</script`` is refused);
- ``static(name)``: a file of the templates folder (the page's CSS and JS) as it is.
"""

from __future__ import annotations

from functools import cache
from importlib import resources
from typing import Any

from jinja2 import Environment, PackageLoader, StrictUndefined
from markupsafe import Markup

TEMPLATES = "templates"


def render(name: str, **context: Any) -> Markup:
    """Template ``name`` (``*.html.j2``) rendered with ``context``."""
    return Markup(_environment().get_template(name).render(**context))


def script_json(text: str) -> Markup:
    """JSON text safe inside a ``<script>`` element: ``<``, ``>`` and ``&`` (which can occur
    only inside its strings) written as ``\\u003c``, ``\\u003e``, ``\\u0026``, the same JSON
    value with no ``</script`` or ``<!--`` in it."""
    return Markup(str(text).replace("<", "\\u003c").replace(">", "\\u003e")
                  .replace("&", "\\u0026"))


def script(text: str) -> Markup:
    """A script's text for a ``<script>`` element, unescaped.

    Raises
    ------
    ValueError
        If it holds ``</script``, which would end the element.
    """
    if "</script" in text.lower():
        raise ValueError("a script holding '</script' cannot be embedded")
    return Markup(text)


def static(name: str) -> Markup:
    """The text of ``templates/<name>`` (the page's CSS or JS), unescaped."""
    return Markup(resources.files("metrics.report").joinpath(TEMPLATES, name)
                  .read_text(encoding="utf-8"))


@cache
def _environment() -> Environment:
    env = Environment(loader=PackageLoader("metrics.report", TEMPLATES), autoescape=True,
                      undefined=StrictUndefined, trim_blocks=True, lstrip_blocks=True,
                      keep_trailing_newline=False)
    env.filters["script_json"] = script_json
    env.filters["script"] = script
    env.globals["static"] = static
    return env
