# keyframe cloth: author a keyframed cloth shot in Blender, solve it with `keyframe optimize`, play it back.
# Blender 3.4 (Debian 12's) and later. Install: README, "Authoring a shot in Blender".
#
# A mesh object becomes the cloth (its vertices the particles, in Blender's order); vertex groups name the pins
# and the keyframed sets; an Empty's location at a frame is a set's target (its centre of mass, or every vertex
# carried rigidly by the Empty); spheres, cylinders (as capsules), cubes (as boxes), planes and tori become
# colliders. A flock instead: an object marked Flock is where its agents start (their count and spawn radius), and
# closed curves marked Flock shape are the shapes it fills at their frames (drawn on Blender's ground, XY).
# The scene
# is written in keyframe's frame (Y up: Blender's (x, y, z) is keyframe's (x, z, -y)) beside the mesh as OBJ,
# so the same file runs from the shell or on the farm.
bl_info = {
    "name": "keyframe cloth",
    "author": "keyframe",
    "version": (1, 0, 0),
    "blender": (3, 4, 0),
    "location": "Properties > Physics > keyframe",
    "description": "Keyframed cloth through keyframe's adjoint optimiser, played back by the Mesh Cache modifier",
    "category": "Physics",
}

import json
import os
import queue
import re
import shutil
import signal
import struct
import subprocess
import threading

import bpy
from mathutils import Matrix, Vector

# keyframe's exit codes (README, "Exit codes").
EXIT_OK, EXIT_INPUT, EXIT_INTERRUPTED, EXIT_NOT_REACHED = 0, 3, 6, 7
EVALUATION_LINE = re.compile(r"eval\s+(\d+)\s+phi\s+(\S+)")


def to_keyframe(p):
    return [float(p[0]), float(p[2]), float(-p[1])]


def unit(a):
    n = sum(x * x for x in a) ** 0.5
    return [x / n for x in a]


def from_keyframe(q):
    return Vector((q[0], -q[2], q[1]))


class ShotError(Exception):
    """A shot that cannot be written: the message names the object and what to change."""


# ---------------------------------------------------------------- properties

class KeyframeTarget(bpy.types.PropertyGroup):
    group: bpy.props.StringProperty(name="Vertex group", description="The keyframed vertices")
    empty: bpy.props.PointerProperty(name="Empty", type=bpy.types.Object,
                                     poll=lambda self, o: o.type == 'EMPTY',
                                     description="Its location at the frame is the target")
    frame: bpy.props.IntProperty(name="Frame", default=0, min=0,
                                 description="The keyframe's frame; 0: every frame the Empty's location is keyed at")
    mode: bpy.props.EnumProperty(name="Mode", default='CENTER', items=[
        ('CENTER', "Centre of mass", "The group's centre of mass goes to the Empty"),
        ('RIGID', "Rigid", "Every vertex goes where the Empty carries it from the first frame (location and rotation)")])


class KeyframeObject(bpy.types.PropertyGroup):
    role: bpy.props.EnumProperty(name="Role", default='NONE', items=[
        ('NONE', "None", "Not part of the shot"),
        ('CLOTH', "Cloth", "This mesh is the cloth"),
        ('COLLIDER', "Collider", "The cloth is pushed out of this object"),
        ('FLOCK', "Flock", "A flock of agents starts around this object (instead of a cloth)"),
        ('SHAPE', "Flock shape", "A closed curve the flock fills at a frame")])
    mass: bpy.props.FloatProperty(name="Mass", default=0.5, min=1e-6, unit='MASS', description="Total, kg")
    stretch: bpy.props.FloatProperty(name="Stretch", default=500, min=0, description="N/m")
    shear: bpy.props.FloatProperty(name="Shear", default=50, min=0, description="N/m")
    bend: bpy.props.FloatProperty(name="Bend", default=5, min=0, description="N/m")
    damping: bpy.props.FloatProperty(name="Damping", default=0.05, min=0, description="Spring damping, N·s/m")
    pin_group: bpy.props.StringProperty(name="Pins", description="Vertex group held in place")
    targets: bpy.props.CollectionProperty(type=KeyframeTarget)
    shape: bpy.props.EnumProperty(name="Shape", default='AUTO', items=[
        ('AUTO', "Detect", "From the mesh's name: Sphere, Cylinder, Cube, Plane, Torus"),
        ('SPHERE', "Sphere", ""), ('CAPSULE', "Capsule", "A cylinder with round ends"),
        ('BOX', "Box", "A cube or cuboid, along the object's axes"),
        ('PLANE', "Plane", "The infinite plane, free side along the object's Z"), ('TORUS', "Torus", "")])
    friction: bpy.props.FloatProperty(name="Friction", default=0, min=0, max=10)
    agents: bpy.props.IntProperty(name="Agents", default=100, min=1, max=1000000)
    spawn_radius: bpy.props.FloatProperty(name="Spawn radius", default=8, min=0.01, unit='LENGTH',
                                          description="The agents start in a disc of this radius on the ground")
    frame: bpy.props.IntProperty(name="Frame", default=0, min=0, description="The frame the flock fills this shape")
    coverage: bpy.props.FloatProperty(name="Coverage", default=0.3, min=0,
                                      description="Weight of filling every part of the shape (0: only inside)")


