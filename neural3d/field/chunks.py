"""How many points one call of a field takes at most, defined once.

A field is evaluated in chunks at one place: :class:`neural3d.field.trained.TrainedField`
splits every query (SDF, semantic logits, colour) into calls of at most
``chunk_points`` points, :data:`DEFAULT_CHUNK_POINTS` unless told otherwise
(``ExtractConfig.chunk_points``), which bounds the memory of the network's
activations. Meshing, vertex labels and colours and the footprint hand it whole
arrays (the marching-cubes grid in groups of slabs of about that many points,
:func:`neural3d.extraction.meshing.sample_sdf_grid`); the occupancy grid's
refresh during training splits by the same constant.
"""

from __future__ import annotations

DEFAULT_CHUNK_POINTS = 1 << 16  # 65k points: ~0.8 MB of float32 coordinates per call
