"""Importers: the sources other than the procedural presets (a user's labelled mesh or IFC
model, the official BuildNet3D layouts, :mod:`dataset.importers.source`), the sdfstudio
``meta_data.json`` layout, and the mesh analysis they share (ground, contacts, facade
grouping)."""
