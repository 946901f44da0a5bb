#!/usr/bin/python3
"""Checkpoints on several processes, restarts on any number (docs/parallel.md): a checkpoint
written by `mpirun -n N` holds every particle in id order (and every surface traction's
state), as a serial run's; continued with
--restart on M processes (M = 1 without mpirun, 2, 3) the results equal the uninterrupted serial
run's to 1e-12 (same_answers.py's measure), and a serial checkpoint continues on 2 processes
likewise. A restart on several processes reads only each process's particles' columns of the
checkpoint (dealt2d: geostatic bodies, a body from a point list, a traction and probes).

Usage: restart.py EMPM MPIRUN WORKDIR
"""
import os
import pathlib
import subprocess
import sys

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent))
from same_answers import case_text, compare, write_body_files  # noqa: E402

TOL = 1.0e-12


def main():
    empm, mpirun, work = sys.argv[1], sys.argv[2], pathlib.Path(sys.argv[3])
    work.mkdir(parents=True, exist_ok=True)
    mpi = [mpirun, "--oversubscribe"] + (["--allow-run-as-root"] if os.geteuid() == 0 else [])
    fails = []
    write_body_files(work)

    def run(n, args):
        cmd = [empm, "run"] + args
        if n > 0:
            cmd = mpi + ["-n", str(n)] + cmd
        r = subprocess.run(cmd, cwd=work, capture_output=True, text=True, timeout=300)
        return r.returncode, r.stdout + r.stderr

    for name, scheme, shape in [("disks2d", "pc_newmark", "lme"), ("disks2d", "musl", "linear"),
                                ("block3d", "gen_alpha", "bspline2"),
                                ("strip2d", "pc_newmark", "lme"), ("dealt2d", "musl", "ugimp")]:
        tag = f"{name}_{scheme}_{shape}"
        ref = work / f"{tag}.nml"
        ref.write_text(case_text(name, scheme, shape))
        ck = work / f"{tag}_ck.nml"
        every = 4 if name == "block3d" else 37  # the 3D block takes 9 steps
        if name == "strip2d":
            every = 100  # not at a re-cut (every 32 steps): a traction's state must travel
        ck.write_text(case_text(name, scheme, shape).replace(
            "snapshot_times", f"checkpoint_every = {every}, snapshot_times"))
        rc, log = run(0, [str(ref), "-o", f"{tag}_ref.h5"])
        if rc:
            fails.append(f"{tag}: reference run exited {rc}: {log[-300:]}")
            continue
        for writer in (0, 2):
            out = f"{tag}_w{writer}.h5"
            rc, log = run(writer, [str(ck), "-o", out])
            if rc:
                fails.append(f"{tag}: the run writing checkpoints on {writer or 1} process(es) "
                             f"exited {rc}: {log[-300:]}")
                continue
            ckpt = out.replace(".h5", ".ckpt.h5")
            for reader in ((0, 2, 3) if writer else (2,)):
                res = f"{tag}_w{writer}_r{reader}.h5"
                rc, log = run(reader, [str(ck), "-o", res, "--restart", ckpt])
                if rc:
                    fails.append(f"{tag}: restart on {reader or 1} of a checkpoint from "
                                 f"{writer or 1} exited {rc}: {log[-300:]}")
                    continue
                worst, where, same = compare(work / f"{tag}_ref.h5", work / res)
                line = (f"{tag}: checkpoint of {writer or 1} process(es), restart on "
                        f"{reader or 1}: {'bitwise' if same else f'{worst:.2e} ({where})'}")
                if worst <= TOL:
                    print("ok  ", line)
                else:
                    fails.append(line)
    for f in fails:
        print("FAIL", f)
    return 1 if fails else 0


if __name__ == "__main__":
    sys.exit(main())