class KeyframeScene(bpy.types.PropertyGroup):
    binary: bpy.props.StringProperty(name="keyframe", subtype='FILE_PATH',
                                     description="The keyframe program (empty: $KEYFRAME_BINARY, then PATH)")
    directory: bpy.props.StringProperty(name="Directory", default="//keyframe", subtype='DIR_PATH',
                                        description="Where the scene, its mesh and the run are written")
    max_evaluations: bpy.props.IntProperty(name="Evaluations", default=300, min=1, max=100000)
    stop_when_reached: bpy.props.BoolProperty(name="Stop when reached", default=True)
    status: bpy.props.StringProperty(name="Status")
    exit_code: bpy.props.IntProperty(default=-1)


# ---------------------------------------------------------------- the scene file

def safe_name(name):
    return re.sub(r"[^A-Za-z0-9_.-]", "_", name) or "shot"


def group_indices(obj, name, what):
    group = obj.vertex_groups.get(name)
    if group is None:
        raise ShotError(f"{obj.name}: {what}: no vertex group named \"{name}\"")
    out = [v.index for v in obj.data.vertices if any(g.group == group.index and g.weight > 0 for g in v.groups)]
    if not out:
        raise ShotError(f"{obj.name}: {what}: vertex group \"{name}\" has no vertices")
    return out


def write_obj(path, obj):
    """The mesh in world space, Blender's axes; vertex i is Blender's vertex i (every vertex must be in a face:
    keyframe leaves out the others, which would shift the indices)."""
    mesh = obj.data
    used = set()
    for poly in mesh.polygons:
        used.update(poly.vertices)
    if len(used) != len(mesh.vertices):
        raise ShotError(f"{obj.name}: {len(mesh.vertices) - len(used)} vertices in no face (delete loose vertices)")
    lines = [f"o {safe_name(obj.name)}"]
    m = obj.matrix_world
    for v in mesh.vertices:
        p = m @ v.co
        lines.append(f"v {p.x:.9g} {p.y:.9g} {p.z:.9g}")
    for poly in mesh.polygons:
        lines.append("f " + " ".join(str(i + 1) for i in poly.vertices))
    write_whole(path, "\n".join(lines) + "\n")


def write_whole(path, text):
    tmp = path + ".tmp"
    with open(tmp, "w") as f:
        f.write(text)
    os.replace(tmp, path)


def world_center(obj):
    corners = [obj.matrix_world @ Vector(c) for c in obj.bound_box]
    return sum(corners, Vector()) / 8


