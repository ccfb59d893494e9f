"""Brings a keyframe run into Blender: `blender -P scripts/blender_import.py -- RUN_DIR [--pc2]`.

Reads what `keyframe export RUN_DIR` wrote into RUN_DIR/export/: by default the animated glTF
(<scene>.gltf: one object per moving mesh, its motion as shape keys), with --pc2 each NAME.obj with a
Mesh Cache modifier playing NAME.pc2. Sets the scene's frame rate and range to the run's. Blender turns
keyframe's Y-up metres into its Z-up world on import (glTF: in the data; OBJ: as the object's rotation,
which the Mesh Cache modifier's default axes keep)."""
import json
import os
import sys

import bpy

args = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
if not args:
    raise SystemExit(__doc__)
run_dir, use_pc2 = args[0], "--pc2" in args[1:]
scene_file = json.load(open(os.path.join(run_dir, "scene.json")))
fps = int(scene_file.get("time", {}).get("fps", 30))
frames = int(scene_file.get("time", {}).get("frames", 1))
export = os.path.join(run_dir, "export")

bpy.ops.wm.read_factory_settings(use_empty=True)
scene = bpy.context.scene
scene.render.fps = fps  # before the glTF import: it turns seconds into frames at this rate
scene.frame_start, scene.frame_end = 0, frames
if use_pc2:
    for name in sorted(f[:-4] for f in os.listdir(export) if f.endswith(".pc2")):
        bpy.ops.wm.obj_import(filepath=os.path.join(export, name + ".obj"))
        obj = bpy.context.selected_objects[0]
        cache = obj.modifiers.new("keyframe", "MESH_CACHE")
        cache.cache_format = "PC2"
        cache.filepath = os.path.join(export, name + ".pc2")
else:
    gltf = [f for f in os.listdir(export) if f.endswith(".gltf")]
    if len(gltf) != 1:
        raise SystemExit(f"{export}: expected one .gltf (keyframe export {run_dir}), found {gltf}")
    bpy.ops.import_scene.gltf(filepath=os.path.join(export, gltf[0]))
print(f"keyframe: {run_dir}: {', '.join(o.name for o in scene.objects)} at {fps} fps, frames 0..{frames}")
