#!/usr/bin/env bash
# Checks that Blender imports our BVH export as the same motion: writes a dataset clip (or the
# given features .npy) as BVH and JSON, imports the BVH with Blender's own importer and compares
# bone heads with our joints (fails beyond 1 mm). Needs Blender: apt-get install blender.
set -euo pipefail
cd "$(dirname "$0")/.."
motion="${1:-data/bandai/new_joint_vecs/bn2_walk_normal_001.npy}"
tmp="$(mktemp -d)"
cargo run --release -q -p coma -- convert "$motion" "$tmp/m.bvh"
cargo run --release -q -p coma -- convert "$motion" "$tmp/m.json"
blender -b --factory-startup --python scripts/blender_bvh_check.py -- "$tmp/m.bvh" "$tmp/m.json" 2>&1 | grep -E "blender import|differ|Error"