def collider_spec(obj):
    s = obj.keyframe
    shape = s.shape
    if shape == 'AUTO':
        name = (obj.data.name if obj.data else obj.name).lower()
        for prefix, kind in (("sphere", 'SPHERE'), ("icosphere", 'SPHERE'), ("cylinder", 'CAPSULE'),
                             ("cube", 'BOX'), ("plane", 'PLANE'), ("grid", 'PLANE'), ("torus", 'TORUS')):
            if name.startswith(prefix):
                shape = kind
                break
        else:
            raise ShotError(f"{obj.name}: collider shape not detected from its name "
                            "(choose Sphere, Capsule, Box, Plane or Torus)")
    d = obj.dimensions
    m3 = obj.matrix_world.to_3x3()
    axis = (m3 @ Vector((0, 0, 1))).normalized()
    c = world_center(obj)
    if shape == 'SPHERE':
        spec = {"type": "sphere", "center": to_keyframe(c), "radius": max(d) / 2}
    elif shape == 'CAPSULE':
        radius = max(d.x, d.y) / 2
        half = max(d.z / 2 - radius, 1e-3)
        spec = {"type": "capsule", "a": to_keyframe(c - half * axis), "b": to_keyframe(c + half * axis), "radius": radius}
    elif shape == 'BOX':
        # Its local X and Y as keyframe's u_axis and v_axis, made perpendicular in double precision (Blender's
        # vectors are single; keyframe refuses axes off by more than 1e-6); the third size is along X x Y, its Z.
        u = unit([float(a) for a in m3 @ Vector((1, 0, 0))])
        v = [float(a) for a in m3 @ Vector((0, 1, 0))]
        dot = sum(a * b for a, b in zip(u, v))
        v = unit([b - dot * a for a, b in zip(u, v)])
        spec = {"type": "box", "center": to_keyframe(c), "size": [float(d.x), float(d.y), float(d.z)],
                "u_axis": to_keyframe(u), "v_axis": to_keyframe(v)}
    elif shape == 'PLANE':
        spec = {"type": "ground", "center": to_keyframe(obj.matrix_world.translation), "axis": to_keyframe(axis)}
    else:
        tube = d.z / 2
        spec = {"type": "torus", "center": to_keyframe(c), "axis": to_keyframe(axis),
                "radius": max(d.x, d.y) / 2 - tube, "tube_radius": tube}
    if s.friction > 0:
        spec["friction"] = s.friction
    return spec


def keyed_frames(empty):
    frames = set()
    action = empty.animation_data.action if empty.animation_data else None
    for fc in (action.fcurves if action else []):
        if fc.data_path in ("location", "rotation_euler", "rotation_quaternion", "scale"):
            frames.update(int(round(k.co.x)) for k in fc.keyframe_points)
    return sorted(frames)


def objectives(scene, cloth):
    start, end = scene.frame_start, scene.frame_end
    rest = [cloth.matrix_world @ v.co for v in cloth.data.vertices]
    out = []
    for k, t in enumerate(cloth.keyframe.targets):
        what = f"keyframe {k + 1}"
        if t.empty is None:
            raise ShotError(f"{cloth.name}: {what}: no Empty chosen")
        particles = group_indices(cloth, t.group, what)
        frames = [t.frame] if t.frame > 0 else [f for f in keyed_frames(t.empty) if f > start]
        if not frames:
            raise ShotError(f"{cloth.name}: {what}: {t.empty.name} has no keyed frame after {start} (or set a frame)")
        scene.frame_set(start)
        first = t.empty.matrix_world.copy()
        for f in frames:
            if not start < f <= end:
                raise ShotError(f"{cloth.name}: {what}: frame {f} outside the scene's frames {start + 1}..{end}")
            scene.frame_set(f)
            m = t.empty.matrix_world.copy()
            term = {"frame": f - start, "particles": particles}
            if t.mode == 'CENTER':
                term.update(type="center_of_mass", target=to_keyframe(m.translation))
            else:
                carry = m @ first.inverted()
                term.update(type="position", targets=[to_keyframe(carry @ rest[i]) for i in particles])
            out.append(term)
    scene.frame_set(start)
    return out


def shot_objects(scene):
    cloths = [o for o in scene.objects if o.keyframe.role == 'CLOTH']
    if len(cloths) != 1:
        raise ShotError(f"expected one object marked as keyframe cloth, found {len(cloths)}")
    cloth = cloths[0]
    if cloth.type != 'MESH':
        raise ShotError(f"{cloth.name}: the cloth must be a mesh")
    colliders = [o for o in scene.objects if o.keyframe.role == 'COLLIDER']
    return cloth, colliders


def shot_directory(scene):
    d = scene.keyframe.directory or "//keyframe"
    if d.startswith("//") and not bpy.data.filepath:
        d = os.path.join(bpy.app.tempdir, d[2:])
    return os.path.abspath(bpy.path.abspath(d))


