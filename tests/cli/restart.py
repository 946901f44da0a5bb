#!/usr/bin/python3
"""Checkpoint and restart of `empm run` (one scenario per call; CTest runs each):

  matrix    every integrator x every shape family (2D, 144 particles), and 1D and 3D cases:
            a run writing checkpoints every k steps, then a restart from the one before the
            last; every dataset of the restarted run's results equals the uninterrupted run's,
            bitwise.
  threads   the same with 2 threads on 4,096+ particles (the P2G sums are threaded), for
            linear and LME shapes with two integrators; and 1 thread, for comparison.
  geotech   Mohr-Coulomb with state variables, gravity, a surface traction with a ramp, local
            damping, volumetric smoothing and a named boundary (residual and reactions).
  sigkill   a run killed with SIGKILL at a random moment (fixed seed): the checkpoint left
            is whole and at most one interval old, and the restart from it ends bitwise as
            the uninterrupted run.
  signals   SIGINT and SIGTERM: exit 130 / 143, a checkpoint and the results so far (marked
            incomplete) written; the restart completes bitwise.
  seconds   checkpoints by wall time (checkpoint_seconds): written during the run, and the
            restart from the one before the last is bitwise.
  guard     a guard stop after more steps than the kept copy spans (the solver keeps the state
            every 128 steps and replays the steps since): the last good state written equals,
            bitwise, the state of the same run stopped before the failing step by max_steps.
  refuse    a checkpoint of another case file (one value changed), of another version, a
            damaged one, a results file and a missing file: each refused with status 2 and
            the reason.

usage: restart.py EMPM WORK_DIR SCENARIO
Exit 0 pass, 1 fail.
"""
import os
import random
import shutil
import signal
import subprocess
import sys
import time

import h5py
import numpy as np

SCHEMES = ["usf", "usl", "musl", "pc_published", "pc_newmark", "gen_alpha_grid", "gen_alpha"]
SHAPES = ["linear", "ugimp", "bspline2", "lme_g3"]

CASE_2D = """&grid ndim = 2, origin = -0.5, -0.5, h = 0.25, cells = {cells}, {cells} /
&shape family = '{shape}' /
&material name = 'm', model = 'linear_elastic', E = 1.0e4, nu = 0.3, density = 1.0 /
&particles material = 'm', geometry = 'box', lo = 0.5, 0.5, hi = {hi}, {hi}, ppc = 2,
  velocity = 0.1, 0.05 /
&integrator scheme = '{scheme}', t_end = {t_end} /
&boundary lo = -0.5, -0.5, hi = 3.0, 0.0, fix = .true., .true. /
&probe name = 'c', point = 1.0, 1.0 /
&output checkpoint_every = {every}, snapshot_times = {snaps} /
"""

CASE_1D = """&grid ndim = 1, origin = -1.0, h = 0.5, cells = 30 /
&shape family = '{shape}' /
&material name = 'm', model = 'linear_elastic', E = 100.0, density = 1.0 /
&particles material = 'm', geometry = 'interval', lo = 0.0, hi = 10.0, ppc = 2,
  velocity_sine_amplitude = 0.5, velocity_sine_wavenumber = 0.15707963267948966 /
&integrator scheme = '{scheme}', t_end = 3.0 /
&boundary lo = -1.0, hi = 0.0, fix = .true. /
&probe name = 'end', point = 10.0 /
&output checkpoint_every = 40, snapshot_times = 1.0, 2.0 /
"""

CASE_3D = """&grid ndim = 3, origin = -0.5, -0.5, -0.5, h = 0.5, cells = 8, 8, 8 /
&shape family = '{shape}' /
&material name = 'm', model = 'neohookean', E = 1.0e3, nu = 0.3, density = 1.0 /
&particles material = 'm', geometry = 'box', lo = 0.5, 0.5, 0.5, hi = 2.0, 2.0, 2.0, ppc = 2,
  velocity = 0.2, -0.1, 0.3 /
&integrator scheme = '{scheme}', t_end = 0.3 /
&probe name = 'c', point = 1.0, 1.0, 1.0 /
&output checkpoint_every = 10, snapshot_times = 0.1 /
"""

