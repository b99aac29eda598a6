"""Imports a .glb written by `coma convert` into Blender with Blender's own glTF importer and
compares every bone head, every frame, with the joints JSON of the same motion, once per bone
heuristic. Run through scripts/blender_gltf_check.sh.
"""
import bpy, json, math, struct, sys
import numpy
# Debian's Blender 3.4 glTF importer still uses `numpy.bool`, which Debian's numpy 1.24 no
# longer has (it was an alias of `bool`).
if "bool" not in numpy.__dict__:
    numpy.bool = bool

args = sys.argv[sys.argv.index("--") + 1:]
glb_path, json_path = args[0], args[1]
ref = json.load(open(json_path))
frames = len(ref["frames"])

# The joint nodes' names in joint order, from the file's own JSON chunk (nodes 0..21 are the
# joints), so Mixamo-named files compare too.
with open(glb_path, "rb") as f:
    data = f.read()
magic, version, length = struct.unpack_from("<III", data, 0)
json_len, json_type = struct.unpack_from("<II", data, 12)
assert magic == 0x46546C67 and version == 2 and length == len(data), "not a GLB 2.0 file"
gltf = json.loads(data[20:20 + json_len])
names = [gltf["nodes"][j]["name"] for j in range(len(ref["joint_names"]))]

failed = []
for heuristic in ("TEMPERANCE", "BLENDER", "FORTUNE"):
    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    # The importer turns key times into frames at the scene's rate: 20 fps puts key t on
    # frame t.
    scene.render.fps = 20
    scene.render.fps_base = 1.0
    bpy.ops.import_scene.gltf(filepath=glb_path, bone_heuristic=heuristic)
    arms = [o for o in scene.objects if o.type == 'ARMATURE']
    meshes = [o for o in scene.objects if o.type == 'MESH']
    arm = arms[0]
    worst, worst_at = 0.0, None
    for f in range(frames):
        scene.frame_set(f)
        for j, name in enumerate(names):
            p = arm.matrix_world @ arm.pose.bones[name].head
            # Blender Z-up (x, y, z) back to glTF's Y-up (x, z, -y)
            q = (p.x, p.z, -p.y)
            r = ref["frames"][f][j]
            d = math.dist(q, r)
            if d > worst:
                worst, worst_at = d, (f, name)
    print(f"blender gltf import ({heuristic}): frames={frames} bones={len(arm.pose.bones)} "
          f"fps={scene.render.fps} worst_mm={worst*1000:.3f} at {worst_at}")
    if worst > 1e-3:
        failed.append(f"{heuristic}: bone heads differ from our joints by {worst*1000:.2f} mm")
    if heuristic == "TEMPERANCE":
        body = meshes[0]
        mods = [m for m in body.modifiers if m.type == 'ARMATURE']
        groups = sorted(g.name for g in body.vertex_groups)
        print(f"mesh: {len(body.data.vertices)} vertices, {len(body.data.polygons)} faces, "
              f"armature modifier={bool(mods) and mods[0].object == arm}, "
              f"vertex groups={len(groups)}")
        if not mods or mods[0].object != arm or groups != sorted(names):
            failed.append("Error: the mesh is not skinned on the 22 bones")
for message in failed:
    print(message)
if failed:
    sys.exit(1)
