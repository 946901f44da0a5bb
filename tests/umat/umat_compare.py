#!/usr/bin/python3
"""Run a reference case and a UMAT case with empm and compare their final states.

usage: umat_compare.py EMPM REF.nml TEST.nml WORKDIR --tol T [--threads N]
                       [--expect NAME OP VALUE ...] [--match NAME REFNAME ...]

The fields final/stress, final/x and final/v of the two outputs must agree to T relative to the
largest magnitude of the reference field: max|a - b| <= T max|a|. Each --expect checks a state
variable of the UMAT run: NAME (a dataset under final/state, e.g. umat_cuts), OP one of
  'eq'      every particle's value equals VALUE (VALUE 'steps' = the final step number,
            'time' = the final time; compared to 1e-12 relative)
  'maxgt'   the largest value exceeds VALUE
Each --match compares the UMAT run's final/state/NAME (e.g. statev1) with the reference run's
final/state/REFNAME (e.g. eps_p_eq) to T relative to max|REFNAME| (which must be > 0: the check
is meant for a variable that evolved).
Exit status 0 when every check passes, 1 otherwise (the figures are printed either way).
"""
import subprocess
import sys
import os
import numpy as np
import h5py


def run(empm, case, out, threads):
    args = [empm, 'run', case, '-o', out]
    if threads:
        args += ['--threads', str(threads)]
    r = subprocess.run(args, capture_output=True, text=True)
    sys.stdout.write(r.stdout + r.stderr)
    if r.returncode != 0:
        print(f'FAIL: {case} exited with status {r.returncode}')
        sys.exit(1)


def main(argv):
    empm, ref, test, work = argv[1:5]
    rest = argv[5:]
    tol, threads, expects, matches = None, None, [], []
    i = 0
    while i < len(rest):
        if rest[i] == '--tol':
            tol = float(rest[i + 1]); i += 2
        elif rest[i] == '--threads':
            threads = int(rest[i + 1]); i += 2
        elif rest[i] == '--expect':
            expects.append(rest[i + 1:i + 4]); i += 4
        elif rest[i] == '--match':
            matches.append(rest[i + 1:i + 3]); i += 3
        else:
            print(f'unknown argument {rest[i]}'); return 1
    os.makedirs(work, exist_ok=True)
    name = os.path.splitext(os.path.basename(test))[0]
    a_path = os.path.join(work, name + '.ref.h5')
    b_path = os.path.join(work, name + '.h5')
    run(empm, ref, a_path, None)
    run(empm, test, b_path, threads)
    ok = True
    with h5py.File(a_path, 'r') as a, h5py.File(b_path, 'r') as b:
        if a['final'].attrs['step'] != b['final'].attrs['step']:
            print(f"FAIL: steps {a['final'].attrs['step']} vs {b['final'].attrs['step']}")
            ok = False
        for f in ('stress', 'x', 'v'):
            A = a['final/' + f][()]
            B = b['final/' + f][()]
            scale = np.abs(A).max()
            err = np.abs(A - B).max() / scale if scale > 0 else np.abs(B).max()
            good = A.shape == B.shape and err <= tol
            ok = ok and good
            print(f"{'ok  ' if good else 'FAIL'} final/{f}: relative difference {err:.3e} "
                  f'(tolerance {tol:.1e})')
        for var, ref in matches:
            A = a['final/state/' + ref][()]
            B = b['final/state/' + var][()]
            scale = np.abs(A).max()
            err = np.abs(A - B).max() / scale if scale > 0 else np.inf
            good = A.shape == B.shape and err <= tol
            ok = ok and good
            print(f"{'ok  ' if good else 'FAIL'} state/{var} vs reference state/{ref} "
                  f'(largest {scale:.3e}, {int((A != 0).sum())} of {A.size} nonzero): '
                  f'relative difference {err:.3e} (tolerance {tol:.1e})')
        steps = float(b['final'].attrs['step'])
        time = float(b['final'].attrs['time'])
        for var, op, value in expects:
            v = b['final/state/' + var][()]
            if op == 'eq':
                target = {'steps': steps, 'time': time}.get(value)
                target = float(value) if target is None else target
                dev = np.abs(v - target).max()
                good = bool(dev <= 1e-12 * max(1.0, abs(target)))
                print(f"{'ok  ' if good else 'FAIL'} state/{var} == {target:.15g}: largest "
                      f'deviation {dev:.3e}')
            elif op == 'maxgt':
                good = bool(v.max() > float(value))
                print(f"{'ok  ' if good else 'FAIL'} max state/{var} = {v.max():.15g} > {value} "
                      f'({int((v > float(value)).sum())} of {v.size} particles)')
            else:
                print(f'unknown check {op}'); good = False
            ok = ok and good
    print('all checks passed' if ok else 'some checks FAILED')
    return 0 if ok else 1


if __name__ == '__main__':
    sys.exit(main(sys.argv))
