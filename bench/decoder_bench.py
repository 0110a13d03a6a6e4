"""Decoder throughput against a plain ``str.split`` tokenizer of the same file.

``python -m bench.decoder_bench [--lines N] [--runs R]``

The program is generated (``generate_program``): a realistic CAM-like mix of
N-numbered G1 lines with X/Y/Z/F, G2/G3 arcs with I/J whose end points lie on their
circles, rapid moves, ``;`` comments (whole-line and trailing), a few technology lines
(S, M3, T) and M30 at the end. Each run times the reference tokenizer and then the
decoder on the same text (paired runs: the drift of a noisy machine hits both); the
figures are medians over the runs and the ratio is the median of the per-run ratios.
Target: decoder lines/s >= 0.5 x tokenizer lines/s.
"""

from __future__ import annotations

import argparse
import gc
import math
import random
import statistics
import sys
import time

from cnc_objects.service.kernel.nc import Decoder

AXES = ("X", "Y", "Z")


def generate_program(lines: int = 200_000) -> str:
    """A valid program of ``lines`` lines that ends with M30."""
    rng = random.Random(42)
    out = ["%BENCH", "; generated program for the decoder benchmark",
           "N1 G17 G90 G40", "N2 T1 M6", "N3 S12000 M3", "N4 G0 X0 Y0 Z5",
           "N5 G1 Z-1 F500"]
    x = y = 0.0
    n = 6
    while len(out) < lines - 2:
        r = rng.random()
        n += 1
        if r < 0.55:
            x = round(x + rng.uniform(-5, 5), 3)
            y = round(y + rng.uniform(-5, 5), 3)
            z = round(rng.uniform(-2, 0), 3)
            feed = rng.choice((800, 1200, 1500, 2000))
            tail = " ; cut" if rng.random() < 0.1 else ""
            out.append(f"N{n} G1 X{x:.3f} Y{y:.3f} Z{z:.3f} F{feed}{tail}")
        elif r < 0.85:
            # an arc whose end point lies on its circle: centre at a random offset
            i = round(rng.uniform(-8, 8), 3) or 1.0
            j = round(rng.uniform(-8, 8), 3) or 1.0
            cx, cy = x + i, y + j
            radius = math.hypot(i, j)
            angle = math.atan2(y - cy, x - cx) + rng.uniform(0.2, 2.5)
            ex = round(cx + radius * math.cos(angle), 3)
            ey = round(cy + radius * math.sin(angle), 3)
            g = rng.choice((2, 3))
            out.append(f"N{n} G{g} X{ex:.3f} Y{ey:.3f} I{i:.3f} J{j:.3f}")
            x, y = ex, ey
        elif r < 0.93:
            x = round(rng.uniform(-50, 50), 3)
            y = round(rng.uniform(-50, 50), 3)
            out.append(f"N{n} G0 X{x:.3f} Y{y:.3f}")
        elif r < 0.99:
            out.append(f"; contour {n}")
        else:
            out.append(f"N{n} S{rng.choice((8000, 10000, 12000))} M3")
    out.append(f"N{n + 1} M5")
    out.append(f"N{n + 2} M30")
    return "\n".join(out) + "\n"


def split_tokenizer(text: str) -> int:
    """The reference: per line strip the ';' comment, split, float() each word's value."""
    count = 0
    for line in text.split("\n"):
        code = line.partition(";")[0]
        words = {}
        for word in code.split():
            try:
                words[word[0]] = float(word[1:])
            except ValueError:  # "%BENCH": not a word with a number
                words[word[0]] = 0.0
        count += 1
    return count


def _no_files(name: str) -> str:
    raise KeyError(name)


def decode_all(text: str) -> int:
    """Decode ``text`` completely; the number of blocks."""
    decoder = Decoder(text, "bench.nc", axes=AXES, loader=_no_files, tools={1: 3.0})
    count = 0
    for _ in decoder.blocks():
        count += 1
    return count


def _timed(fn, text: str) -> float:
    gc.collect()
    start = time.perf_counter()
    fn(text)
    return time.perf_counter() - start


def measure(lines: int = 200_000, runs: int = 5) -> dict:
    """Paired runs; medians of lines/s and of the per-run ratio decoder/tokenizer."""
    text = generate_program(lines)
    count = text.count("\n")
    decode_all(text)  # warm up (imports, regex compilation)
    split_rates, decode_rates, ratios = [], [], []
    for _ in range(runs):
        split_s = _timed(split_tokenizer, text)
        decode_s = _timed(decode_all, text)
        split_rates.append(count / split_s)
        decode_rates.append(count / decode_s)
        ratios.append(split_s / decode_s)
    return {
        "lines": count,
        "decoder_lines_s": statistics.median(decode_rates),
        "split_lines_s": statistics.median(split_rates),
        "ratio": statistics.median(ratios),
    }


def main(argv: list[str] | None = None) -> int:
    """Print the figures."""
    parser = argparse.ArgumentParser(prog="python -m bench.decoder_bench")
    parser.add_argument("--lines", type=int, default=200_000)
    parser.add_argument("--runs", type=int, default=5)
    args = parser.parse_args(argv)
    result = measure(args.lines, args.runs)
    verdict = "met" if result["ratio"] >= 0.5 else "NOT met"
    print(f"program: {result['lines']} lines; median of {args.runs} paired runs")
    print(f"split tokenizer: {result['split_lines_s']:12,.0f} lines/s")
    print(f"decoder        : {result['decoder_lines_s']:12,.0f} lines/s")
    print(f"ratio          : {result['ratio']:.2f}  (target >= 0.5: {verdict})")
    return 0


if __name__ == "__main__":
    sys.exit(main())
