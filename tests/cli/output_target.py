#!/usr/bin/python3
"""Output-path robustness of `empm run` (one scenario per call; CTest runs each):

  concurrent  two runs writing the same -o: the second is refused at its start (status 4,
              naming the other process), and so is one on -o OUT without .h5 (the same
              XDMF file and checkpoints); the first completes (status 0, a complete file
              with non-zero data); no partial or lock file is left.
  stale_lock  a lock left by a killed run (a dead process id) is taken over (status 0), and
              the partial files it left (beside the output, its XDMF file and checkpoints,
              and in its snapshots' folder) are removed; a live process's partial file, and
              a file that is not a partial name, are left.
  fifo        an existing non-regular file (a FIFO) as -o: refused (status 2, naming it),
              left as it was.
  directory   a folder as -o: refused (status 2), no partial or XDMF file left.
  disk_full   the file-size limit (RLIMIT_FSIZE) below the output size: status 4, one
              message with the system's reason, no HDF5 error stack, no crash, no file left.
  snapshots   each snapshot goes to OUT.h5.snapshots/ as it is taken: a run's peak memory does
              not grow with its snapshots (60 against 2 on the same block: the growth is below
              a tenth of what holding them would cost); the results hold every snapshot and
              the folder is gone; a snapshot file is there while the run goes on.
  xdmf_fails  the XDMF file cannot be put in place (a folder appears at OUT.xmf during the
              run): status 4 with the system's reason, the XDMF partial removed, the folder
              untouched, the HDF5 file complete.

usage: output_target.py EMPM CASE_DIR WORK_DIR SCENARIO
Exit 0 pass, 1 fail, 77 skipped (CTest SKIP_RETURN_CODE).
"""
import glob
import os
import resource
import shutil
import stat
import subprocess
import sys
import time

import h5py
import numpy as np


def fail(msg):
    print("FAIL: " + msg)
    sys.exit(1)


def leftovers(work):
    return sorted(glob.glob(os.path.join(work, "*.partial")) +
                  glob.glob(os.path.join(work, "*.lock")))


def run(empm, args, work, **kw):
    p = subprocess.run([empm, "run"] + args, cwd=work, capture_output=True, text=True,
                       errors="replace", timeout=120, **kw)
    print(f"$ empm run {' '.join(args)}\n-> status {p.returncode}\n{p.stdout}{p.stderr}")
    return p


def check_complete(path):
    with h5py.File(path, "r") as f:
        if int(f.attrs["complete"]) != 1:
            fail(f"{path}: complete = {f.attrs['complete']}")
        x = f["final/x"][()]
        if not np.all(np.isfinite(x)) or not np.any(x != 0.0):
            fail(f"{path}: /final/x is not finite and non-zero")
        t = f["history/time"][()]
        if t[-1] <= 0.0:
            fail(f"{path}: history ends at t = {t[-1]}")


def start_long_run(empm, cases, work, out, what):
    """Start long.nml (about 1 s in a Debug build) writing `out`; return once it holds the
    output's lock, i.e. after its up-front checks."""
    case = os.path.join(cases, "long.nml")
    a = subprocess.Popen([empm, "run", case, "-o", out], cwd=work, stdout=subprocess.PIPE,
                         stderr=subprocess.PIPE, text=True)
    lock = os.path.join(work, out + ".lock")
    t0 = time.time()
    while not os.path.exists(lock) and a.poll() is None and time.time() - t0 < 30:
        time.sleep(0.005)
    if a.poll() is not None:
        fail(f"the run ended before {what} (case too short)")
    return a


