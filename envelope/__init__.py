"""The core every part may import: classes, protocols, units and frames (camera), the WWR
definition, meshes, plane polygons (area, normal), the truth and scene records, results, the
method interface, provenance, atomic writes and CLI errors."""
