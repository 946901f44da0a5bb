#!/usr/bin/python3
"""Stopping together (docs/parallel.md): under `mpirun -n N`,
1. a guard tripped on one process (a particle of one process's box leaves the grid) stops every
   process with exit status 3 and one message, naming the particle as the serial run does, and
   the results written (marked incomplete) equal the serial run's last good state;
2. a stress update that fails on one process (a particle inverted) does the same;
3. a case file error is reported once, with exit status 2 on every process; so is a particle
   whose support does not fit the grid, found by the process holding it once the particles
   are shared (several processes hold such particles; the serial run's, the smallest id, is
   named), before the output is claimed (an unusable output folder changes nothing); so are
   the set-up's checks over particles each process stores a share of (a traction box deeper
   than the outer layer or selecting none, particles on a mirror's ghost side): the serial
   run's message, naming the particle of smallest id;
4. case 1 with a surface traction and checkpoints (its loaded particles shared out, the
   checkpoints gathered) stops the same way, with the serial run's message and last good state;
5. a file the case needs that is missing on one process only (its own working folder, with
   mpirun's MPMD form) gives status 2 and one message naming the file, on every process; so
   does a point list that differs between the processes' folders; a point list whose bad
   values are met by different processes (each converts its own points' values) gives the
   serial run's message, that of the earliest line;
6. an output that one process cannot write (its file size limited) gives status 4 and one
   message naming the file, and leaves no partial file.
No process may hang: each run has a time limit.

Usage: stops.py EMPM MPIRUN WORKDIR [--ranks 2,3] [--writers all|1]
--writers: how the build writes its output (all processes together, or the root: case 6).
"""
import os
import pathlib
import re
import shutil
import subprocess
import sys

import h5py
import numpy as np

LEAVE = """&grid
  ndim = 2, origin = 0.0, 0.0, h = 0.1, cells = 20, 10
/
&material
  name = 'm', model = 'linear_elastic', E = 1.0e4, nu = 0.3, density = 1000.0
/
&particles
  material = 'm', geometry = 'box', lo = 0.2, 0.2, hi = 0.8, 0.8, ppc = 2
/
&particles
  material = 'm', geometry = 'box', lo = 1.2, 0.2, hi = 1.8, 0.8, ppc = 2, velocity = 3.0, 0.0
/
&integrator
  scheme = 'musl', cfl = 0.5, t_end = 1.0
/
&output
  snapshot_times = 0.05
/
"""

# The right block hits a fixed wall so fast (0.12 m, 1.2 cells, a step) that its particles in
# the wall's cell invert in the next step (1 + tr Δε <= 0): a stress-update failure.
INVERT = LEAVE.replace("E = 1.0e4", "E = 1.0") \
    .replace("velocity = 3.0, 0.0", "velocity = 1200.0, 0.0").replace("cfl = 0.5", "dt = 1.0e-4").replace("""&output
  snapshot_times = 0.05
/
""", """&boundary
  lo = 1.9, 0.0, hi = 2.0, 1.0, fix = .true., .true.
/
""")

BAD = LEAVE.replace("cfl = 0.5", "cfl = -0.5")
# Quadratic B-splines without padding: the particles next to the right face (and those of a
# second body there, later ids) need nodes beyond the grid.
UNFIT = """&grid
  ndim = 2, h = 0.1, cells = 40, 10
/
&material
  name = 'm', model = 'linear_elastic', E = 1.0e6, nu = 0.3, density = 2000.0
/
&particles
  material = 'm', lo = 0.3, 0.3, hi = 4.0, 0.5
/
&particles
  material = 'm', lo = 3.0, 0.5, hi = 4.0, 1.0
/
&shape
  family = 'bspline2'
/
&integrator
  scheme = 'musl', t_end = 0.01
/
"""
# Checkpoints of a case with surface tractions (their per-particle state is not gathered yet).
CKPT = LEAVE.replace("snapshot_times = 0.05", "snapshot_times = 0.05, checkpoint_every = 10") \
    .replace("material = 'm', geometry = 'box', lo = 0.2, 0.2, hi = 0.8, 0.8, ppc = 2",
             "name = 'left', material = 'm', geometry = 'box', lo = 0.2, 0.2, hi = 0.8, 0.8, "
             "ppc = 2") + """&traction
  name = 'top', body = 'left', lo = 0.2, 0.76, hi = 0.8, 0.8, face = '+y', pressure = 10.0
/
"""

# Set-up checks over the particles that each process stores a share of (docs/parallel.md,
# "Set-up"): the first offending particle (lowest id, on whichever process) is named as in the
# serial run (particles 122 and 17: not the first process's on 3 processes, 122 not on 2). A traction
# box reaching two rows into a body; one selecting no particle; a mirror plane with particles
# on its ghost side.
DEEP = CKPT.replace("lo = 0.2, 0.76, hi = 0.8, 0.8", "lo = 0.25, 0.7, hi = 0.8, 0.8")
NOBOX = CKPT.replace("lo = 0.2, 0.76, hi = 0.8, 0.8", "lo = 0.2, 0.85, hi = 0.8, 0.9")
GHOST = LEAVE + """&boundary
  lo = 0.6, 0.0, hi = 0.6, 1.0, fix = .true., .false., mirror = '+x'
/
"""


