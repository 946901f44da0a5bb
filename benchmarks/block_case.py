#!/usr/bin/env python3
"""Write the block of `empm bench` as a case file, for timing `empm run` on it.

Usage: block_case.py FILE DIM SHAPE CELLS PPC STEPS

The grid, its padding (one cell on every side for uniform B-splines and uGIMP, none for
linear and LME shapes, as in the bench), the particles (PPC Gauss positions per direction and cell of the unit box), the
material (linear elastic, E = 1e7 Pa, nu = 0.3, rho = 1000 kg/m3) and the Courant number 0.5
are those of `empm bench`; the initial velocity is a plane sine wave of the bench's amplitude
0.1 m/s (a case file cannot state the bench's product of sines). t_end gives STEPS steps, the
last one cut short. The output goes next to FILE, with the defaults of `&output`.
"""
import math
import sys


def main():
    path, dim, shape, cells, ppc, steps = sys.argv[1:7]
    dim, cells, ppc, steps = int(dim), int(cells), int(ppc), int(steps)
    h = 1.0 / cells
    e, nu, rho = 1.0e7, 0.3, 1000.0
    c = math.sqrt(e * (1 - nu) / ((1 + nu) * (1 - 2 * nu)) / rho)  # P-wave speed [m/s]
    t_end = (steps - 0.5) * 0.5 * h / c

    def vec(v):
        return ', '.join([repr(v)] * dim)

    family, gamma = shape, ''
    if shape.startswith('lme_g'):
        family, gamma = 'lme', f', gamma = {shape[5:]}'
    pad = 1 if family in ('bspline2', 'bspline3', 'ugimp') else 0
    lines = [
        '! Written by benchmarks/block_case.py: the block of `empm bench` as a case file.',
        '&grid',
        f'  ndim = {dim}, origin = {vec(-pad * h)}, h = {h!r}, cells = '
        + ', '.join([str(cells + 2 * pad)] * dim),
        '/',
        '&material',
        f"  name = 'block', model = 'linear_elastic', E = {e!r}, nu = {nu!r}, density = {rho!r}",
        '/',
        '&particles',
        f"  material = 'block', geometry = 'box', lo = {vec(0.0)}, hi = {vec(1.0)}, "
        f"ppc = {ppc}, placement = 'gauss'",
        f'  velocity_sine_amplitude = {vec(0.1)}, velocity_sine_wavenumber = {vec(math.pi)}',
        '/',
        '&shape',
        f"  family = '{family}'{gamma}",
        '/',
        '&integrator',
        f"  scheme = 'pc_newmark', cfl = 0.5, t_end = {t_end!r}",
        '/',
        '&output',
        f"  file = '{path[:-4] if path.endswith('.nml') else path}.h5'",
        '/',
    ]
    with open(path, 'w') as f:
        f.write('\n'.join(lines) + '\n')


if __name__ == '__main__':
    main()
