#!/usr/bin/python3
"""Weak scaling of `empm run` from 1 to 2 processes (docs/parallel.md, issue 18 item 6): the
bench's block (benchmarks/block_case.py) with the same particles per process, run by one
process and by `mpirun -n 2` (one thread each), in interleaved rounds; the time-loop wall
times ('wall ... s' of the summary line) give the efficiency T1/T2. Also the bytes the busiest
process sent per step in the nodal sums ('halo ... bytes per step', the neighbour exchange),
beside what an all-reduce of the whole nodal arrays (the design before it) would move.

Usage: mpi_scaling.py EMPM MPIRUN WORKDIR [--cells 256 | 32] [--steps 60] [--rounds 3]
       [--shape linear] [--dim 2]
--cells is the 1-process block's cells a side (2 particles per direction and cell: 2.6e5
particles at the defaults, 256 in 2D and 32 in 3D). Prints one line per run and a JSON line with the medians.
"""
import json
import math
import os
import pathlib
import re
import statistics
import subprocess
import sys

HERE = pathlib.Path(__file__).resolve().parent


def opt(name, default):
    if name in sys.argv:
        return type(default)(sys.argv[sys.argv.index(name) + 1])
    return default


def wall(log):
    m = re.findall(r"wall ([0-9.]+) s", log)
    if not m:
        raise RuntimeError("no summary line in:\n" + log[-800:])
    return float(m[-1])


def halo(log):
    m = re.findall(r"halo ([0-9.E+-]+) bytes per step", log)
    return float(m[-1]) if m else float("nan")


def main():
    empm, mpirun, work = sys.argv[1], sys.argv[2], pathlib.Path(sys.argv[3])
    dim = opt("--dim", 2)
    cells = opt("--cells", 256 if dim == 2 else 32)
    steps, rounds = opt("--steps", 60), opt("--rounds", 3)
    shape = opt("--shape", "linear")
    work.mkdir(parents=True, exist_ok=True)
    # The same particles per process: the 2-process block has 2^(1/dim) times the cells a side.
    cells2 = int(round(cells * 2.0 ** (1.0 / dim)))
    cases = {}
    for n, c in ((1, cells), (2, cells2)):
        path = work / f"weak_{n}.nml"
        subprocess.run(["/usr/bin/python3", str(HERE / "block_case.py"), str(path), str(dim),
                        shape, str(c), "2", str(steps)], check=True)
        cases[n] = (path, c)
    env = dict(os.environ, OMP_NUM_THREADS="1")
    mpi = [mpirun] + (["--allow-run-as-root"] if os.geteuid() == 0 else [])
    times = {1: [], 2: []}
    halo_bytes = []
    for r in range(rounds):
        for n in (1, 2):
            path, c = cases[n]
            cmd = [empm, "run", str(path), "-o", str(work / f"weak_{n}.h5")]
            if n > 1:
                cmd = mpi + ["-n", str(n)] + cmd
            out = subprocess.run(cmd, capture_output=True, text=True, env=env)
            if out.returncode != 0:
                print(out.stdout[-500:], out.stderr[-800:])
                return 1
            t = wall(out.stdout + out.stderr)
            times[n].append(t)
            if n > 1:
                halo_bytes.append(halo(out.stdout + out.stderr))
            npart = (2 * c) ** dim
            print(f"round {r + 1}: {n} process(es), {npart} particles "
                  f"({npart // n} per process), time loop {t:.2f} s", flush=True)
    t1, t2 = statistics.median(times[1]), statistics.median(times[2])
    # Efficiency per particle: the 2-process block holds a little more or fewer particles per
    # process than the 1-process one (cells a side are whole numbers).
    per1, per2 = (2 * cells) ** dim, (2 * cells2) ** dim / 2.0
    eff = (t1 / per1) / (t2 / per2)
    # An all-reduce of the whole nodal arrays would move, per step of pc_newmark: masses,
    # momenta (map_velocity) and forces (kick), 1 + 2 dim doubles per node.
    nodes2 = (cells2 + 1) ** dim
    sent = 8 * (1 + 2 * dim) * nodes2
    print(json.dumps({"tag": "mpi_weak", "shape": shape, "dim": dim,
                      "particles_per_process": (2 * cells) ** dim,
                      "steps": steps, "t1_median": t1, "t2_median": t2,
                      "efficiency": eff, "t1": times[1], "t2": times[2],
                      "halo_bytes_per_step": statistics.median(halo_bytes),
                      "allreduce_bytes_per_step": sent}))
    return 0


if __name__ == "__main__":
    sys.exit(main())
