#!/usr/bin/python3
"""Load balance under motion (docs/parallel.md, issue 18 item 4): a Mohr–Coulomb column
collapsing to one side on 4 processes. The boxes are cut again every 32 steps; the run's summary
line reports the largest process's share of the particles over the mean just before each re-cut
(the worst the boxes drifted to) and what the first boxes, never re-cut, would hold. Asserted:
re-cuts happen, the first boxes reach 2x the mean or more, the re-cut ones stay within 1.25x
(measured 1.20 at 800 particles; cell planes of 8-20 particles limit a cut's precision here),
and the result equals the serial run's to 1e-9 (a plastic flow over 8,600 steps amplifies the
processes' other summation order: measured 1.3e-10; the elastic cases of same_answers.py are
held to 1e-12).

With `--refine K` the grid's cells and the particles' spacing are K times finer (K² times the
particles, K times the steps): a measurement, not part of CTest. At K = 4 (12,800 particles)
the bound is the issue's 1.1, and the serial run is reported, not asserted: over 52,000 steps
of plastic flow the two summation orders part (measured: 52,493 against 52,701 steps, runout
0.4801 against 0.4806 m), as they did before the neighbour exchange (that build's 4 processes
agree with today's to 3.3e-15).

Usage: balance.py EMPM MPIRUN WORKDIR [--refine K]
"""
import os
import pathlib
import re
import subprocess
import sys

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent))
from same_answers import compare  # noqa: E402

CASE = """&grid
  ndim = 2, origin = 0.0, 0.0, h = 0.01, cells = 60, 24
/
&material
  name = 'sand', model = 'mohr_coulomb', density = 1500.0, E = 2.0e6, nu = 0.3,
  cohesion = 0.0, friction_angle = 30.0, dilatancy_angle = 0.0
/
&particles
  name = 'column', material = 'sand', geometry = 'box', lo = 0.0, 0.0, hi = 0.1, 0.2,
  ppc = 2, geostatic = .true., k0 = 0.5
/
&integrator
  scheme = 'musl', cfl = 0.5, t_end = 0.4
/
&loads
  gravity = 0.0, -9.81
/
&boundary
  lo = 0.0, 0.0, hi = 0.6, 0.0, fix = .true., .true.
/
&boundary
  lo = 0.0, 0.0, hi = 0.0, 0.24, fix = .true., .false.
/
&output
  history_every = 50, snapshot_times = 0.2, 0.4
/
"""


def main():
    empm, mpirun, work = sys.argv[1], sys.argv[2], pathlib.Path(sys.argv[3])
    refine = int(sys.argv[sys.argv.index("--refine") + 1]) if "--refine" in sys.argv else 1
    work.mkdir(parents=True, exist_ok=True)
    case = CASE.replace("h = 0.01, cells = 60, 24",
                        f"h = {0.01 / refine}, cells = {60 * refine}, {24 * refine}")
    (work / "column.nml").write_text(case)
    mpi = [mpirun, "--oversubscribe"] + (["--allow-run-as-root"] if os.geteuid() == 0 else [])
    r = subprocess.run([empm, "run", "column.nml", "-o", "serial.h5"], cwd=work,
                       capture_output=True, text=True, timeout=600 * refine)
    if r.returncode:
        print("FAIL serial run:", r.stderr[-400:]); return 1
    r = subprocess.run(mpi + ["-n", "4", empm, "run", "column.nml", "-o", "p4.h5"], cwd=work,
                       capture_output=True, text=True, timeout=600 * refine)
    out = r.stdout + r.stderr
    m = re.search(r"(\d+) re-cuts, particles per process at most ([0-9.]+) x the mean "
                  r"\(never re-cut: ([0-9.]+)\)", out)
    if r.returncode or not m:
        print("FAIL mpirun -n 4:", out[-600:]); return 1
    recuts, worst, static = int(m.group(1)), float(m.group(2)), float(m.group(3))
    diff, where, _ = compare(work / "serial.h5", work / "p4.h5")
    print(f"4 processes: {recuts} re-cuts, at most {worst} x the mean (first boxes: {static}); "
          f"against the serial run {diff:.2e} ({where})")
    bound = 1.1 if refine >= 4 else 1.25
    ok = recuts > 0 and static >= 2.0 and worst <= bound and (refine > 1 or diff <= 1e-9)
    print("ok" if ok else "FAIL")
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