CASE_GEOTECH = """&grid ndim = 2, origin = -0.25, -0.25, h = 0.25, cells = 18, 12 /
&shape family = '{shape}' /
&material name = 'sand', model = 'mohr_coulomb', density = 1800.0, E = 2.0e6, nu = 0.3,
  cohesion = 2.0e3, friction_angle = 30.0, dilatancy_angle = 5.0 /
&particles name = 'layer', material = 'sand', geometry = 'box', lo = 0.0, 0.0, hi = 4.0, 2.0,
  ppc = 2, geostatic = .true., k0 = 0.5 /
&loads gravity = 0.0, -9.81 /
&traction body = 'layer', lo = 0.0, 1.88, hi = 1.0, 2.0, face = '+y', pressure = 8.0e4,
  ramp = 'linear', ramp_time = 0.05 /
&integrator scheme = '{scheme}', t_end = 0.3, damping = 0.05, volumetric_smoothing = .true. /
&boundary name = 'base', lo = -0.25, -0.25, hi = 4.25, 0.0, fix = .true., .true. /
&boundary lo = -0.25, -0.25, hi = 0.0, 2.75, fix = .true., .false. /
&boundary lo = 4.0, -0.25, hi = 4.25, 2.75, fix = .true., .false. /
&probe name = 'top', point = 0.5, 2.0 /
&output checkpoint_every = 20, snapshot_times = 0.04 /
"""


def fail(msg):
    print("FAIL: " + msg)
    sys.exit(1)


def run(empm, args, work, threads=1, check=None, **kw):
    env = dict(os.environ, OMP_NUM_THREADS=str(threads))
    p = subprocess.run([empm, "run"] + args, cwd=work, capture_output=True, text=True,
                       errors="replace", timeout=600, env=env, **kw)
    if check is not None and p.returncode != check:
        print(p.stdout + p.stderr)
        fail(f"empm run {' '.join(args)}: status {p.returncode}, expected {check}")
    return p


def differences(a_path, b_path):
    """Names of the datasets that differ (values, shape or presence) between two files."""
    bad = []
    with h5py.File(a_path, "r") as a, h5py.File(b_path, "r") as b:
        names = []
        a.visititems(lambda n, o: names.append(n) if isinstance(o, h5py.Dataset) else None)
        other = []
        b.visititems(lambda n, o: other.append(n) if isinstance(o, h5py.Dataset) else None)
        bad += [f"{n} (only in {b_path})" for n in sorted(set(other) - set(names))]
        for n in names:
            if n not in b:
                bad.append(f"{n} (only in {a_path})")
                continue
            x, y = a[n][()], b[n][()]
            if x.shape != y.shape or not np.array_equal(x, y, equal_nan=True):
                bad.append(n)
        for k in ("complete", "status"):
            if a.attrs.get(k) != b.attrs.get(k):
                bad.append(f"attribute {k}")
        return len(names), bad


def restart_equals(empm, work, name, text, threads=1, ckpt="prev"):
    """Run `text` through, then restart it from its previous checkpoint; compare bitwise."""
    case = os.path.join(work, name + ".nml")
    with open(case, "w") as f:
        f.write(text)
    out = name + ".h5"
    run(empm, [case, "-o", out], work, threads, check=0)
    ref = os.path.join(work, name + ".ref.h5")
    shutil.copy(os.path.join(work, out), ref)
    src = os.path.join(work, name + (".ckpt.h5" if ckpt == "last" else ".ckpt.prev.h5"))
    if not os.path.exists(src) and ckpt == "any":
        src = os.path.join(work, name + ".ckpt.h5")
    if not os.path.exists(src):
        fail(f"{name}: no checkpoint {src} was written")
    start = os.path.join(work, name + ".start.h5")
    shutil.copy(src, start)
    with h5py.File(start, "r") as f:
        step = int(f["model/scalars"][1])
    run(empm, [case, "-o", out, "--restart", start], work, threads, check=0)
    n, bad = differences(ref, os.path.join(work, out))
    print(f"{name}: restart from step {step}: {n} datasets, {len(bad)} differ {bad[:6]}")
    if bad:
        fail(f"{name}: the restarted run differs from the uninterrupted one: {bad[:6]}")
    if step <= 0:
        fail(f"{name}: the checkpoint is at step {step}")


