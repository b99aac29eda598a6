#!/usr/bin/env bash
# Checks that Blender imports our glTF export (.glb) as the same motion the engine shows:
# writes the motion as .glb and as joints JSON, imports the .glb with Blender's own glTF
# importer once per bone heuristic (TEMPERANCE, BLENDER, FORTUNE: they turn the bones, not
# their heads) and compares every bone head, every frame, with the joints (fails beyond
# 1 mm); also checks the body mesh came in skinned on the 22 bones. Needs Blender:
# apt-get install blender.
#
#   scripts/blender_gltf_check.sh motion.npy|.bvh      # any motion file `coma convert` reads
#   scripts/blender_gltf_check.sh generate "a person waves the left hand" --seed 2 --seconds 5
#   scripts/blender_gltf_check.sh run "A person squats twice" --seed 1   # key postures
#   scripts/blender_gltf_check.sh run "a person walks forward then waves the right hand" --seed 1
#
# With a command (any `coma` command that writes its motion with `--out FILE`), the engine's
# motion is written with `--out m.npy` (HumanML3D features, as `coma generate`/`coma run`
# export them) and both files are converted from it. MIXAMO=1 writes Mixamo's joint names
# (`coma convert --mixamo`). COMA=path runs another build of coma.
set -euo pipefail
cd "$(dirname "$0")/.."
if [ -n "${COMA:-}" ]; then
    coma() { "$COMA" "$@"; }
else
    coma() { cargo run --release -q -p coma -- "$@"; }
fi
if [ $# -eq 0 ]; then
    sed -n '2,17p' "$0" >&2
    exit 2
fi
tmp="$(mktemp -d)"
trap 'rm -rf "$tmp"' EXIT
if [ -f "$1" ]; then
    motion="$1"
else
    motion="$tmp/m.npy"
    coma "$@" --out "$motion" >"$tmp/log" 2>&1 || { cat "$tmp/log" >&2; exit 1; }
fi
mixamo=()
if [ "${MIXAMO:-0}" = 1 ]; then
    mixamo=(--mixamo)
fi
coma convert "$motion" "$tmp/m.glb" "${mixamo[@]}" >/dev/null
coma convert "$motion" "$tmp/m.json" >/dev/null
blender -b --factory-startup --python scripts/blender_gltf_check.py -- "$tmp/m.glb" "$tmp/m.json" 2>&1 |
    grep -E "blender gltf import|mesh|differ|Error"
