# Builds a shot in Blender through the keyframe cloth add-on and solves it with the real keyframe program:
#   KEYFRAME_BINARY=build/release/keyframe blender -b --factory-startup --python-exit-code 1 \
#       --python tests/blender/solve_shot.py -- WORK_DIR
# A subdivided plane hangs from a pin group; an animated Empty is the target of its lower corner; a UV sphere is
# a collider. Checks: the played-back corner at the keyframe lies within 1 cm of the Empty; the written scene
# validates against `keyframe schema`; a target out of reach reports the diagnosis (exit 7); Cancel sends
# SIGINT (exit 6) and the best controls so far play back; a cube, a plane, a cylinder and a torus are written as
# keyframe's colliders and load; a flock from an agent count fills a curve drawn in Blender. Any failed check
# raises (Blender exits 1).
import json
import math
import os
import shutil
import subprocess
import sys
import time

import bmesh
import bpy
import jsonschema  # Debian's python3-jsonschema, which Blender's Python reads

sys.dont_write_bytecode = True  # no __pycache__ in the source tree
sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "scripts", "blender"))
import keyframe_cloth  # noqa: E402

work = sys.argv[sys.argv.index("--") + 1]
binary = os.environ["KEYFRAME_BINARY"]
keyframe_cloth.register()

scene = bpy.context.scene
for o in list(scene.objects):
    bpy.data.objects.remove(o)
scene.frame_start, scene.frame_end = 1, 25
scene.render.fps, scene.render.fps_base = 24, 1
scene.keyframe.directory = work
scene.keyframe.binary = binary

# The cloth: a 0.8 m plane standing in Blender's XZ plane, 6 x 6 vertices, pinned along its top edge.
bpy.ops.mesh.primitive_plane_add(size=0.8, location=(0, 0, 1.2), rotation=(math.pi / 2, 0, 0))
cloth = bpy.context.object
cloth.name = "Sheet"
bm = bmesh.new()
bm.from_mesh(cloth.data)
bmesh.ops.subdivide_edges(bm, edges=bm.edges[:], cuts=4, use_grid_fill=True)
bm.to_mesh(cloth.data)
bm.free()
world = [cloth.matrix_world @ v.co for v in cloth.data.vertices]
assert len(world) == 36, len(world)
top = max(p.z for p in world)
pins = cloth.vertex_groups.new(name="pins")
pins.add([i for i, p in enumerate(world) if abs(p.z - top) < 1e-6], 1.0, 'REPLACE')
corner = min(range(len(world)), key=lambda i: (world[i].z, world[i].x))
group = cloth.vertex_groups.new(name="corner")
group.add([corner], 1.0, 'REPLACE')

# The target: an Empty keyed at the corner's rest place on frame 1 and 30 cm forward (-Y), 25 cm up on frame 25.
empty = bpy.data.objects.new("Target", None)
scene.collection.objects.link(empty)
empty.location = world[corner]
empty.keyframe_insert("location", frame=1)
empty.location = world[corner] + type(world[corner])((0, -0.3, 0.25))
empty.keyframe_insert("location", frame=25)

bpy.ops.mesh.primitive_uv_sphere_add(radius=0.15, location=(0.2, 0.3, 0.9))
sphere = bpy.context.object
sphere.keyframe.role = 'COLLIDER'

s = cloth.keyframe
s.role = 'CLOTH'
s.mass = 0.3
s.pin_group = "pins"
t = s.targets.add()
t.group, t.empty, t.frame = "corner", empty, 0  # 0: the Empty's keyed frames (25)
scene.keyframe.max_evaluations = 300


def played_back_corner(frame):
    scene.frame_set(frame)
    ev = cloth.evaluated_get(bpy.context.evaluated_depsgraph_get())
    return cloth.matrix_world @ ev.data.vertices[corner].co


# 1. Solve: the played-back corner meets the Empty at frame 25.
started = time.time()
assert bpy.ops.keyframe.solve(wait=True) == {'FINISHED'}, scene.keyframe.status
assert scene.keyframe.exit_code == 0, scene.keyframe.status
scene.frame_set(25)
goal = empty.matrix_world.translation.copy()
miss = (played_back_corner(25) - goal).length
rest_miss = (played_back_corner(1) - world[corner]).length
solve_s = time.time() - started
print(f"solve: {solve_s:.1f} s; corner at frame 25 is {100 * miss:.3f} cm from the Empty; "
      f"at frame 1 {100 * rest_miss:.3f} cm from its rest place; {scene.keyframe.status}")
