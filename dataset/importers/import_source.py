"""The building a command line names: ``--mesh FILE`` or ``--ifc FILE``, with the import options.

Used by ``python -m dataset.generate``; the options come from
:func:`dataset.importers.import_config.add_import_arguments`.
"""

from __future__ import annotations

import argparse
import sys
from dataclasses import asdict
from typing import Any

from dataset.core.provenance import file_fingerprint
from dataset.core.truth import Building
from dataset.importers.import_config import import_config_from_args


def import_inputs(args: argparse.Namespace) -> dict[str, Any]:
    """What a scene imported from ``args`` was made from, for its provenance record: the
    fingerprints of the source file (and of the class overrides) and the import options."""
    source = args.mesh if getattr(args, "ifc", None) is None else args.ifc
    inputs: dict[str, Any] = {"source": file_fingerprint(source),
                              "import": asdict(import_config_from_args(args))}
    if getattr(args, "ifc_classes", None) is not None:
        inputs["classes"] = file_fingerprint(args.ifc_classes)
    return inputs


def import_from_args(args: argparse.Namespace) -> Building:
    """Import ``args.mesh`` or ``args.ifc`` (with ``args.ifc_classes``) as the options ask.

    IFC warnings are printed to stderr, one line per kind with its count.

    Raises
    ------
    ValueError
        Bad options or input (one line, with a fix).
    """
    config = import_config_from_args(args)
    if getattr(args, "ifc", None) is None:
        if args.ifc_classes is not None:
            raise ValueError("--ifc-classes goes with --ifc")
        from dataset.importers.mesh_import import import_labelled_mesh

        return import_labelled_mesh(args.mesh, config=config)
    from dataset.importers.ifc_classes import read_class_overrides
    from dataset.importers.ifc_import import import_ifc, warning_lines

    overrides = None if args.ifc_classes is None else read_class_overrides(args.ifc_classes)
    building = import_ifc(args.ifc, config=config, overrides=overrides,
                          progress=not args.quiet)
    for line in warning_lines(building.truth.extra["ifc"]):
        print(line, file=sys.stderr)
    return building