def shape_term(scene, obj):
    """A Flock shape curve as a shape keyframe: its points flattened to the ground, keyframe's [x, z]."""
    what = f"{obj.name}: flock shape"
    if obj.type != 'CURVE' or len(obj.data.splines) != 1 or not obj.data.splines[0].use_cyclic_u:
        raise ShotError(f"{what}: expected a closed curve of one spline")
    f = obj.keyframe.frame
    if not scene.frame_start < f <= scene.frame_end:
        raise ShotError(f"{what}: frame {f} outside the scene's frames {scene.frame_start + 1}..{scene.frame_end}")
    evaluated = obj.evaluated_get(bpy.context.evaluated_depsgraph_get())
    mesh = evaluated.to_mesh()
    points = [obj.matrix_world @ v.co for v in mesh.vertices]
    evaluated.to_mesh_clear()
    if len(points) < 3:
        raise ShotError(f"{what}: fewer than 3 points")
    term = {"type": "shape", "frame": f - scene.frame_start, "polygon": [[p.x, -p.y] for p in points]}
    if obj.keyframe.coverage > 0:
        term["coverage"] = {"weight": obj.keyframe.coverage}
    return term


def write_flock_scene(scene, flock, header):
    """Writes DIRECTORY/NAME.json for a flock; returns the scene's path and the flock object."""
    if any(o.keyframe.role in ('CLOTH', 'COLLIDER') for o in scene.objects):
        raise ShotError(f"{flock.name}: a shot is a flock or a cloth (unmark the cloth and its colliders)")
    terms = [shape_term(scene, o) for o in scene.objects if o.keyframe.role == 'SHAPE']
    if not terms:
        raise ShotError(f"{flock.name}: no flock shape (mark a closed curve as Flock shape and give it a frame)")
    c = to_keyframe(flock.matrix_world.translation)
    s = flock.keyframe
    shot = dict(header, flock={"agents": s.agents, "spawn": {"center": [c[0], 0, c[2]], "radius": s.spawn_radius}},
                objectives=terms)
    path = os.path.join(shot_directory(scene), safe_name(flock.name) + ".json")
    os.makedirs(os.path.dirname(path), exist_ok=True)
    write_whole(path, json.dumps(shot, indent=1) + "\n")
    return path, flock


def shot_header(scene):
    frames = scene.frame_end - scene.frame_start
    if frames < 1:
        raise ShotError("the scene needs at least two frames")
    fps, ks = scene.render.fps / scene.render.fps_base, scene.keyframe
    return {"time": {"fps": int(fps) if float(fps).is_integer() else fps, "frames": frames},
            "controls": {"kind": "per_frame"},
            "optimizer": {"max_evaluations": ks.max_evaluations, "stop_when_reached": ks.stop_when_reached}}


def write_scene(scene):
    """Writes DIRECTORY/NAME.json and NAME.obj; returns the scene's path and the object played back (the cloth,
    or the flock's)."""
    header = shot_header(scene)
    flocks = [o for o in scene.objects if o.keyframe.role == 'FLOCK']
    if len(flocks) > 1:
        raise ShotError(f"expected at most one object marked as flock, found {len(flocks)}")
    if flocks:
        return write_flock_scene(scene, flocks[0], header)
    cloth, colliders = shot_objects(scene)
    s = cloth.keyframe
    name = safe_name(cloth.name)
    directory = shot_directory(scene)
    os.makedirs(directory, exist_ok=True)
    write_obj(os.path.join(directory, name + ".obj"), cloth)
    block = {"mesh": {"file": name + ".obj", "up_axis": "z"},
             "mass": s.mass, "stretch": s.stretch, "shear": s.shear, "bend": s.bend, "damping": s.damping}
    if s.pin_group:
        block["pins"] = group_indices(cloth, s.pin_group, "pins")
    if scene.use_gravity:
        block["gravity"] = to_keyframe(scene.gravity)
    if colliders:
        block["colliders"] = [collider_spec(o) for o in colliders]
    terms = objectives(scene, cloth)
    if not terms:
        raise ShotError(f"{cloth.name}: no keyframe (add one: a vertex group and an Empty)")
    shot = dict(header, cloth=block, objectives=terms)
    path = os.path.join(directory, name + ".json")
    write_whole(path, json.dumps(shot, indent=1) + "\n")
    return path, cloth


