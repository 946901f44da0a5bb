#!/usr/bin/env python3
"""Instructions per particle-step of `empm bench`, counted by callgrind (stable on a noisy
machine, unlike wall time).

Two runs of the same case that differ only in the number of timed steps (N1 and N2, after the
same warm-up) are counted; their difference divided by (N2 - N1) * particles removes set-up,
warm-up and output. The per-function split of that difference shows where the instructions go.

Usage: callgrind_count.py EMPM SHAPE   (prints one JSON object)
SHAPE is a shape identifier as in a case file: linear, ..., lme (gamma 3), lme_g<gamma>.
Case: 2D, 32x32 cells, 4 particles per cell (4096 particles), 2 warm-up steps, 1 thread,
N1 = 2 and N2 = 6 timed steps; pc_newmark.
"""
import json
import re
import subprocess
import sys
import tempfile
from pathlib import Path

CELLS, PPC, WARMUP, N1, N2 = 32, 4, 2, 2, 6


def count(empm, shape, steps, outdir):
    out = Path(outdir) / f"cg.{steps}"
    cmd = ["valgrind", "--tool=callgrind", f"--callgrind-out-file={out}", empm, "bench",
           "--dim", "2", "--shape", shape, "--cells", str(CELLS),
           "--ppc", str(PPC), "--warmup", str(WARMUP), "--steps", str(steps), "--threads", "1"]
    run = subprocess.run(cmd, capture_output=True, text=True, check=True)
    bench = json.loads(run.stdout.strip().splitlines()[-1])
    ann = subprocess.run(["callgrind_annotate", "--threshold=100", str(out)],
                         capture_output=True, text=True, check=True).stdout
    funcs = {}
    total = None
    for line in ann.splitlines():
        m = re.match(r"\s*([\d,]+)\s+\([^)]*\)\s+(.*)", line)
        if not m:
            continue
        n, name = int(m.group(1).replace(",", "")), m.group(2).strip()
        if name.startswith("PROGRAM TOTALS"):
            total = n
        else:
            # "file:function [object]" -> function, without gfortran's module mangling.
            fn = name.split(" [")[0].split(":")[-1]
            fn = re.sub(r"^__empm_(\w+?)_MOD_", r"\1::", fn)
            funcs[fn] = funcs.get(fn, 0) + n
    return total, funcs, bench


def main():
    if len(sys.argv) != 3:
        sys.exit("usage: callgrind_count.py EMPM SHAPE   (SHAPE e.g. linear, lme_g3)")
    empm, shape = sys.argv[1], sys.argv[2]
    with tempfile.TemporaryDirectory() as tmp:
        t1, f1, _ = count(empm, shape, N1, tmp)
        t2, f2, bench = count(empm, shape, N2, tmp)
    den = (N2 - N1) * bench["particles"]
    split = {k: (f2.get(k, 0) - f1.get(k, 0)) / den for k in set(f1) | set(f2)}
    split = dict(sorted(((k, round(v, 1)) for k, v in split.items() if abs(v) >= 5.0),
                        key=lambda kv: -kv[1]))
    print(json.dumps({"dim": 2, "shape": bench["shape"], "particles": bench["particles"],
                      "steps": [N1, N2], "newton_iterations_mean": bench["newton_iterations_mean"],
                      "instructions_per_particle_step": round((t2 - t1) / den, 1),
                      "by_function": split}))


if __name__ == "__main__":
    main()