def concurrent(empm, cases, work):
    case, out = os.path.join(cases, "long.nml"), "same.h5"
    a = start_long_run(empm, cases, work, out, "the second could start")
    b = run(empm, [case, "-o", out], work)
    # `same` shares same.h5's XDMF file and checkpoints: refused too while it runs.
    c = run(empm, [case, "-o", "same"], work)
    a_out, a_err = a.communicate(timeout=120)
    if c.returncode != 4 or "same.h5" not in c.stderr or f"process {a.pid}" not in c.stderr:
        fail(f"-o same beside -o same.h5: status {c.returncode}: {c.stderr[-300:]}")
    print(f"-o same beside -o same.h5 -> status 4: {c.stderr.strip()[:150]}")
    print(f"first run -> status {a.returncode}\n{a_out}{a_err}")
    if b.returncode != 4:
        fail(f"second run: status {b.returncode}, expected 4")
    if f"process {a.pid}" not in b.stderr or "is writing this file" not in b.stderr:
        fail("second run: the message does not name the first run's process")
    if a.returncode != 0:
        fail(f"first run: status {a.returncode}, expected 0")
    check_complete(os.path.join(work, out))
    if leftovers(work):
        fail(f"left behind: {leftovers(work)}")


def stale_lock(empm, cases, work):
    dead = subprocess.Popen(["true"])
    dead.wait()  # its id is no longer a process (reuse within the test is improbable)
    with open(os.path.join(work, "stale.h5.lock"), "w") as f:
        f.write(f"{dead.pid}\n")
    os.makedirs(os.path.join(work, "stale.h5.snapshots"))
    dead_files = [f"stale.h5.{dead.pid}-1.partial", f"stale.xmf.{dead.pid}-2.partial",
                  f"stale.ckpt.h5.{dead.pid}-3.partial",
                  f"stale.ckpt.prev.h5.{dead.pid}-5.partial",
                  f"stale.h5.snapshots/000001.h5.{dead.pid}-4.partial"]
    kept = [f"stale.h5.{os.getpid()}-9.partial", "stale.h5.notes.partial"]
    for name in dead_files + kept:
        with open(os.path.join(work, name), "w") as f:
            f.write("x" * 1000)
    p = run(empm, [os.path.join(cases, "good.nml"), "-o", "stale.h5"], work)
    if p.returncode != 0:
        fail(f"status {p.returncode}, expected 0 (stale lock taken over)")
    check_complete(os.path.join(work, "stale.h5"))
    left = [n for n in dead_files if os.path.exists(os.path.join(work, n))]
    if left or os.path.exists(os.path.join(work, "stale.h5.snapshots")):
        fail(f"a killed run's partial files left behind: {left}")
    if not all(os.path.exists(os.path.join(work, n)) for n in kept):
        fail(f"removed a live process's partial file or another file: {kept}")
    for name in kept:
        os.remove(os.path.join(work, name))
    if leftovers(work):
        fail(f"left behind: {leftovers(work)}")
    # A lock held by a live process (this script) is respected.
    with open(os.path.join(work, "held.h5.lock"), "w") as f:
        f.write(f"{os.getpid()}\n")
    p = run(empm, [os.path.join(cases, "good.nml"), "-o", "held.h5"], work)
    os.remove(os.path.join(work, "held.h5.lock"))
    if p.returncode != 4 or f"process {os.getpid()}" not in p.stderr:
        fail(f"status {p.returncode}, expected 4 naming process {os.getpid()}")
    if os.path.exists(os.path.join(work, "held.h5")):
        fail("held.h5 was written although another process held the lock")


def fifo(empm, cases, work):
    path = os.path.join(work, "pipe.h5")
    os.mkfifo(path)
    p = run(empm, [os.path.join(cases, "good.nml"), "-o", "pipe.h5"], work)
    if p.returncode != 2:
        fail(f"status {p.returncode}, expected 2")
    if "pipe.h5: the output exists and is not a regular file" not in p.stderr:
        fail("the message does not name the output and say why")
    if not stat.S_ISFIFO(os.stat(path).st_mode):
        fail("the FIFO was replaced")
    if leftovers(work) or os.path.exists(os.path.join(work, "pipe.xmf")):
        fail(f"left behind: {leftovers(work)}")


