#!/usr/bin/python3
"""Memory per process of a parallel `empm run` (docs/parallel.md, "Block-local grids"): a 3D
column of soil on a wide, mostly empty grid (a runout domain), run under `mpirun -n N`; every
process's resident memory is sampled from /proc while it runs. Prints, per process, the peak
(VmHWM, whenever it came: set-up, time loop or the output's writing), the largest sample
before the first step's progress line (the set-up), the median of the samples over the last
half of the run (the time loop), and the summary line's grid nodes stored per process.

Usage: mpi_memory.py EMPM MPIRUN WORKDIR [--ranks 1,2,4] [--cells 96] [--steps 40]
       [--shape linear|lme] [--width 0.1] [--ppc 2]
--shape lme: gamma = 1.8, whose basis outweighs the particles; --width: the column's width as
a share of the grid's (0.5: a particle-heavy case); --ppc: particles per cell and direction.
Prints one line per run and a JSON line per run.
"""
import json
import os
import pathlib
import re
import statistics
import subprocess
import sys
import threading
import time


def opt(name, default):
    if name in sys.argv:
        return type(default)(sys.argv[sys.argv.index(name) + 1])
    return default


CASE = """&grid
  ndim = 3, h = {h}, cells = {n}, {n}, {nz}
/
&material
  name = 'soil', model = 'linear_elastic', E = 1.0e6, nu = 0.3, density = 2000.0
/
&particles
  material = 'soil', geometry = 'box', lo = {a}, {a}, 0.0, hi = {b}, {b}, {top}, ppc = {ppc}
/
&shape
  family = {shape}
/
&integrator
  scheme = 'pc_newmark', cfl = 0.5, t_end = {t_end}
/
&loads
  gravity = 0.0, 0.0, -9.81
/
&boundary
  lo = 0.0, 0.0, 0.0, hi = {L}, {L}, 0.0, fix = .true., .true., .true.
/
&output
  history_every = 1000000
/
"""


def status(pid):
    out = {}
    try:
        for line in pathlib.Path(f"/proc/{pid}/status").read_text().splitlines():
            if line.startswith(("VmRSS:", "VmHWM:")):
                out[line.split(":")[0]] = int(line.split()[1]) / 1024.0
    except OSError:
        pass
    return out


def workers(exe, case):
    """Pids of the running empm processes (the binary `exe`) of the case file `case`."""
    pids = []
    for d in pathlib.Path("/proc").iterdir():
        if d.name.isdigit():
            try:
                if os.readlink(d / "exe") == exe and \
                        case.encode() in (d / "cmdline").read_bytes():
                    pids.append(int(d.name))
            except OSError:
                pass
    return sorted(pids)


def main():
    empm, mpirun, work = sys.argv[1], sys.argv[2], pathlib.Path(sys.argv[3])
    ranks = [int(k) for k in opt("--ranks", "1,2,4").split(",")]
    n, steps = opt("--cells", 96), opt("--steps", 40)
    shape = {"linear": "'linear'", "lme": "'lme', gamma = 1.8"}[opt("--shape", "linear")]
    work.mkdir(parents=True, exist_ok=True)
    h = 0.05
    L = n * h
    # A column `width` of the grid wide (a tenth by default) and a third of its height, in
    # the grid's middle.
    width = opt("--width", 0.1)
    a, b = round((0.5 - width / 2) * L, 6), round((0.5 + width / 2) * L, 6)
    nz = n // 2
    top = round(nz * h / 3.0, 6)
    dt = 0.5 * h / (1.0e6 * 0.7 / (1.3 * 0.4) / 2000.0) ** 0.5
    path = work / "column.nml"
    path.write_text(CASE.format(h=h, n=n, nz=nz, a=a, b=b, top=top, L=L, t_end=steps * dt,
                               shape=shape, ppc=opt("--ppc", 2)))
    exe = os.path.realpath(empm)
    env = dict(os.environ, OMP_NUM_THREADS="1")
    mpi = [mpirun, "--oversubscribe"] + (["--allow-run-as-root"] if os.geteuid() == 0 else [])
    for r in ranks:
        cmd = [empm, "run", str(path), "-o", str(work / f"column_{r}.h5")]
        if r > 1:
            cmd = mpi + ["-n", str(r)] + cmd
        proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
                                env=env)
        # The log is read as it comes: the first progress line ends the set-up (it comes a few
        # steps in: a tenth of the run, which the set-up's figure may then include).
        lines, first_step = [], []

        def reader():
            for line in proc.stdout:
                if not first_step and re.search(r"%\s+t =.*\bstep \d+", line):
                    first_step.append(time.time())
                lines.append(line)
        th = threading.Thread(target=reader)
        th.start()
        # Every 2 ms (a set-up's peak may last tens of milliseconds); /proc is searched for the
        # processes until all r are found.
        samples, pids = {}, []
        while proc.poll() is None:
            if len(pids) < r:
                pids = workers(exe, str(path))
            for pid in pids:
                s = status(pid)
                if s:
                    s["t"] = time.time()
                    samples.setdefault(pid, []).append(s)
            time.sleep(0.002)
        th.join()
        log = "".join(lines)
        if proc.returncode != 0:
            print(log[-800:])
            return 1
        m = re.search(r"grid nodes stored per process at most (\d+) of (\d+)", log)
        stored = (int(m[1]), int(m[2])) if m else None
        per = []
        for pid, ss in sorted(samples.items()):
            loop = [s["VmRSS"] for s in ss[len(ss) // 2:] if "VmRSS" in s]
            peak = max(s.get("VmHWM", 0.0) for s in ss)
            setup = [s["VmRSS"] for s in ss if "VmRSS" in s and first_step and
                     s["t"] < first_step[0]]
            per.append({"peak_mb": round(peak, 1),
                        "setup_mb": round(max(setup), 1) if setup else None,
                        "time_loop_mb": round(statistics.median(loop), 1) if loop else None})
        print(f"{r} process(es): peak {[p['peak_mb'] for p in per]} MB, set-up "
              f"{[p['setup_mb'] for p in per]} MB, time loop "
              f"{[p['time_loop_mb'] for p in per]} MB, grid nodes stored "
              f"{stored[0] if stored else 'all'} of {stored[1] if stored else 'all'}", flush=True)
        print(json.dumps({"tag": "mpi_memory", "ranks": r, "cells": [n, n, nz], "shape": shape,
                          "width": width, "ppc": opt("--ppc", 2),
                          "processes": per, "stored_nodes": stored}))
    return 0


if __name__ == "__main__":
    sys.exit(main())
