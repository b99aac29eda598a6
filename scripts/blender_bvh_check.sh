#!/usr/bin/env bash
# Checks that Blender imports our BVH export as the same motion the engine shows: writes the
# motion as BVH and as joints JSON, imports the BVH with Blender's own importer and compares
# every bone head, every frame, with the joints (fails beyond 1 mm); also prints how much the
# bone lengths vary in the JSON. Needs Blender: apt-get install blender.
#
#   scripts/blender_bvh_check.sh                      # a dataset walk (data/bandai, see README)
#   scripts/blender_bvh_check.sh motion.npy|.bvh      # any motion file `coma convert` reads
#   scripts/blender_bvh_check.sh generate "a person waves the left hand" --seed 2 --seconds 5
#   scripts/blender_bvh_check.sh run "a person walks forward then waves the right hand" --seed 1
#   scripts/blender_bvh_check.sh run "A person squats twice" --seed 1   # key postures
#   scripts/blender_bvh_check.sh /tmp/lib/jumping-jacks--movement-.npy # a library movement
#
# With a command (any `coma` command that writes its motion with `--out FILE`), the engine's
# motion is written with `--out m.npy` (HumanML3D features, as `coma generate`/`coma run`
# export them) and both files are converted from it, so the check covers the features export
# too. Key postures: `run` with a prompt the planner plans with postures, or a file that
# `coma posture motions --out /tmp/lib` wrote (joints of each named posture and movement, as
# the engine returns them). COMA=path runs another build of coma (e.g. an older one, to
# compare).
set -euo pipefail
cd "$(dirname "$0")/.."
if [ -n "${COMA:-}" ]; then
    coma() { "$COMA" "$@"; }
else
    coma() { cargo run --release -q -p coma -- "$@"; }
fi
tmp="$(mktemp -d)"
trap 'rm -rf "$tmp"' EXIT
if [ $# -eq 0 ] || [ -f "$1" ]; then
    motion="${1:-data/bandai/new_joint_vecs/bn2_walk_normal_001.npy}"
    if [ ! -f "$motion" ]; then
        echo "no $motion: build the dataset (coma data build --bandai … --out data/bandai) or name a motion file" >&2
        exit 1
    fi
else
    motion="$tmp/m.npy"
    coma "$@" --out "$motion" >"$tmp/log" 2>&1 || { cat "$tmp/log" >&2; exit 1; }
fi
coma convert "$motion" "$tmp/m.bvh" >/dev/null
coma convert "$motion" "$tmp/m.json" >/dev/null
blender -b --factory-startup --python scripts/blender_bvh_check.py -- "$tmp/m.bvh" "$tmp/m.json" 2>&1 |
    grep -E "blender import|bone lengths|differ|Error"