def matrix(empm, work):
    for scheme in SCHEMES:
        for shape in SHAPES:
            restart_equals(empm, work, f"m_{scheme}_{shape}", CASE_2D.format(
                cells=14, shape=shape, scheme=scheme, hi=2.0, t_end=0.4, every=40,
                snaps="0.1, 0.2"))
    restart_equals(empm, work, "d1_pc_lme", CASE_1D.format(shape="lme_g3", scheme="pc_newmark"))
    restart_equals(empm, work, "d1_ga_ugimp", CASE_1D.format(shape="ugimp", scheme="gen_alpha_grid"))
    restart_equals(empm, work, "d3_pc_lme", CASE_3D.format(shape="lme_g3", scheme="pc_newmark"))
    restart_equals(empm, work, "d3_musl_linear",
                   CASE_3D.format(shape="linear", scheme="musl"))


def threads(empm, work):
    # 64 x 64 particles (4,096: the threshold of the threaded particle loops).
    for nt in (1, 2):
        for scheme, shape in (("pc_newmark", "linear"), ("gen_alpha_grid", "lme_g3")):
            restart_equals(empm, work, f"t{nt}_{scheme}_{shape}", CASE_2D.format(
                cells=44, shape=shape, scheme=scheme, hi=8.5, t_end=0.02, every=8,
                snaps="0.01"), threads=nt)


def geotech(empm, work):
    for scheme, shape in (("musl", "linear"), ("pc_newmark", "lme_g3")):
        restart_equals(empm, work, f"g_{scheme}_{shape}",
                       CASE_GEOTECH.format(shape=shape, scheme=scheme))


def long_case(work, every=100):
    # A long run must stay physical: at v0 = 0.5 the particles cross cells and linear MPM's
    # energy grows (+78 % over 600 s, until a particle leaves the grid); at 0.05 it is conserved
    # to 1e-4.
    case = os.path.join(work, "long.nml")
    with open(case, "w") as f:
        f.write(CASE_1D.format(shape="linear", scheme="pc_newmark")
                .replace("velocity_sine_amplitude = 0.5", "velocity_sine_amplitude = 0.05")
                .replace("t_end = 3.0", "t_end = 600.0")
                .replace("checkpoint_every = 40", f"checkpoint_every = {every}")
                .replace("snapshot_times = 1.0, 2.0",
                         "snapshot_times = " + ", ".join(str(50.0 * k) for k in range(1, 12))))
    return case


def reference(empm, work, case):
    run(empm, [case, "-o", "ref.h5"], work, check=0)
    for f in ("ref.ckpt.h5", "ref.ckpt.prev.h5"):
        os.remove(os.path.join(work, f))
    return os.path.join(work, "ref.h5")


def wait_started(proc, work, out, least=0.3):
    lock = os.path.join(work, out + ".lock")
    t0 = time.time()
    while not os.path.exists(os.path.join(work, out.replace(".h5", ".ckpt.h5"))) and \
            proc.poll() is None and time.time() - t0 < 60:
        time.sleep(0.01)
    time.sleep(least)
    if proc.poll() is not None or not os.path.exists(lock):
        fail("the run ended before it could be interrupted (case too short)")


def sigkill(empm, work):
    every = 100
    case = long_case(work, every)
    ref = reference(empm, work, case)
    rnd = random.Random(20261124)
    for trial in range(2):
        for f in os.listdir(work):
            if f.startswith("k.") or f.startswith("k.h5"):
                path = os.path.join(work, f)
                shutil.rmtree(path) if os.path.isdir(path) else os.remove(path)
        p = subprocess.Popen([empm, "run", case, "-o", "k.h5"], cwd=work,
                             stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                             env=dict(os.environ, OMP_NUM_THREADS="1"))
        wait_started(p, work, "k.h5", least=rnd.uniform(0.05, 0.5))
        p.send_signal(signal.SIGKILL)
        p.communicate()
        ck = os.path.join(work, "k.ckpt.h5")
        if not os.path.exists(ck):
            ck = os.path.join(work, "k.ckpt.prev.h5")  # killed between the two renames
        with h5py.File(ck, "r") as f:
            step = int(f["model/scalars"][1])
        if step % every != 0:
            fail(f"the checkpoint left is at step {step}, not a multiple of {every}")
        # A killed run leaves its lock and partial files, and the snapshots taken so far in
        # their own files (the restart copies them into its results); the lock of a dead
        # process is taken over by the restart.
        staged = os.path.join(work, "k.h5.snapshots")
        taken = sorted(os.listdir(staged)) if os.path.isdir(staged) else []
        if not taken or taken[0] != "000000.h5":
            fail(f"the killed run left no snapshot files in {staged}: {taken}")
        run(empm, [case, "-o", "k.h5", "--restart", ck], work, check=0)
        if os.path.exists(staged):
            fail(f"the restarted run left {staged}: {os.listdir(staged)}")
        n, bad = differences(ref, os.path.join(work, "k.h5"))
        print(f"SIGKILL trial {trial}: checkpoint at step {step}; {n} datasets, "
              f"{len(bad)} differ")
        if bad:
            fail(f"restart after SIGKILL differs: {bad[:6]}")


