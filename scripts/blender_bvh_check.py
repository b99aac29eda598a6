"""Imports a BVH written by `coma convert` into Blender and compares every bone head, every
frame, with the joints JSON of the same motion. Run through scripts/blender_bvh_check.sh.
"""
import bpy, json, math, builtins
# Debian's Blender 3.4 runs on Python 3.11, where the BVH importer's open(..., "rU") fails.
_open = builtins.open
def _compat_open(file, mode="r", *args, **kwargs):
    return _open(file, mode.replace("U", ""), *args, **kwargs)
builtins.open = _compat_open
bpy.ops.wm.read_factory_settings(use_empty=True)
import sys
args = sys.argv[sys.argv.index("--") + 1:]
bpy.ops.import_anim.bvh(filepath=args[0], update_scene_fps=True, update_scene_duration=True)
arm = [o for o in bpy.context.scene.objects if o.type == 'ARMATURE'][0]
ref = json.load(open(args[1]))
names = ref["joint_names"]
scene = bpy.context.scene
worst = 0.0
frames = len(ref["frames"])
for f in range(frames):
    scene.frame_set(scene.frame_start + f)
    for j, name in enumerate(names):
        pb = arm.pose.bones[name]
        p = arm.matrix_world @ pb.head
        # Blender Z-up (x, y, z) back to Y-up (x, z, -y)
        q = (p.x, p.z, -p.y)
        r = ref["frames"][f][j]
        worst = max(worst, math.dist(q, r))
print(f"blender import: frames={frames} bones={len(arm.pose.bones)} fps={scene.render.fps} worst_mm={worst*1000:.3f}")
# How much each bone's length varies over the motion (the JSON is rounded to 0.1 mm): a
# skeleton's bones do not stretch, so anything above a few tenths of a millimetre cannot be
# carried by a BVH.
parents = {b.name: b.parent.name for b in arm.pose.bones if b.parent}
spread, spread_bone = 0.0, ""
for child, parent in parents.items():
    c, p = names.index(child), names.index(parent)
    lengths = [math.dist(f[c], f[p]) for f in ref["frames"]]
    if max(lengths) - min(lengths) > spread:
        spread, spread_bone = max(lengths) - min(lengths), child
print(f"bone lengths: largest spread {spread*1000:.2f} mm ({spread_bone})")
if worst > 1e-3:
    sys.exit(f"bone heads differ from our joints by {worst*1000:.2f} mm")