def directory(empm, cases, work):
    os.mkdir(os.path.join(work, "out.h5"))
    p = run(empm, [os.path.join(cases, "good.nml"), "-o", "out.h5"], work)
    if p.returncode != 2:
        fail(f"status {p.returncode}, expected 2")
    if "out.h5: the output exists and is a folder" not in p.stderr:
        fail("the message does not name the output and say why")
    if leftovers(work) or os.path.exists(os.path.join(work, "out.xmf")) or \
            os.listdir(os.path.join(work, "out.h5")):
        fail(f"left behind: {leftovers(work)}")


def disk_full(empm, cases, work):
    limit = 16 * 1024  # good.nml writes about 40 kB

    def limit_size():
        resource.setrlimit(resource.RLIMIT_FSIZE, (limit, limit))

    try:
        soft, hard = resource.getrlimit(resource.RLIMIT_FSIZE)
        if hard != resource.RLIM_INFINITY and hard < limit:
            print("SKIP: the file-size limit cannot be set here")
            sys.exit(77)
    except (ValueError, OSError) as e:
        print(f"SKIP: {e}")
        sys.exit(77)
    p = run(empm, [os.path.join(cases, "good.nml"), "-o", "full.h5"], work,
            preexec_fn=limit_size)
    msg = p.stdout + p.stderr
    if p.returncode != 4:
        fail(f"status {p.returncode}, expected 4")
    if "full.h5: writing the HDF5 output" not in msg or "File too large" not in msg:
        fail("no single message with the system's reason")
    if "HDF5-DIAG" in msg or "Backtrace" in msg:
        fail("HDF5's error stack or a backtrace was printed")
    if msg.count("error:") != 1:
        fail("expected exactly one error line")
    if os.path.exists(os.path.join(work, "full.h5")) or leftovers(work) or \
            os.path.exists(os.path.join(work, "full.xmf")):
        fail(f"left behind: {os.listdir(work)}")


SNAP_CASE = """&grid ndim = 2, origin = -0.5, -0.5, h = 0.025, cells = 80, 80 /
&shape family = 'linear' /
&material name = 'm', model = 'linear_elastic', E = 1.0e4, nu = 0.3, density = 1.0 /
&particles material = 'm', geometry = 'box', lo = 0.0, 0.0, hi = 1.0, 1.0, ppc = 2,
  velocity = 0.1, 0.05 /
&integrator scheme = 'musl', t_end = {t_end} /
&output snapshot_times = {times} /
"""


