"""PyTorch reference for `coma bench`: SPAM's base transformer with random weights, of the sizes
a spam.json gives, running the same generation loop (guided pair, iterative unmasking with the
cosine schedule, sampling the re-masked positions), timed the same way (median of repeats, the
same work each time). Only speed is compared: the weights are random, so the tokens mean
nothing. Run by scripts/speed_reference.sh, which installs torch in its own environment.
"""

import argparse
import json
import math
import statistics
import time

import torch
from torch import nn

PARTS = 4
TEXT_DIM = 384


class Layer(nn.Module):
    """Attention across the 4 parts of a step, across the steps of a part, feed-forward."""

    def __init__(self, w, heads, ff):
        super().__init__()
        self.spatial_norm = nn.LayerNorm(w)
        self.spatial = nn.MultiheadAttention(w, heads, batch_first=True)
        self.temporal_norm = nn.LayerNorm(w)
        self.temporal = nn.MultiheadAttention(w, heads, batch_first=True)
        self.ff_norm = nn.LayerNorm(w)
        self.ff_in = nn.Linear(w, ff)
        self.ff_out = nn.Linear(ff, w)

    def forward(self, x, pad):
        b, s, p, w = x.shape
        h = self.spatial_norm(x).reshape(b * s, p, w)
        h = self.spatial(h, h, h, need_weights=False)[0].reshape(b, s, p, w)
        x = x + h
        h = self.temporal_norm(x).transpose(1, 2).reshape(b * p, s, w)
        h = self.temporal(h, h, h, key_padding_mask=pad, need_weights=False)[0]
        x = x + h.reshape(b, p, s, w).transpose(1, 2)
        return x + self.ff_out(nn.functional.gelu(self.ff_in(self.ff_norm(x))))


class Base(nn.Module):
    """Per-part token tables (tied to the output logits), text adapter, factorised layers."""

    def __init__(self, c):
        super().__init__()
        w, k = c["width"], c["codebook_size"]
        self.k = k
        self.tokens = nn.ModuleList(nn.Embedding(k + 2, w) for _ in range(PARTS))
        self.text_in = nn.Linear(TEXT_DIM, w)
        self.text_out = nn.Linear(w, w)
        self.null_text = nn.Parameter(torch.randn(w) * 0.02)
        self.time = nn.Embedding(c["max_steps"] + 1, w)
        self.part = nn.Embedding(PARTS, w)
        self.layers = nn.ModuleList(
            Layer(w, c["heads"], c["ff_width"]) for _ in range(c["depth"])
        )
        self.final_norm = nn.LayerNorm(w)

    def forward(self, ids, text, keep, pad):
        b, p, n = ids.shape
        x = torch.stack([self.tokens[i](ids[:, i]) for i in range(p)], 1)
        w = x.shape[-1]
        cond = self.text_out(nn.functional.gelu(self.text_in(text)))
        keep = keep.reshape(b, p, 1)
        cond = cond * keep + self.null_text.reshape(1, 1, w) * (1 - keep)
        x = torch.cat([cond.reshape(b, p, 1, w), x], 2)
        x = x + self.time.weight[: n + 1].reshape(1, 1, n + 1, w)
        x = x + self.part.weight.reshape(1, p, 1, w)
        x = x.transpose(1, 2)
        pad = torch.cat([torch.zeros(b, 1, dtype=torch.bool), pad], 1)
        pad = pad.reshape(b, 1, n + 1).expand(b, p, n + 1).reshape(b * p, n + 1)
        for layer in self.layers:
            x = layer(x, pad)
        h = self.final_norm(x).transpose(1, 2)[:, :, 1:] / math.sqrt(w)
        return torch.stack(
            [h[:, i] @ self.tokens[i].weight[: self.k].T for i in range(p)], 1
        )


def flops(c, batch, steps):
    """Multiply-adds ×2 of the matrix products of one pass, counted as coma bench counts them."""
    b, n, w = batch, steps, c["width"]
    grid = b * PARTS * (n + 1)
    text = b * PARTS * (TEXT_DIM * w + w * w) * 2
    attention = lambda length: 4 * grid * w * w * 2 + 2 * grid * length * w * 2
    ff = 2 * grid * w * c["ff_width"] * 2
    layer = attention(PARTS) + attention(n + 1) + ff
    logits = b * PARTS * n * w * c["codebook_size"] * 2
    return text + c["depth"] * layer + logits


@torch.inference_mode()
def generate(model, text, steps, iterations, guidance, generator):
    mask = model.k
    ids = torch.full((PARTS, steps), mask, dtype=torch.long)
    confidence = torch.full((PARTS * steps,), -math.inf)
    texts = text.expand(2, PARTS, TEXT_DIM)
    keep = torch.tensor([[1.0] * PARTS, [0.0] * PARTS])
    pad = torch.zeros(2, steps, dtype=torch.bool)
    flat = ids.view(-1)
    for it in range(iterations):
        still = round(math.cos(it / iterations * math.pi / 2) * flat.numel())
        still = min(max(still, 1), flat.numel())
        remasked = torch.argsort(confidence, stable=True)[:still]
        flat[remasked] = mask
        logits = model(flat.view(1, PARTS, steps).expand(2, PARTS, steps), texts, keep, pad)
        guided = ((1 + guidance) * logits[0] - guidance * logits[1]).reshape(-1, model.k)
        probs = torch.softmax(guided[remasked], -1)
        drawn = torch.multinomial(probs, 1, generator=generator).squeeze(1)
        flat[remasked] = drawn
        confidence[remasked] = probs.gather(1, drawn[:, None]).squeeze(1)
    return flat.view(PARTS, steps)


def main():
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--config", default="static/models/spam.json")
    parser.add_argument("--threads", type=int, default=2)
    parser.add_argument("--repeat", type=int, default=5)
    parser.add_argument("--steps", type=int, default=49, help="time steps (4 frames each)")
    parser.add_argument("--iterations", type=int, default=10)
    parser.add_argument("--guidance", type=float, default=4.0)
    parser.add_argument("--peak", action="store_true", help="also time a large sgemm")
    args = parser.parse_args()
    torch.set_num_threads(args.threads)
    torch.manual_seed(0)
    with open(args.config) as f:
        config = json.load(f)["base"]
    model = Base(config).eval()
    text = torch.randn(1, PARTS, TEXT_DIM)
    generate(model, text, args.steps, args.iterations, args.guidance, torch.Generator().manual_seed(0))
    times = []
    for _ in range(args.repeat):
        start = time.perf_counter()
        generate(model, text, args.steps, args.iterations, args.guidance, torch.Generator().manual_seed(0))
        times.append(time.perf_counter() - start)
    median = statistics.median(times)
    gflop = args.iterations * flops(config, 2, args.steps) / 1e9
    print(
        json.dumps(
            {
                "torch": torch.__version__,
                "threads": torch.get_num_threads(),
                "median_ms": median * 1e3,
                "best_ms": min(times) * 1e3,
                "gflop": gflop,
                "gflops": gflop / median,
            }
        )
    )
    if args.peak:
        a, b = torch.randn(2048, 2048), torch.randn(2048, 2048)
        a @ b
        best = math.inf
        for _ in range(5):
            start = time.perf_counter()
            a @ b
            best = min(best, time.perf_counter() - start)
        print(json.dumps({"sgemm_2048_gflops": 2 * 2048**3 / best / 1e9}))


if __name__ == "__main__":
    main()