def run(cmd, cwd):
    try:
        r = subprocess.run(cmd, cwd=cwd, capture_output=True, text=True, timeout=120)
    except subprocess.TimeoutExpired:
        return None, "timed out (a process hangs)"
    return r.returncode, r.stdout + r.stderr


def error_lines(log):
    return [ln for ln in log.splitlines() if ln.startswith("empm: error:")]


def main():
    empm, mpirun, work = sys.argv[1], sys.argv[2], pathlib.Path(sys.argv[3])
    ranks = [2, 3]
    writers = sys.argv[sys.argv.index("--writers") + 1] if "--writers" in sys.argv else "all"
    if "--ranks" in sys.argv:
        ranks = [int(k) for k in sys.argv[sys.argv.index("--ranks") + 1].split(",")]
    work.mkdir(parents=True, exist_ok=True)
    mpi = [mpirun, "--oversubscribe"] + (["--allow-run-as-root"] if os.geteuid() == 0 else [])
    fails = []
    for name, text, status in [("leave", LEAVE, 3), ("invert", INVERT, 3), ("bad", BAD, 2),
                               ("unfit", UNFIT, 2), ("ckpt", CKPT, 3), ("deep", DEEP, 2),
                               ("nobox", NOBOX, 2), ("ghost", GHOST, 2)]:
        nml = work / f"{name}.nml"
        nml.write_text(text)
        rc, slog = run([empm, "run", str(nml), "-o", f"{name}_s.h5"], work)
        serial_err = error_lines(slog)
        if rc != status or len(serial_err) != 1:
            fails.append(f"{name}: the serial run exited {rc}, expected {status}: {slog[-300:]}")
            continue
        for n in ranks:
            out = f"{name}_p{n}.h5"
            rc, log = run(mpi + ["-n", str(n), empm, "run", str(nml), "-o", out], work)
            errs = error_lines(log)
            if rc != status:
                fails.append(f"{name} -n {n}: exit status {rc}, expected {status}: {log[-400:]}")
                continue
            if len(errs) != 1:
                fails.append(f"{name} -n {n}: {len(errs)} error lines, expected one: {errs}")
                continue
            # The same message as the serial run but for the output file's name.
            if errs[0].replace(out, "OUT") != serial_err[0].replace(f"{name}_s.h5", "OUT"):
                fails.append(f"{name} -n {n}: message differs:\n  {errs[0]}\n  {serial_err[0]}")
                continue
            if status == 3:
                with h5py.File(work / f"{name}_s.h5") as a, h5py.File(work / out) as b:
                    if a.attrs.get("complete") != b.attrs.get("complete"):
                        fails.append(f"{name} -n {n}: 'complete' attribute differs")
                    # Stress against E at least: the free blocks' stresses are round-off noise.
                    e_mod = 1.0e4 if name in ("leave", "ckpt") else 1.0
                    for ds, floor in (("final/x", 0.0), ("final/v", 0.0),
                                      ("final/stress", e_mod)):
                        x, y = a[ds][...], b[ds][...]
                        d = np.max(np.abs(x - y)) / max(np.max(np.abs(x)), floor, 1e-300)
                        if not d <= 1e-12:
                            fails.append(f"{name} -n {n}: {ds} differs by {d:.2e}")
            if name == "unfit":
                # The input error comes before the output is claimed, as in the serial run: an
                # output folder that does not exist changes nothing.
                rc2, log2 = run(mpi + ["-n", str(n), empm, "run", str(nml), "-o", "missing/x.h5"],
                                work)
                errs2 = error_lines(log2)
                if rc2 != status or errs2 != errs:
                    fails.append(f"{name} -n {n}, unusable output: exit {rc2}: {errs2}")
                    continue
            print(f"ok   {name} -n {n}: exit {rc}: {errs[0][:110]}")
    # 5. The mesh of examples/embankment_2d.nml next to the case for process 0 only.
    examples = pathlib.Path(__file__).resolve().parents[2] / "examples"
    for sub in ("A", "B"):
        (work / sub).mkdir(exist_ok=True)
        shutil.copy(examples / "embankment_2d.nml", work / sub)
    shutil.copy(examples / "embankment_2d.msh", work / "A")
    (work / "B" / "embankment_2d.msh").unlink(missing_ok=True)
    rc, log = run(mpi + ["-n", "1", "--wdir", str(work / "A"), empm, "run", "embankment_2d.nml",
                         ":", "-n", "1", "--wdir", str(work / "B"), empm, "run",
                         "embankment_2d.nml"], work)
    errs = error_lines(log)
    if rc != 2 or len(errs) != 1 or "embankment_2d.msh" not in errs[0]:
        fails.append(f"missing file on process 1: exit {rc}, messages {errs}: {log[-400:]}")
    else:
        print(f"ok   missing file on process 1 of 2: exit {rc}: {errs[0][:110]}")
    # 5b. A point list that differs between the processes' folders (one point more for
    # process 1): every process generates the particles, so they would disagree on the ids;
    # status 2 and one message on every process.
    body = "x, y, volume\n" + "".join(f"{0.25 + 0.1 * i:.2f}, 0.35, 0.01\n" for i in range(5))
    for sub, extra in (("D", ""), ("E", "0.85, 0.45, 0.01\n")):
        (work / sub).mkdir(exist_ok=True)
        (work / sub / "pts.csv").write_text(body + extra)
        (work / sub / "pts.nml").write_text(LEAVE.replace(
            "geometry = 'box', lo = 0.2, 0.2, hi = 0.8, 0.8, ppc = 2",
            "geometry = 'file', file = 'pts.csv'"))
    rc, log = run(mpi + ["-n", "1", "--wdir", str(work / "D"), empm, "run", "pts.nml", ":",
                         "-n", "1", "--wdir", str(work / "E"), empm, "run", "pts.nml"], work)
    errs = error_lines(log)
    if rc != 2 or len(errs) != 1 or "different numbers of particles" not in errs[0]:
        fails.append(f"body files differing between processes: exit {rc}, messages {errs}: "
                     f"{log[-400:]}")
    else:
        print(f"ok   body files differing between processes: exit {rc}: {errs[0][:110]}")
    # 3b. A point list with two bad values (points 6 and 7): each process converts the values
    # of its own points only, so the earliest error (point 6, held by process 1 of 2 and 2 of
    # 3) must win over the root's (point 7): the serial run's message, on every process.
    pts = [f"{0.2 + 0.05 * i:.2f}, 0.35, 0.01" for i in range(12)]
    pts[5] = "0.45, 0.35, -0.01"
    pts[6] = "0.50, 0.35, abc"
    (work / "F").mkdir(exist_ok=True)
    (work / "F" / "pts.csv").write_text("x, y, volume\n" + "\n".join(pts) + "\n")
    (work / "F" / "pts.nml").write_text(LEAVE.replace(
        "geometry = 'box', lo = 0.2, 0.2, hi = 0.8, 0.8, ppc = 2",
        "geometry = 'file', file = 'pts.csv'"))
    rc, slog = run([empm, "run", "pts.nml", "-o", "s.h5"], work / "F")
    serial_err = error_lines(slog)
    if rc != 2 or len(serial_err) != 1 or ":7" not in serial_err[0]:
        fails.append(f"csvbad: the serial run exited {rc}: {serial_err}")
    for n in ranks:
        rc, log = run(mpi + ["-n", str(n), empm, "run", "pts.nml", "-o", "p.h5"], work / "F")
        errs = error_lines(log)
        if rc != 2 or len(errs) != 1 or errs[0] != serial_err[0]:
            fails.append(f"csvbad -n {n}: exit {rc}, messages {errs}, serial {serial_err}")
        else:
            print(f"ok   csvbad -n {n}: exit {rc}: {errs[0][:110]}")
    # 6. The output cannot be written by one process (its file size limited, as by a full
    # disk or a quota): status 4 on every process, one message naming the file and the reason,
    # no partial file left, no hang. Written together (parallel HDF5) the job ends there
    # (MPI_Abort); written by the root, the root alone writes and fails.
    (work / "C").mkdir(exist_ok=True)
    # Case 1 with its right block slowed so that it stays on the grid: a run that completes.
    (work / "C" / "leave.nml").write_text(LEAVE.replace("t_end = 1.0", "t_end = 0.1")
                                          .replace("velocity = 3.0, 0.0", "velocity = 0.3, 0.0"))
    for limited in range(2):
        for f in (work / "C").glob("full*"):
            shutil.rmtree(f) if f.is_dir() else f.unlink()
        shell = ('if [ "$OMPI_COMM_WORLD_RANK" = ' + str(limited) + ' ]; then trap "" XFSZ; '
                 'ulimit -f 8; fi; exec "$0" run leave.nml -o full.h5')
        rc, log = run(mpi + ["-n", "2", "sh", "-c", shell, empm], work / "C")
        errs = error_lines(log)
        # The snapshots go to full.h5.snapshots/ as they are taken: the first write may fail there.
        left = sorted(f.name for f in (work / "C").glob("full*.partial")) + \
            sorted(f.name for f in (work / "C").glob("full.h5.snapshots/*.partial"))
        if writers == "1" and limited != 0:
            # Only the root writes: the limited process has nothing to write.
            if rc != 0 or errs or left:
                fails.append(f"root writes, process {limited} limited: exit {rc}, {errs}")
            else:
                print(f"ok   write limited on process {limited} of 2, the root writes: exit 0")
            continue
        if rc != 4 or len(errs) != 1 or not re.search(r"full\.(h5|snapshots/)", errs[0]) or left:
            fails.append(f"write failure on process {limited}: exit {rc}, messages {errs}, "
                         f"partial files {left}: {log[-400:]}")
        else:
            print(f"ok   write failure on process {limited} of 2: exit {rc}: {errs[0][:110]}")
    for f in fails:
        print("FAIL", f)
    return 1 if fails else 0


if __name__ == "__main__":
    sys.exit(main())
