#!/usr/bin/python3
"""Weak scaling of `empm run` from 1 to 2 processes (docs/parallel.md, issue 18 item 6): the
bench's block (benchmarks/block_case.py) with the same particles per process, run by one
process and by `mpirun -n 2` (one thread each), in interleaved rounds; the time-loop wall
times ('wall ... s' of the summary line) give the efficiency T1/T2. Also the bytes the busiest
process sent per step in the nodal sums ('halo ... bytes per step', the neighbour exchange),
beside what an all-reduce of the whole nodal arrays (the design before it) would move.

Usage: mpi_scaling.py EMPM MPIRUN WORKDIR [--cells 256] [--steps 60] [--rounds 3]
       [--shape linear]
Prints one line per run and a JSON line with the medians.
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
    cells, steps, rounds = opt("--cells", 256), opt("--steps", 60), opt("--rounds", 3)
    shape = opt("--shape", "linear")
    work.mkdir(parents=True, exist_ok=True)
    # The same particles per process: the 2-process block has sqrt(2) times the cells a side.
    cells2 = int(round(cells * math.sqrt(2.0)))
    cases = {}
    for n, c in ((1, cells), (2, cells2)):
        path = work / f"weak_{n}.nml"
        subprocess.run(["/usr/bin/python3", str(HERE / "block_case.py"), str(path), "2", shape,
                        str(c), "2", str(steps)], check=True)
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
            npart = 4 * c * c
            print(f"round {r + 1}: {n} process(es), {npart} particles "
                  f"({npart // n} per process), time loop {t:.2f} s", flush=True)
    t1, t2 = statistics.median(times[1]), statistics.median(times[2])
    # An all-reduce of the whole nodal arrays would move, per step of pc_newmark with linear
    # shapes: masses, momenta (map_velocity) and forces (kick), (1 + 2 + 2) doubles per node.
    nodes2 = (cells2 + 1) ** 2
    sent = 8 * 5 * nodes2
    print(json.dumps({"tag": "mpi_weak", "shape": shape, "particles_per_process": 4 * cells * cells,
                      "steps": steps, "t1_median": t1, "t2_median": t2,
                      "efficiency": t1 / t2, "t1": times[1], "t2": times[2],
                      "halo_bytes_per_step": statistics.median(halo_bytes),
                      "allreduce_bytes_per_step": sent}))
    return 0


if __name__ == "__main__":
    sys.exit(main())
