"""2D-S and 2D-SS as benchmark methods (:class:`envelope.method.Method`).

Each takes its name from the module that makes its results (``METHOD``), so that the
name its results carry, and hence their file names, is its ``Method.name``.
"""

from __future__ import annotations

from pathlib import Path

from baselines import wwr2ds, wwr2dss
from baselines.wwr2ds import Wwr2dsConfig, run_2ds
from baselines.wwr2dss import Wwr2dssConfig, run_2dss
from envelope.method import Method
from envelope.method_input import MethodInput
from envelope.protocols import STREET_PROTOCOL, TRAIN_PROTOCOL, VIEW_PROTOCOLS

PROTOCOLS_2D = (*VIEW_PROTOCOLS, TRAIN_PROTOCOL, STREET_PROTOCOL)
"""In the tables' order (``envelope.protocols.PROTOCOLS``): the paper's facade views (``ideal``,
``multi``), then the views without facade ids, on which they find their own facades
(:mod:`baselines.own_facades`): the orbit (``train``, as neural3d) and a street capture."""
LIBRARIES = ("numpy", "torch", "kornia", "opencv-contrib-python-headless")


def debug_images_2dss(scene: MethodInput, protocol: str, config: Wwr2dssConfig,
                      folder: Path) -> None:
    """Run 2D-SS on ``scene`` only to write its pipeline images into ``folder``."""
    run_2dss(scene, protocol, config, debug_dir=folder)


METHOD_2DS = Method(
    name=wwr2ds.METHOD, inputs=("semantics", "depth", "poses"), protocols=PROTOCOLS_2D,
    config_type=Wwr2dsConfig, run=run_2ds, packages=("baselines",), libraries=LIBRARIES,
    description="per-view window/facade pixel ratio of the semantic mask (Szczesniak et al.); "
                "on views without facade ids, views grouped by their dominant depth plane",
    paper_name="2D-S",
)
METHOD_2DSS = Method(
    name=wwr2dss.METHOD, inputs=("rgb", "semantics", "depth", "poses"), protocols=PROTOCOLS_2D,
    config_type=Wwr2dssConfig, run=run_2dss, packages=("baselines",), libraries=LIBRARIES,
    description="facade plane by RANSAC, rectified facade, WWR in the rectified mask; on views "
                "without facade ids, own facades from depth planes measured by cell voting",
    debug_images=debug_images_2dss, paper_name="2D-SS",
)
