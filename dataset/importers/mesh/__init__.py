"""Labelled meshes: reading, validation, ground, contacts, facade grouping."""
