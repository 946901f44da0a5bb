#!/usr/bin/python3
"""Memory and time of a parallel run's output (docs/parallel.md, "Output"; issue 18 item 5):
the bench's 2D block (benchmarks/block_case.py) with SNAPSHOTS snapshots is run by
`mpirun -n N` under `/usr/bin/time`, which reports each process's peak resident memory; the
whole command's wall time is measured here. Run it with two builds to compare the two ways a
parallel run writes its file: processes writing their blocks together (parallel HDF5) and the
root gathering every particle (a build with -DEMPM_PARALLEL_HDF5=OFF, or serial HDF5).

Usage: mpi_output.py EMPM MPIRUN WORKDIR [--ranks 2] [--cells 256] [--snapshots 10]
       [--steps 40]
Prints the peak memory of each process (MB), the largest over the mean, and the wall time,
then a JSON line.
"""
import json
import os
import pathlib
import re
import subprocess
import sys
import time

HERE = pathlib.Path(__file__).resolve().parent


def opt(name, default):
    if name in sys.argv:
        return type(default)(sys.argv[sys.argv.index(name) + 1])
    return default


def main():
    empm, mpirun, work = sys.argv[1], sys.argv[2], pathlib.Path(sys.argv[3]).resolve()
    ranks, cells = opt("--ranks", 2), opt("--cells", 256)
    nsnap, steps = opt("--snapshots", 10), opt("--steps", 40)
    work.mkdir(parents=True, exist_ok=True)
    case = work / "block.nml"
    subprocess.run([sys.executable, str(HERE / "block_case.py"), str(case), "2", "linear",
                    str(cells), "2", str(steps)], check=True)
    text = case.read_text()
    t_end = float(re.search(r"t_end = ([0-9.eE+-]+)", text).group(1))
    times = ", ".join(repr(t_end * (k + 1) / (nsnap + 1)) for k in range(nsnap))
    case.write_text(text.replace("&output\n", f"&output\n  snapshot_times = {times}\n"))
    # Each process writes its peak resident set size (kB) to rss.<rank>.
    wrap = work / "rss.sh"
    wrap.write_text('#!/bin/sh\nexec /usr/bin/time -f %M -o "' + str(work) +
                    '/rss.$OMPI_COMM_WORLD_RANK" "$@"\n')
    wrap.chmod(0o755)
    for f in work.glob("rss.*[0-9]"):
        f.unlink()
    mpi = [mpirun, "--oversubscribe"] + (["--allow-run-as-root"] if os.geteuid() == 0 else [])
    out = work / "block.h5"
    t0 = time.perf_counter()
    r = subprocess.run(mpi + ["-n", str(ranks), str(wrap), empm, "run", str(case), "-o",
                              str(out)], cwd=work, capture_output=True, text=True,
                       env=dict(os.environ, OMP_NUM_THREADS="1"))
    seconds = time.perf_counter() - t0
    if r.returncode != 0:
        sys.exit(f"mpi_output: the run failed ({r.returncode}): {(r.stdout + r.stderr)[-600:]}")
    loop = float(re.findall(r"wall ([0-9.]+) s", r.stderr + r.stdout)[-1])
    rss = [int((work / f"rss.{k}").read_text().split()[-1]) / 1024 for k in range(ranks)]
    mean = sum(rss) / len(rss)
    for k, m in enumerate(rss):
        print(f"process {k}: peak {m:8.1f} MB")
    print(f"largest / mean {max(rss) / mean:.3f}; command {seconds:.2f} s, time loop {loop:.2f} s,"
          f" after it {seconds - loop:.2f} s; file {out.stat().st_size / 2**20:.1f} MB")
    print(json.dumps({"ranks": ranks, "cells": cells, "snapshots": nsnap, "peak_mb": rss,
                      "max_over_mean": max(rss) / mean, "seconds": seconds, "loop": loop}))


if __name__ == "__main__":
    main()