def signals(empm, work):
    case = long_case(work)
    ref = reference(empm, work, case)
    for sig, status in ((signal.SIGINT, 130), (signal.SIGTERM, 143)):
        out = f"s{status}.h5"
        p = subprocess.Popen([empm, "run", case, "-o", out], cwd=work, stdout=subprocess.PIPE,
                             stderr=subprocess.PIPE, text=True,
                             env=dict(os.environ, OMP_NUM_THREADS="1"))
        wait_started(p, work, out)
        p.send_signal(sig)
        o, e = p.communicate(timeout=120)
        print(f"{sig.name} -> status {p.returncode}\n{o}{e}")
        if p.returncode != status:
            fail(f"{sig.name}: status {p.returncode}, expected {status}")
        if f"stopped by {sig.name}" not in e or "--restart" not in e:
            fail(f"{sig.name}: the message does not say what happened and how to continue")
        with h5py.File(os.path.join(work, out), "r") as f:
            if int(f.attrs["complete"]) != 0:
                fail(f"{sig.name}: the results so far are not marked incomplete")
        ck = os.path.join(work, f"s{status}.ckpt.h5")
        run(empm, [case, "-o", out, "--restart", ck], work, check=0)
        n, bad = differences(ref, os.path.join(work, out))
        print(f"{sig.name}: restarted; {n} datasets, {len(bad)} differ")
        if bad:
            fail(f"{sig.name}: the restarted run differs: {bad[:6]}")


def seconds(empm, work):
    text = (CASE_1D.format(shape="linear", scheme="pc_newmark")
            .replace("t_end = 3.0", "t_end = 300.0")
            .replace("checkpoint_every = 40", "checkpoint_every = 0, checkpoint_seconds = 0.05"))
    # By wall time: how many are written depends on the machine; the one before the last when
    # there are two, else the last.
    restart_equals(empm, work, "wall", text, ckpt="any")


def guard(empm, work):
    # A bar thrown towards the end of its grid: it leaves it after about 300 steps.
    text = """&grid ndim = 1, h = 0.05, cells = 60 /
&shape family = '{shape}' /
&material name = 'm', model = 'linear_elastic', E = 100.0, density = 1.0 /
&particles material = 'm', geometry = 'interval', lo = 0.0, hi = 1.0, ppc = 2, velocity = 0.1 /
&integrator scheme = '{scheme}', t_end = 100.0{cap} /
&probe name = 'end', point = 1.0 /
"""
    for shape, scheme in (("linear", "pc_newmark"), ("lme_g3", "musl")):
        case = os.path.join(work, f"g_{shape}.nml")
        with open(case, "w") as f:
            f.write(text.format(shape=shape, scheme=scheme, cap=""))
        p = run(empm, [case, "-o", f"g_{shape}.h5"], work, check=3)
        if "left the grid" not in p.stderr:
            fail(f"{shape}: expected a particle leaving the grid: {p.stderr}")
        with h5py.File(os.path.join(work, f"g_{shape}.h5"), "r") as f:
            t_last = float(f["history/time"][-1])
            steps = int(f["final"].attrs["step"]) if "step" in f["final"].attrs else None
        if steps is None:
            # The step of the last good state: from the failing step in the message.
            steps = int(p.stderr.split("step ")[1].split(":")[0]) - 1
        if steps <= 128:
            fail(f"{shape}: the guard tripped at step {steps + 1}, within the first kept copy")
        capped = os.path.join(work, f"c_{shape}.nml")
        with open(capped, "w") as f:
            f.write(text.format(shape=shape, scheme=scheme, cap=f", max_steps = {steps}"))
        p2 = run(empm, [capped, "-o", f"c_{shape}.h5"], work, check=3)
        if "step cap" not in p2.stderr:
            fail(f"{shape}: the capped run did not stop at its cap: {p2.stderr}")
        a, b = os.path.join(work, f"g_{shape}.h5"), os.path.join(work, f"c_{shape}.h5")
        with h5py.File(a, "r") as fa, h5py.File(b, "r") as fb:
            bad = [k for k in fa["final"] if isinstance(fa["final"][k], h5py.Dataset)
                   and not np.array_equal(fa["final"][k][()], fb["final"][k][()])]
        print(f"guard {shape}/{scheme}: last good state after step {steps} (t = {t_last}); "
              f"{len(bad)} final datasets differ from the capped run")
        if bad:
            fail(f"{shape}: the last good state differs from the state at step {steps}: {bad}")


