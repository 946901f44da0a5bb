#!/usr/bin/env python3
"""The peer of `empm bench --shape bspline2` (issue 17, item 3): a plain mpm88-style MLS-MPM
step in Taichi (quadratic B-splines, APIC transfers, float64, CPU backend) on the bench's own
block, timed the same way; prints one JSON object per run.

Usage: taichi_mpm88.py CELLS STEPS THREADS

The block: the unit square on a grid of CELLS² cells with one padding cell per side (as the
bench gives B-splines), 2 × 2 Gauss particles per cell, density 1000 kg/m³, moving with the
bench's standing-wave velocity (amplitude 0.1 m/s). The stress is mpm88's: a compressible
fluid with bulk modulus K = E/(3(1 − 2ν)) of the bench's E = 1e7 Pa, ν = 0.3, through the
volume ratio J (one scalar per particle, where empm carries the full stress, strain and F
and runs the two-pass pc_newmark scheme). Δt = half the CFL limit, as in the bench.
Run from the virtual environment `benchmarks/run --peers` makes (Taichi from PyPI).
"""
import json
import math
import sys
import time

import taichi as ti


def main():
    cells, steps, threads = (int(a) for a in sys.argv[1:4])
    ti.init(arch=ti.cpu, default_fp=ti.f64, cpu_max_num_threads=threads, offline_cache=True,
            log_level=ti.ERROR)
    pad = 1
    n_grid = cells + 2 * pad
    dx = 1.0 / cells
    inv_dx = 1.0 / dx
    n_particles = 4 * cells * cells
    rho, e_mod, nu = 1000.0, 1.0e7, 0.3
    bulk = e_mod / (3.0 * (1.0 - 2.0 * nu))
    c_p = math.sqrt(e_mod * (1 - nu) / ((1 + nu) * (1 - 2 * nu)) / rho)
    dt = 0.5 * dx / c_p
    p_vol = (dx * 0.5) ** 2
    p_mass = rho * p_vol

    x = ti.Vector.field(2, dtype=ti.f64, shape=n_particles)
    v = ti.Vector.field(2, dtype=ti.f64, shape=n_particles)
    C = ti.Matrix.field(2, 2, dtype=ti.f64, shape=n_particles)
    J = ti.field(dtype=ti.f64, shape=n_particles)
    grid_v = ti.Vector.field(2, dtype=ti.f64, shape=(n_grid, n_grid))
    grid_m = ti.field(dtype=ti.f64, shape=(n_grid, n_grid))

    @ti.kernel
    def init():
        g = 0.5 / ti.sqrt(3.0)
        for p in x:
            c = p // 4
            k = p % 4
            i, j = c % cells, c // cells
            px = (i + 0.5 + (k % 2 * 2 - 1) * g) * dx
            py = (j + 0.5 + (k // 2 * 2 - 1) * g) * dx
            x[p] = ti.Vector([px, py]) + pad * dx
            # the bench's standing wave, on the block's own coordinates
            v[p] = 0.1 * ti.Vector([ti.sin(2 * math.pi * px) * ti.sin(math.pi * py),
                                    ti.sin(math.pi * px) * ti.sin(2 * math.pi * py)])
            C[p] = ti.Matrix.zero(ti.f64, 2, 2)
            J[p] = 1.0

    @ti.kernel
    def substep():
        for i, j in grid_m:
            grid_v[i, j] = ti.Vector.zero(ti.f64, 2)
            grid_m[i, j] = 0.0
        for p in x:
            Xp = x[p] * inv_dx
            base = ti.cast(Xp - 0.5, ti.i32)
            fx = Xp - base
            w = [0.5 * (1.5 - fx) ** 2, 0.75 - (fx - 1) ** 2, 0.5 * (fx - 0.5) ** 2]
            stress = -dt * 4 * bulk * p_vol * (J[p] - 1) * inv_dx ** 2
            affine = ti.Matrix([[stress, 0.0], [0.0, stress]]) + p_mass * C[p]
            for i, j in ti.static(ti.ndrange(3, 3)):
                offset = ti.Vector([i, j])
                dpos = (offset - fx) * dx
                weight = w[i][0] * w[j][1]
                grid_v[base + offset] += weight * (p_mass * v[p] + affine @ dpos)
                grid_m[base + offset] += weight * p_mass
        for i, j in grid_m:
            if grid_m[i, j] > 0:
                grid_v[i, j] /= grid_m[i, j]
        for p in x:
            Xp = x[p] * inv_dx
            base = ti.cast(Xp - 0.5, ti.i32)
            fx = Xp - base
            w = [0.5 * (1.5 - fx) ** 2, 0.75 - (fx - 1) ** 2, 0.5 * (fx - 0.5) ** 2]
            new_v = ti.Vector.zero(ti.f64, 2)
            new_C = ti.Matrix.zero(ti.f64, 2, 2)
            for i, j in ti.static(ti.ndrange(3, 3)):
                offset = ti.Vector([i, j])
                dpos = (offset - fx) * dx
                weight = w[i][0] * w[j][1]
                g_v = grid_v[base + offset]
                new_v += weight * g_v
                new_C += 4 * weight * g_v.outer_product(dpos) * inv_dx ** 2
            v[p] = new_v
            x[p] += dt * v[p]
            J[p] *= 1 + dt * new_C.trace()
            C[p] = new_C

    init()
    for _ in range(3):  # compile and warm up, as the bench's warm-up steps
        substep()
    ti.sync()
    t0 = time.perf_counter()
    for _ in range(steps):
        substep()
    ti.sync()
    seconds = time.perf_counter() - t0
    print(json.dumps({"peer": "taichi_mpm88", "taichi": ti.__version__, "cells": cells,
                      "particles": n_particles, "steps": steps, "threads": threads,
                      "seconds": seconds,
                      "particle_steps_per_second": n_particles * steps / seconds}))


if __name__ == "__main__":
    main()