assert miss < 0.01, miss
assert rest_miss < 0.002, rest_miss  # frame 1 is the rest shape (up to keyframe's imperfection)
assert cloth.modifiers["keyframe"].type == 'MESH_CACHE'
solved = json.load(open(os.path.join(work, "Sheet-run", "report.json")))
keep = os.environ.get("KEYFRAME_BLENDER_KEEP")  # scripts/blender/shot_results keeps the solved shot
if keep:
    shutil.copytree(work, keep)
    with open(os.path.join(keep, "results.csv"), "w") as f:
        f.write("particles,frames,evaluations,solve_s,played_back_miss_cm,status\n"
                f"{len(world)},{solved['steps']},{solved['evaluations']},{solve_s:.2f},{100 * miss:.3f},"
                f"{solved['status']}\n")

# 2. The written scene: keyframe's own frame (Y up) and it validates against `keyframe schema`.
path = os.path.join(work, "Sheet.json")
shot = json.load(open(path))
assert shot["cloth"]["mesh"] == {"file": "Sheet.obj", "up_axis": "z"}, shot["cloth"]["mesh"]
assert shot["cloth"]["colliders"][0]["type"] == "sphere"
c, r = shot["cloth"]["colliders"][0]["center"], shot["cloth"]["colliders"][0]["radius"]
assert max(abs(a - b) for a, b in zip(c, [0.2, 0.9, -0.3])) < 1e-6 and abs(r - 0.15) < 1e-6, (c, r)
assert shot["objectives"][0]["frame"] == 24 and shot["objectives"][0]["particles"] == [corner]
assert len(shot["cloth"]["pins"]) == 6
schema = json.loads(subprocess.run([binary, "schema"], capture_output=True, text=True, check=True).stdout)
validator = jsonschema.validators.validator_for(schema)(schema)


def validates(scene_path):
    with open(scene_path) as f:
        errors = [e.message for e in validator.iter_errors(json.load(f))]
    return not errors, errors


ok, why = validates(path)
assert ok, why
# The check can fail: a misspelt key does not validate.
bad_path = os.path.join(work, "bad.json")
with open(bad_path, "w") as f:
    json.dump(dict(shot, cloth=dict(shot["cloth"], stiffnes=1)), f)
assert not validates(bad_path)[0], "a misspelt key validated"
print("schema: the written scene validates; a misspelt key does not")

# 3. Out of reach: 5 m away. keyframe exits 7 and its diagnosis is the add-on's report.
empty.location = world[corner] + type(world[corner])((0, -5, 0))
empty.keyframe_insert("location", frame=25)
scene.keyframe.max_evaluations = 20
assert bpy.ops.keyframe.solve(wait=True) == {'CANCELLED'}
status = scene.keyframe.status
print("out of reach:", scene.keyframe.exit_code, status)
assert scene.keyframe.exit_code == 7, status
report = json.load(open(os.path.join(work, "Sheet-run", "report.json")))
assert status == report["diagnosis"]["diagnosis"] and "center_of_mass@24 is" in status, status
assert cloth.modifiers["keyframe"].type == 'MESH_CACHE'

# 4. Cancel: SIGINT once the first evaluation is reported; keyframe saves the best controls and exits 6.
scene.keyframe.max_evaluations = 100000
shot_path, _ = keyframe_cloth.write_scene(scene)
solve = keyframe_cloth.Solve(binary, shot_path, cloth.name)
deadline = time.time() + 60
while solve.poll() is None and not solve.progress.startswith("evaluation") and time.time() < deadline:
    time.sleep(0.05)
solve.cancel()
code = solve.wait()
level, text = keyframe_cloth.finish(scene, solve, code, cloth)
print("cancel:", code, text)
assert code == 6, (code, solve.errors)
assert text.startswith("cancelled"), text
# 5. Every collider shape: a rotated, scaled cube (a box along its axes), a plane (the ground), a cylinder (a
# capsule) and a torus, detected from their names, are written in keyframe's frame, validate against the schema
# and load in keyframe itself (`keyframe inspect SCENE` parses the scene and fills in its defaults).
bpy.ops.mesh.primitive_cube_add(size=0.2, location=(0.5, 0.3, 0.2), rotation=(0, 0, 0.3), scale=(1, 2, 0.5))
bpy.ops.mesh.primitive_plane_add(size=2, location=(0, 0, 0.05))
bpy.ops.mesh.primitive_cylinder_add(radius=0.05, depth=0.5, location=(-0.5, 0, 0.5))
bpy.ops.mesh.primitive_torus_add(major_radius=0.3, minor_radius=0.05, location=(0, 0.5, 0.1))
for o in scene.objects:
    if o.type == 'MESH' and o is not cloth:
        o.keyframe.role = 'COLLIDER'
