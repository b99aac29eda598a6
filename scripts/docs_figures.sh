#!/usr/bin/env bash
# Remakes the figures under docs/ from the default model in static/models: the filmstrips of
# the model issue's four prompts, of dataset v2's actions and of the agents' acceptance prompt
# (built-in planner, no LLM), each from a fixed seed so anyone gets the same pictures.
set -euo pipefail
cd "$(dirname "$0")/.."
# COMA names an already built binary; by default cargo builds and runs it.
if [ -n "${COMA:-}" ]; then coma=("$COMA"); else coma=(cargo run --release -q -p coma --); fi
out=docs/generated
mkdir -p "$out"
for prompt in "a person walks forward" "a person waves the left hand" \
  "a person raises the right hand" "a person bows"; do
  name="${prompt// /-}"
  "${coma[@]}" generate "$prompt" --seconds 6 --seed 1 --png "$out/$name.png"
done
# Dataset v2's actions, with the action probes' prompts and lengths (the median length of the
# training motions that show each action: `coma probe squat|jump|lie-down|kick|throw`).
for spec in "a person does a squat:1.4" "a person jumps with both feet:2.4" \
  "a person lies down on the floor:5.8" "a person kicks forward:1.8" "a person throws a ball:3"; do
  prompt="${spec%:*}"
  name="${prompt// /-}"
  "${coma[@]}" generate "$prompt" --seconds "${spec##*:}" --seed 1 --png "$out/$name.png"
done
"${coma[@]}" run "A person walks forward waving the left hand, then turns right and bows" \
  --seed 0 --png "$out/walk-wave-turn-bow.png" --json > "$out/walk-wave-turn-bow.json"
echo "figures in $out"
