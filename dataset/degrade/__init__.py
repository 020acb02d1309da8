"""Input-degradation protocols: a scene's inputs as they come from the field.

Each protocol is a named, seeded transformation of the *inputs* of a scene
(RGB, depth, semantic masks, normals, camera poses) with a severity; the
ground truth (``building.json``, ``mesh.ply``, facade-id images) is never
changed. :mod:`dataset.degrade.spec` names them and parses ``NAME[:SEVERITY],...``;
:mod:`dataset.degrade.scene_copy` writes a degraded copy of a scene folder that
every method reads as it reads any scene.
"""