def snapshots(empm, cases, work):
    import re
    peaks = {}
    for n in (2, 60):
        case = os.path.join(work, f"s{n}.nml")
        with open(case, "w") as f:
            f.write(SNAP_CASE.format(t_end=0.02, times=", ".join(
                f"{0.02 * k / n:.6f}" for k in range(1, n + 1))))
        out = f"s{n}.h5"
        p = run(empm, [case, "-o", out], work)
        if p.returncode != 0:
            fail(f"{n} snapshots: status {p.returncode}: {p.stderr[-300:]}")
        m = re.search(r"peak memory ([0-9.]+) MiB", p.stdout + p.stderr)
        if not m:
            fail(f"no peak memory on the summary line: {(p.stdout + p.stderr)[-300:]}")
        peaks[n] = float(m.group(1))
        with h5py.File(os.path.join(work, out), "r") as f:
            got, npart = len(f["snapshots"]), f["final/mass"].shape[0]
            last = f["snapshots"][f"{n:06d}"]["x"][()]
            if not np.array_equal(last, f["final/x"][()]):
                fail(f"{n} snapshots: the last one is not the final state")
        if got != n + 1:
            fail(f"{n} snapshots asked for (and t = 0): the file holds {got}")
        if os.path.exists(os.path.join(work, f"s{n}.h5.snapshots")) or leftovers(work):
            fail(f"left behind: {os.listdir(work)}")
    held = 60 * npart * (2 * 2 + 15) * 8 / 2**20  # what holding them in memory costs
    grew = peaks[60] - peaks[2]
    print(f"{npart} particles: peak {peaks[2]:.1f} MiB with 2 snapshots, {peaks[60]:.1f} MiB "
          f"with 60 (holding them would add {held:.1f} MiB)")
    if grew > 0.1 * held:
        fail(f"the peak memory grew by {grew:.1f} MiB with 58 more snapshots")
    # A file where the snapshot folder goes is refused (status 2), left as it was.
    with open(os.path.join(work, "f.h5.snapshots"), "w") as fh:
        fh.write("precious\n")
    p = run(empm, [os.path.join(work, "s2.nml"), "-o", "f.h5"], work)
    if p.returncode != 2 or "f.h5.snapshots" not in p.stderr or \
            open(os.path.join(work, "f.h5.snapshots")).read() != "precious\n":
        fail(f"a file at the snapshot folder's place: status {p.returncode}: {p.stderr[-300:]}")
    print(f"a file at f.h5.snapshots: status 2: {p.stderr.strip()[:120]}")
    # While a run goes on, the snapshots taken so far are files of their own.
    p = start_long_run(empm, cases, work, "live.h5", "snapshot")
    try:
        staged = os.path.join(work, "live.h5.snapshots", "000000.h5")
        deadline = time.time() + 20
        while not os.path.exists(staged) and time.time() < deadline and p.poll() is None:
            time.sleep(0.01)
        if not os.path.exists(staged):
            if p.poll() is None:
                fail("no snapshot file while the run went on")
            print("note: the long run ended before its snapshot file was seen (a fast build)")
            staged = None
        try:
            f = h5py.File(staged, "r") if staged else None
        except OSError:  # removed as the run ended, the instant after it was seen
            print("note: the long run ended as its snapshot file was seen (a fast build)")
            f = None
        if f:
            with f:
                fmt = f.attrs["format"]
                if (fmt.decode() if isinstance(fmt, bytes) else fmt) != "empm snapshot":
                    fail(f"the snapshot file's format attribute is {fmt}")
                print(f"live.h5.snapshots/000000.h5 during the run: t = {f.attrs['time']}, "
                      f"{f.attrs['particles']} particles")
    finally:
        p.communicate(timeout=120)
    if p.returncode != 0 or os.path.exists(os.path.join(work, "live.h5.snapshots")):
        fail(f"the long run: status {p.returncode}, left {os.listdir(work)}")


def xdmf_fails(empm, cases, work):
    out, xmf = "xf.h5", os.path.join(work, "xf.xmf")
    a = start_long_run(empm, cases, work, out, "the folder could be made")
    # After the run's up-front checks: the XDMF file's final rename must fail.
    os.mkdir(xmf)
    with open(os.path.join(xmf, "keep"), "w") as f:
        f.write("x\n")
    a_out, a_err = a.communicate(timeout=120)
    print(f"run -> status {a.returncode}\n{a_out}{a_err}")
    if a.returncode != 4:
        fail(f"status {a.returncode}, expected 4")
    if "xf.xmf" not in a_err or ("Is a directory" not in a_err and
                                 "Directory not empty" not in a_err):
        fail("the message does not name the XDMF file and the system's reason")
    if a_err.count("error:") != 1 or "Backtrace" in a_err:
        fail("expected exactly one error line and no backtrace")
    if leftovers(work):
        fail(f"left behind: {leftovers(work)}")
    if os.listdir(xmf) != ["keep"]:
        fail(f"the folder at the XDMF path was changed: {os.listdir(xmf)}")
    check_complete(os.path.join(work, out))


def main():
    empm, cases, work, scenario = sys.argv[1:5]
    work = os.path.join(work, scenario)
    shutil.rmtree(work, ignore_errors=True)
    os.makedirs(work)
    {"concurrent": concurrent, "stale_lock": stale_lock, "fifo": fifo,
     "directory": directory, "disk_full": disk_full,
     "xdmf_fails": xdmf_fails, "snapshots": snapshots}[scenario](empm, cases, work)
    print("PASS")


if __name__ == "__main__":
    main()
