"""The view protocols, defined once: which views of a scene a method's result was made from.

``ideal``: one fronto-parallel view per facade; ``multi``: five oblique views
per facade (both carry the truth's facade ids, so a result's facades are the
truth's); ``train``: the orbit training views (neural3d numbers its own
facades). The names are also the scene's frame splits (:data:`Split`).
"""

from __future__ import annotations

from typing import Literal, get_args

ViewProtocol = Literal["ideal", "multi"]
"""The facade-view protocols of the 2D methods."""
Protocol = Literal["ideal", "multi", "train"]
"""Every protocol a result may name."""

VIEW_PROTOCOLS: tuple[ViewProtocol, ...] = get_args(ViewProtocol)
IDEAL_PROTOCOL, MULTI_PROTOCOL = VIEW_PROTOCOLS
TRAIN_PROTOCOL: Protocol = "train"
Split = Literal[Protocol, "eval", "street"]
"""A scene frame's split: a protocol's views, ``eval``: held-out orbit views no method runs
on (neural3d evaluates its renders on them), or ``street``: the frames a car takes from the
road (``--street``, :mod:`dataset.rendering.street_views`; placed and named without the
truth: no ``facade_id``; no method reads them yet)."""
EVAL_SPLIT: Split = "eval"
STREET_SPLIT: Split = "street"
SPLITS: tuple[Split, ...] = get_args(Split)
PROTOCOLS: tuple[Protocol, ...] = get_args(Protocol)
"""Every protocol, in the tables' order."""
