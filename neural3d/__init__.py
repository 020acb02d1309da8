"""The 3D method: a semantic neural SDF, its mesh, WWR and footprint."""