shot_path, _ = keyframe_cloth.write_scene(scene)
colliders = {c["type"]: c for c in json.load(open(shot_path))["cloth"]["colliders"]}
assert sorted(colliders) == ["box", "capsule", "ground", "sphere", "torus"], sorted(colliders)


def near(a, b, tol=1e-6):
    return max(abs(x - y) for x, y in zip(a, b)) < tol


box, turn = colliders["box"], 0.3
assert near(box["center"], [0.5, 0.2, -0.3]) and near(box["size"], [0.2, 0.4, 0.1]), box
assert near(box["u_axis"], [math.cos(turn), 0, -math.sin(turn)]), box
assert near(box["v_axis"], [-math.sin(turn), 0, -math.cos(turn)]), box
assert abs(sum(a * b for a, b in zip(box["u_axis"], box["v_axis"]))) < 1e-12, box
assert near(colliders["ground"]["center"], [0, 0.05, 0]) and near(colliders["ground"]["axis"], [0, 1, 0])
capsule = colliders["capsule"]
assert near(capsule["a"], [-0.5, 0.3, 0]) and near(capsule["b"], [-0.5, 0.7, 0]) and abs(capsule["radius"] - 0.05) < 1e-6
torus = colliders["torus"]
assert near(torus["center"], [0, 0.1, -0.5]) and abs(torus["radius"] - 0.3) < 1e-6 and abs(torus["tube_radius"] - 0.05) < 1e-6
ok, why = validates(shot_path)
assert ok, why
inspect = subprocess.run([binary, "inspect", shot_path], capture_output=True, text=True)
assert inspect.returncode == 0, inspect.stdout + inspect.stderr
print("colliders: box, ground, capsule and torus written, validated and loaded by keyframe")
# 6. A flock: 30 agents start around an Empty marked Flock, and fill a closed Bezier circle (radius 2.5 m, 3 m
# along -Y) marked Flock shape at frame 49 (2 s). Solve; keyframe's own measure has at least 95 % of them
# inside; the agents play back on their own object, every agent's arrowhead (its 12 vertices' mean, a few cm
# behind the agent) within the circle grown by 10 cm at frame 49, and most of them outside it at frame 1.
for o in scene.objects:
    o.keyframe.role = 'NONE'
scene.frame_end = 49
bpy.ops.object.empty_add(location=(0, 0, 0))
flock = bpy.context.object
flock.name = "Flock"
flock.keyframe.role = 'FLOCK'
flock.keyframe.agents, flock.keyframe.spawn_radius = 30, 3
bpy.ops.curve.primitive_bezier_circle_add(radius=2.5, location=(0, -3, 0))
circle = bpy.context.object
circle.keyframe.role, circle.keyframe.frame = 'SHAPE', 49
scene.keyframe.max_evaluations = 300
started = time.time()
assert bpy.ops.keyframe.solve(wait=True) == {'FINISHED'}, scene.keyframe.status
flock_path = os.path.join(work, "Flock.json")
flock_shot = json.load(open(flock_path))
ok, why = validates(flock_path)
assert ok, why
polygon = flock_shot["objectives"][0]["polygon"]
assert flock_shot["objectives"][0]["frame"] == 48 and len(polygon) >= 12, flock_shot["objectives"]
assert all(abs(math.hypot(x, z - 3) - 2.5) < 1e-3 for x, z in polygon), polygon  # Blender -Y is keyframe +z
measures = json.load(open(os.path.join(work, "Flock-run", "report.json")))["measures"]
assert measures[0]["inside_fraction"] >= 0.95, measures
agents = bpy.data.objects["Flock agents"]
assert agents.modifiers["keyframe"].type == 'MESH_CACHE'


def agents_in_circle(frame, grown):
    scene.frame_set(frame)
    ev = agents.evaluated_get(bpy.context.evaluated_depsgraph_get())
    points = [agents.matrix_world @ v.co for v in ev.data.vertices]
    assert len(points) == 30 * 12, len(points)  # each agent an arrowhead of 12 vertices (keyframe export)
    centres = [sum(points[12 * k:12 * k + 12], type(points[0])()) / 12 for k in range(30)]
    return sum(math.hypot(c.x, c.y + 3) < 2.5 + grown for c in centres)


at_shape, at_start = agents_in_circle(49, 0.1), agents_in_circle(1, 0.1)
print(f"flock: {time.time() - started:.1f} s; inside fraction {measures[0]['inside_fraction']:.3f}; played back "
      f"{at_shape} of 30 agents in the circle at frame 49, {at_start} at frame 1; {scene.keyframe.status}")
assert at_shape == 30 and at_start <= 20, (at_shape, at_start)
print("BLENDER ADD-ON CHECKS PASSED")
