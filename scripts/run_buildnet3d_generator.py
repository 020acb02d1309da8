"""Run the unmodified BuildNet3D-dataset generator headless with the bpy 4.2 wheel.

usage: /tmp/bpyenv/bin/python run_generator.py GEN_ROOT OUT SEED
(GEN_ROOT/buildnet3d_dataset/config/dataset_config.json decides size, views, image size)

Blender 4.2 no longer bundles the legacy STL add-on (``export_mesh.stl``, moved to the
extensions platform); the generator calls it for ``pointCloud/{i}.stl``, which nothing
here reads. This runner registers ``export_mesh.stl`` as an alias of 4.2's built-in
``wm.stl_export``; the generator's own code is not changed.
"""
import random
import runpy
import sys

import numpy as np

gen, out, seed = sys.argv[1], sys.argv[2], int(sys.argv[3])
sys.path.insert(0, gen)
random.seed(seed)
np.random.seed(seed)  # noqa: NPY002 -- the generator draws from the legacy global RNG
import bpy  # noqa: E402


class EXPORT_MESH_OT_stl(bpy.types.Operator):
    bl_idname = "export_mesh.stl"
    bl_label = "STL (alias of wm.stl_export)"
    filepath: bpy.props.StringProperty()

    def execute(self, context):
        return bpy.ops.wm.stl_export(filepath=self.filepath)


bpy.ops.wm.open_mainfile(filepath=f"{gen}/buildnet3d_dataset/blender_scripts/setup.blend")
bpy.utils.register_class(EXPORT_MESH_OT_stl)
sys.argv = ["dataset.py", "--", "--output-dir", out]
runpy.run_path(f"{gen}/buildnet3d_dataset/blender_scripts/dataset.py", run_name="__main__")