# ---------------------------------------------------------------- running keyframe

def keyframe_binary(scene):
    b = bpy.path.abspath(scene.keyframe.binary) if scene.keyframe.binary else os.environ.get("KEYFRAME_BINARY", "")
    b = b or shutil.which("keyframe") or ""
    if not b or not os.access(b, os.X_OK):
        raise ShotError("the keyframe program was not found (set its path in the panel, or put it on PATH)")
    return b


class Solve:
    """One `keyframe optimize` in the background: its lines arrive on a queue, the last progress is kept."""

    def __init__(self, binary, scene_path, cloth_name):
        self.binary, self.scene_path, self.cloth_name = binary, scene_path, cloth_name
        self.run_dir = os.path.splitext(scene_path)[0] + "-run"
        self.lines, self.errors = queue.Queue(), []
        self.progress = "starting"
        self.proc = subprocess.Popen([binary, "optimize", scene_path, "--out", self.run_dir],
                                     stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
        self.readers = [threading.Thread(target=self._read, args=(self.proc.stdout, self.lines.put), daemon=True),
                        threading.Thread(target=self._read, args=(self.proc.stderr, self.errors.append), daemon=True)]
        for r in self.readers:
            r.start()

    @staticmethod
    def _read(stream, put):
        for line in stream:
            put(line.rstrip("\n"))

    def poll(self):
        """Takes the lines read so far; the exit code once the program has ended, else None."""
        while not self.lines.empty():
            m = EVALUATION_LINE.search(self.lines.get())
            if m:
                self.progress = f"evaluation {m.group(1)}, objective {float(m.group(2)):.4g}"
        return self.proc.poll()

    def wait(self):
        """Blocks until the program ends and its output is read; its exit code."""
        code = self.proc.wait()
        for r in self.readers:
            r.join()
        self.poll()
        return code

    def cancel(self):
        if self.proc.poll() is None:
            self.proc.send_signal(signal.SIGINT)  # keyframe saves the best controls so far and exits 6

    def error_line(self):
        return next((e for e in reversed(self.errors) if e.strip()), "")


def diagnosis(run_dir):
    try:
        with open(os.path.join(run_dir, "report.json")) as f:
            d = json.load(f).get("diagnosis", {})
        return d.get("diagnosis", "") if isinstance(d, dict) else str(d)
    except (OSError, ValueError):
        return ""


def read_pc2(path):
    with open(path, "rb") as f:
        head = f.read(32)
        if len(head) != 32 or head[:12] != b"POINTCACHE2\0":
            raise ShotError(f"{path}: not a PC2 point cache")
        _, points, start, rate, samples = struct.unpack("<iiffi", head[12:])
        data = f.read()
    if len(data) != points * samples * 12:
        raise ShotError(f"{path}: truncated")
    return points, start, rate, samples, data


def agents_object(run_dir, flock):
    """The flock's agents as a mesh object "FLOCK agents" (replaced on every solve) from the export's rest OBJ,
    in Blender's axes, at the world origin."""
    vertices, faces = [], []
    with open(os.path.join(run_dir, "export", "agents.obj")) as f:
        for line in f:
            w = line.split()
            if w and w[0] == "v":
                vertices.append(from_keyframe([float(a) for a in w[1:4]]))
            elif w and w[0] == "f":
                faces.append([int(a.split("/")[0]) - 1 for a in w[1:]])
    name = flock.name + " agents"
    old = bpy.data.objects.get(name)
    if old is not None:
        bpy.data.objects.remove(old)
    mesh = bpy.data.meshes.new(name)
    mesh.from_pydata(vertices, [], faces)
    obj = bpy.data.objects.new(name, mesh)
    bpy.context.scene.collection.objects.link(obj)
    return obj


def play_back(binary, run_dir, cloth):
    """Exports the run as PC2, rewrites it in the object's own space and axes and plays it through a Mesh Cache
    modifier named "keyframe" from the scene's first frame (a flock's on its agents object)."""
    r = subprocess.run([binary, "export", run_dir, "--format", "pc2"], capture_output=True, text=True)
    if r.returncode != 0:
        raise ShotError("keyframe export: " + (r.stderr.strip().splitlines() or ["failed"])[-1])
    system = "cloth"
    if cloth.keyframe.role == 'FLOCK':
        cloth, system = agents_object(run_dir, cloth), "agents"
    points, start, rate, samples, data = read_pc2(os.path.join(run_dir, "export", system + ".pc2"))
    if points != len(cloth.data.vertices):
        raise ShotError(f"{cloth.name}: the run has {points} particles, the mesh {len(cloth.data.vertices)} vertices")
    to_local = cloth.matrix_world.inverted()
    out = bytearray(b"POINTCACHE2\0" + struct.pack("<iiffi", 1, points, start, rate, samples))
    values = struct.unpack(f"<{points * samples * 3}f", data)
    for k in range(0, len(values), 3):
        out += struct.pack("<3f", *(to_local @ from_keyframe(values[k:k + 3])))
    path = os.path.join(run_dir, "export", safe_name(cloth.name) + ".blender.pc2")
    with open(path + ".tmp", "wb") as f:
        f.write(out)
    os.replace(path + ".tmp", path)
    mod = cloth.modifiers.get("keyframe") or cloth.modifiers.new("keyframe", 'MESH_CACHE')
    mod.cache_format = 'PC2'
    mod.filepath = path
    mod.play_mode = 'SCENE'
    mod.time_mode = 'FRAME'
    mod.frame_start = bpy.context.scene.frame_start
    mod.frame_scale = 1.0
    mod.forward_axis, mod.up_axis = 'POS_Y', 'POS_Z'


def finish(scene, solve, code, cloth):
    """Plays back what the run wrote and says how it ended: (report level, message)."""
    ks = scene.keyframe
    ks.exit_code = code
    if code in (EXIT_OK, EXIT_NOT_REACHED, EXIT_INTERRUPTED):
        play_back(solve.binary, solve.run_dir, cloth)
    if code == EXIT_OK:
        level, text = 'INFO', f"keyframes reached ({solve.progress}); run: {solve.run_dir}"
    elif code == EXIT_NOT_REACHED:
        level, text = 'WARNING', diagnosis(solve.run_dir) or solve.error_line()
    elif code == EXIT_INTERRUPTED:
        level, text = 'WARNING', f"cancelled: the best controls so far are played back ({solve.progress})"
    else:
        level, text = 'ERROR', f"keyframe exited {code}: {solve.error_line()}"
    ks.status = text
    return level, text


# ---------------------------------------------------------------- operators

_running = {}  # the solve in progress, at most one


class KEYFRAME_OT_write_scene(bpy.types.Operator):
    bl_idname = "keyframe.write_scene"
    bl_label = "Write scene"
    bl_description = "Write the scene file and its mesh, to run from the shell or on the farm"

    def execute(self, context):
        try:
            path, _ = write_scene(context.scene)
        except ShotError as e:
            self.report({'ERROR'}, str(e))
            return {'CANCELLED'}
        context.scene.keyframe.status = "written: " + path
        self.report({'INFO'}, "written: " + path)
        return {'FINISHED'}


class KEYFRAME_OT_solve(bpy.types.Operator):
    bl_idname = "keyframe.solve"
    bl_label = "Solve"
    bl_description = "Write the scene, run keyframe optimize in the background and play the result back (Esc cancels)"
    wait: bpy.props.BoolProperty(default=False, options={'SKIP_SAVE'},
                                 description="Block until keyframe ends (scripts, background Blender)")

    _timer = None

    def execute(self, context):
        if _running:
            self.report({'ERROR'}, "a solve is already running")
            return {'CANCELLED'}
        try:
            path, cloth = write_scene(context.scene)
            solve = Solve(keyframe_binary(context.scene), path, cloth.name)
        except ShotError as e:
            context.scene.keyframe.status = str(e)
            self.report({'ERROR'}, str(e))
            return {'CANCELLED'}
        _running["solve"] = solve
        if self.wait or bpy.app.background:
            return self._end(context, solve, solve.wait())
        context.window_manager.modal_handler_add(self)
        self._timer = context.window_manager.event_timer_add(0.25, window=context.window)
        return {'RUNNING_MODAL'}

    def modal(self, context, event):
        solve = _running.get("solve")
        if event.type == 'ESC':
            solve.cancel()
        if event.type != 'TIMER':
            return {'PASS_THROUGH'}
        code = solve.poll()
        context.workspace.status_text_set(f"keyframe: {solve.progress} (Esc cancels)")
        if code is None:
            return {'PASS_THROUGH'}
        context.window_manager.event_timer_remove(self._timer)
        context.workspace.status_text_set(None)
        return self._end(context, solve, code)

    def _end(self, context, solve, code):
        _running.clear()
        cloth = bpy.data.objects.get(solve.cloth_name)
        try:
            level, text = finish(context.scene, solve, code, cloth)
        except ShotError as e:
            level, text = 'ERROR', str(e)
            context.scene.keyframe.status = text
        self.report({level}, text)
        return {'FINISHED'} if code == EXIT_OK else {'CANCELLED'}


class KEYFRAME_OT_cancel(bpy.types.Operator):
    bl_idname = "keyframe.cancel"
    bl_label = "Cancel"
    bl_description = "Stop the running solve; the best controls so far are kept and played back"

    def execute(self, context):
        solve = _running.get("solve")
        if solve:
            solve.cancel()
        return {'FINISHED'}


class KEYFRAME_OT_target_add(bpy.types.Operator):
    bl_idname = "keyframe.target_add"
    bl_label = "Add keyframe"

    def execute(self, context):
        context.object.keyframe.targets.add()
        return {'FINISHED'}


class KEYFRAME_OT_target_remove(bpy.types.Operator):
    bl_idname = "keyframe.target_remove"
    bl_label = "Remove keyframe"
    index: bpy.props.IntProperty()

    def execute(self, context):
        context.object.keyframe.targets.remove(self.index)
        return {'FINISHED'}


class KEYFRAME_PT_panel(bpy.types.Panel):
    bl_label = "keyframe"
    bl_space_type = 'PROPERTIES'
    bl_region_type = 'WINDOW'
    bl_context = "physics"

    def draw(self, context):
        layout, obj, ks = self.layout, context.object, context.scene.keyframe
        if obj is not None:
            s = obj.keyframe
            layout.prop(s, "role")
            if s.role == 'CLOTH':
                col = layout.column(align=True)
                for p in ("mass", "stretch", "shear", "bend", "damping"):
                    col.prop(s, p)
                layout.prop_search(s, "pin_group", obj, "vertex_groups")
                for k, t in enumerate(s.targets):
                    box = layout.box()
                    row = box.row()
                    row.prop_search(t, "group", obj, "vertex_groups")
                    row.operator("keyframe.target_remove", text="", icon='X').index = k
                    box.prop(t, "empty")
                    row = box.row()
                    row.prop(t, "frame")
                    row.prop(t, "mode", text="")
                layout.operator("keyframe.target_add", icon='ADD')
            elif s.role == 'COLLIDER':
                layout.prop(s, "shape")
                layout.prop(s, "friction")
            elif s.role == 'FLOCK':
                layout.prop(s, "agents")
                layout.prop(s, "spawn_radius")
            elif s.role == 'SHAPE':
                layout.prop(s, "frame")
                layout.prop(s, "coverage")
        col = layout.column()
        col.prop(ks, "binary")
        col.prop(ks, "directory")
        row = col.row()
        row.prop(ks, "max_evaluations")
        row.prop(ks, "stop_when_reached")
        row = layout.row()
        row.operator("keyframe.solve", icon='PLAY')
        row.operator("keyframe.write_scene", icon='FILE_TICK')
        if _running:
            layout.operator("keyframe.cancel", icon='CANCEL')
        if ks.status:
            layout.label(text=ks.status)


classes = (KeyframeTarget, KeyframeObject, KeyframeScene, KEYFRAME_OT_write_scene, KEYFRAME_OT_solve,
           KEYFRAME_OT_cancel, KEYFRAME_OT_target_add, KEYFRAME_OT_target_remove, KEYFRAME_PT_panel)


def register():
    for c in classes:
        bpy.utils.register_class(c)
    bpy.types.Object.keyframe = bpy.props.PointerProperty(type=KeyframeObject)
    bpy.types.Scene.keyframe = bpy.props.PointerProperty(type=KeyframeScene)


def unregister():
    del bpy.types.Scene.keyframe
    del bpy.types.Object.keyframe
    for c in reversed(classes):
        bpy.utils.unregister_class(c)


if __name__ == "__main__":
    register()
