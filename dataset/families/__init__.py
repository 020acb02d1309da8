"""Procedural building families (skyscraper, L-shaped, realistic) and the geometry they are
assembled from: wall frames with openings, prisms, planar polygons to triangles."""
