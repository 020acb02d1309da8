"""IFC models through IfcOpenShell, and their export as labelled meshes."""