def refuse(empm, work):
    case = os.path.join(work, "r.nml")
    text = CASE_1D.format(shape="linear", scheme="pc_newmark")
    with open(case, "w") as f:
        f.write(text)
    run(empm, [case, "-o", "r.h5"], work, check=0)
    ck = os.path.join(work, "r.ckpt.h5")

    def refused(args, words, label):
        p = run(empm, args, work)
        print(f"{label} -> status {p.returncode}: {p.stderr.strip()}")
        if p.returncode != 2:
            fail(f"{label}: status {p.returncode}, expected 2")
        for w in words:
            if w not in p.stderr:
                fail(f"{label}: the message lacks '{w}'")
        if p.stderr.count("error:") != 1 or "HDF5-DIAG" in p.stderr:
            fail(f"{label}: expected one error line and no HDF5 error stack")

    other = os.path.join(work, "other.nml")
    with open(other, "w") as f:
        f.write(text.replace("E = 100.0", "E = 120.0"))
    refused([other, "-o", "o.h5", "--restart", ck], ["another case file", "line 3",
                                                     "E = 120.0"], "another case")
    old = os.path.join(work, "old.h5")
    shutil.copy(ck, old)
    with h5py.File(old, "r+") as f:
        f.attrs["empm_version"] = np.bytes_("0.0.1")
    refused([case, "-o", "o.h5", "--restart", old], ["written by empm 0.0.1"], "other version")
    damaged = os.path.join(work, "damaged.h5")
    with open(ck, "rb") as f:
        data = f.read()
    with open(damaged, "wb") as f:
        f.write(data[: len(data) // 3])
    refused([case, "-o", "o.h5", "--restart", damaged], ["cannot restart"], "damaged")
    refused([case, "-o", "o.h5", "--restart", os.path.join(work, "r.h5")],
            ["not an empm checkpoint"], "results file")
    refused([case, "-o", "o.h5", "--restart", os.path.join(work, "none.h5")],
            ["no such file"], "missing")
    # The checkpoint names its snapshots: gone from their folder (the run ended) and from the
    # results, the restart is refused naming both.
    if os.path.exists(os.path.join(work, "r.h5.snapshots")):
        fail("the completed run left its snapshot folder r.h5.snapshots")
    os.rename(os.path.join(work, "r.h5"), os.path.join(work, "r.moved.h5"))
    refused([case, "-o", "o.h5", "--restart", ck], ["snapshot 0", "r.h5.snapshots/000000.h5",
                                                     "is missing", "r.h5"], "snapshots lost")
    os.rename(os.path.join(work, "r.moved.h5"), os.path.join(work, "r.h5"))
    # Another case run on the same output since: its snapshots are not this case's.
    keep = os.path.join(work, "r.keep.ckpt.h5")
    shutil.copy(ck, keep)
    run(empm, [other, "-o", "r.h5"], work, check=0)
    refused([case, "-o", "o.h5", "--restart", keep], ["snapshot 0", "another case file"],
            "snapshots of another case")
    if os.path.exists(os.path.join(work, "o.h5")):
        fail("a refused restart wrote results")


def main():
    empm, work, scenario = sys.argv[1:4]
    work = os.path.join(work, scenario)
    shutil.rmtree(work, ignore_errors=True)
    os.makedirs(work)
    {"matrix": matrix, "threads": threads, "geotech": geotech, "sigkill": sigkill,
     "signals": signals, "seconds": seconds, "guard": guard,
     "refuse": refuse}[scenario](empm, work)
    print("PASS")


if __name__ == "__main__":
    main()
