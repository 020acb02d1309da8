"""Importers: a user's labelled mesh (OBJ, PLY, glTF), IFC, BuildNet3D and meta_data.json
scene folders, and the mesh analysis they share (ground, contacts, facade grouping)."""
