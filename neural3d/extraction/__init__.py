"""Extraction: marching cubes, per-vertex semantics, areas and WWR per facade, footprint."""
