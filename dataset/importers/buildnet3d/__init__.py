"""The official BuildNet3D layouts: the generator's output and meta_data.json."""
