"""Photos in: a folder of photos (or an existing COLMAP model, or a nerfstudio
``transforms.json``) to a scene folder with poses and intrinsics from structure from motion,
in metres with z up (docs/importing.md, section 9)."""
