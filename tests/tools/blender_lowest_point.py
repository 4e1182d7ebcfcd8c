# Imports a .glb with Blender's bundled glTF importer and prints, for every frame of its
# animation, the lowest world z (Blender is z up: the importer turns glTF's y up into z) of
# an object's evaluated mesh (shape keys applied), as CSV "t_s,lowest_m".
# Usage: blender -b --factory-startup --python blender_lowest_point.py -- FILE.glb OBJECT OUT.csv
import sys

import bpy
import numpy

# Debian 12's Blender 3.4 importer still names np.bool, an alias numpy 1.24 removed.
if "bool" not in numpy.__dict__:
    numpy.bool = bool

glb, name, out_path = sys.argv[sys.argv.index("--") + 1:][:3]
bpy.ops.wm.read_factory_settings(use_empty=True)
scene = bpy.context.scene
scene.render.fps = 120  # the file's key rate: one frame per key
scene.render.fps_base = 1
bpy.ops.import_scene.gltf(filepath=glb)
ob = bpy.data.objects[name]
start, end = (int(round(f)) for f in ob.animation_data.action.frame_range) if ob.animation_data and ob.animation_data.action else (0, 0)
# Shape-key animation lives on the mesh's key block: take the latest frame either has.
key = ob.data.shape_keys
if key and key.animation_data and key.animation_data.action:
    end = max(end, int(round(key.animation_data.action.frame_range[1])))
with open(out_path, "w") as out:
    out.write("t_s,lowest_m\n")
    for frame in range(start, end + 1):
        scene.frame_set(frame)
        depsgraph = bpy.context.evaluated_depsgraph_get()
        ev = ob.evaluated_get(depsgraph)
        mesh = ev.to_mesh()
        lowest = min((ev.matrix_world @ v.co).z for v in mesh.vertices)
        ev.to_mesh_clear()
        out.write(f"{frame / scene.render.fps:.6f},{lowest:.7f}\n")
print(f"blender_lowest_point: {name}: frames {start}..{end}, shape keys "
      f"{len(key.key_blocks) - 1 if key else 0}")
