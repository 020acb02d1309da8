"""Which files are CityGML, and opening them (plain or compressed).

A CityGML file is named ``*.gml`` or ``*.xml``, also compressed: ``.gz``, ``.xz``, ``.bz2``
(read as they are). :func:`is_citygml` looks at a file's first bytes, so ``--input`` tells a
city model from other XML without parsing it.
"""

from __future__ import annotations

import bz2
import gzip
import lzma
from pathlib import Path
from typing import IO

SNIFF_BYTES = 4096  # the root element and its namespaces are in the first lines
CITYGML_NAMESPACES = ("http://www.opengis.net/citygml/2.0", "http://www.opengis.net/citygml/3.0")
_OPENERS = {".gz": gzip.open, ".xz": lzma.open, ".bz2": bz2.open}


class CityGmlError(ValueError):
    """Bad CityGML input; the message names the file and the element's ``gml:id``."""


def open_citygml(path: str | Path) -> IO[bytes]:
    """``path`` opened for reading bytes, decompressed by its suffix."""
    path = Path(path)
    return _OPENERS.get(path.suffix.lower(), open)(path, "rb")


def citygml_files(path: str | Path) -> list[Path]:
    """The CityGML files ``path`` names: itself, or every ``.gml``/``.xml`` file below a folder
    (also compressed: ``.gz``, ``.xz``, ``.bz2``), sorted.

    Raises
    ------
    CityGmlError
        ``path`` does not exist or the folder holds no such file.
    """
    path = Path(path)
    if path.is_file():
        return [path]
    if not path.is_dir():
        raise CityGmlError(f"{path} does not exist; give a CityGML file or a folder of them")
    files = sorted(p for p in path.rglob("*") if p.is_file() and _stem_suffix(p)[1])
    if not files:
        raise CityGmlError(f"{path} holds no .gml or .xml file (plain, .gz, .xz or .bz2)")
    return files


def is_citygml(path: str | Path) -> bool:
    """Whether ``path`` is a CityGML file (its first :data:`SNIFF_BYTES` name a CityGML
    namespace and ``CityModel``) or a folder whose first such file (sorted) is one. Cheap;
    never raises."""
    try:
        files = citygml_files(path)
        with open_citygml(files[0]) as fh:
            head = fh.read(SNIFF_BYTES)
    except (OSError, EOFError, ValueError, lzma.LZMAError):
        return False
    return b"CityModel" in head and any(ns.encode() in head for ns in CITYGML_NAMESPACES)


def citygml_stem(path: str | Path) -> str:
    """A CityGML file's name without its suffixes: ``4018259.xml.xz`` -> ``4018259``."""
    return _stem_suffix(Path(path))[0]


def _stem_suffix(path: Path) -> tuple[str, str]:
    name = path.name
    low = name.lower()
    for comp in ("", *_OPENERS):
        for ext in (".gml", ".xml"):
            if low.endswith(ext + comp):
                return name[: len(name) - len(ext + comp)], ext + comp
    return path.stem, ""
