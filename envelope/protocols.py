"""The view protocols, defined once: which views of a scene a method's result was made from.

``ideal``: one fronto-parallel view per facade; ``multi``: five oblique views
per facade (both carry the truth's facade ids, so a result's facades are the
truth's); ``train``: the orbit training views, and ``street``: the frames a car takes from
the road (``--street``, :mod:`dataset.rendering.street_views`), which carry no facade id
(neural3d, and the 2D methods, number their own facades on them:
:data:`OWN_FACADE_PROTOCOLS`). The names are also the scene's frame splits (:data:`Split`).
"""

from __future__ import annotations

from typing import Literal, get_args

ViewProtocol = Literal["ideal", "multi"]
"""The facade-view protocols of the 2D methods."""
Protocol = Literal["ideal", "multi", "train", "street"]
"""Every protocol a result may name."""

VIEW_PROTOCOLS: tuple[ViewProtocol, ...] = get_args(ViewProtocol)
IDEAL_PROTOCOL, MULTI_PROTOCOL = VIEW_PROTOCOLS
TRAIN_PROTOCOL: Protocol = "train"
STREET_PROTOCOL: Protocol = "street"
OWN_FACADE_PROTOCOLS: tuple[Protocol, ...] = (TRAIN_PROTOCOL, STREET_PROTOCOL)
"""Protocols of posed views without facade ids, on which the 2D methods find the facades
themselves (:mod:`baselines.own_facades`)."""
DEFAULT_PROTOCOLS: tuple[Protocol, ...] = (*VIEW_PROTOCOLS, TRAIN_PROTOCOL)
"""The protocols a comparison runs when not told otherwise (``--views``): the paper's ideal,
multi and orbit views. A method runs on those of them it declares."""
Split = Literal[Protocol, "eval"]
"""A scene frame's split: a protocol's views, or ``eval``: held-out orbit views no method runs
on (neural3d evaluates its renders on them)."""
EVAL_SPLIT: Split = "eval"
STREET_SPLIT: Split = STREET_PROTOCOL
SPLITS: tuple[Split, ...] = get_args(Split)
PROTOCOLS: tuple[Protocol, ...] = get_args(Protocol)
"""Every protocol, in the tables' order."""
