#!/usr/bin/python3
"""Plot reports/integrators/stability.h5 (benchmarks/stability_curves.f90) as stability.png.

Three panels over Omega = omega*dt (= CFL on the one-cell oscillator): spectral radius,
numerical damping ratio of the principal root and relative period error (T_bar - T)/T.
Solid lines: particle at the cell centre (the MPM scheme); the dashed grey line is gen_alpha_grid
rho_b = 0.8 with the particle on the node, i.e. Hulbert & Chung's nodal scheme. Damping and
period are drawn only where the principal complex pair exists and the scheme is stable.

Usage: /usr/bin/python3 plot_stability.py [stability.h5] [stability.png]
"""
import os
import sys

import h5py
import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from scheme_style import STYLE  # noqa: E402  (same folder as this script)

HERE = os.path.dirname(os.path.abspath(__file__))


def curves(group):
    """Omega, rho, and the masked xi and period error of one scheme group."""
    om = group["omega"][()]
    rho = group["rho"][()]
    ok = (group["oscillatory"][()] == 1) & (om <= group.attrs["omega_crit"])
    xi = np.where(ok, group["xi"][()], np.nan)
    pe = np.where(ok, group["period_error"][()], np.nan)
    return om, rho, xi, pe


def main():
    src = sys.argv[1] if len(sys.argv) > 1 else os.path.join(HERE, "stability.h5")
    dst = sys.argv[2] if len(sys.argv) > 2 else os.path.join(HERE, "stability.png")
    fig, ax = plt.subplots(1, 3, figsize=(16, 6.0))
    with h5py.File(src, "r") as f:
        osc = f["oscillator"]
        for name in STYLE:
            if name not in osc:
                continue
            g = osc[name]
            om, rho, xi, pe = curves(g)
            colour, ls = STYLE[name]
            label = f"{name} ($\\Omega_c$ = {g.attrs['omega_crit']:.3f})"
            ax[0].plot(om, rho, color=colour, ls=ls, lw=1.4, label=label)
            ax[1].plot(om, xi, color=colour, ls=ls, lw=1.4)
            ax[2].plot(om, pe, color=colour, ls=ls, lw=1.4)
        node = f["oscillator_node"]
        if "gen_alpha_grid_rb0.8" in node:
            g = node["gen_alpha_grid_rb0.8"]
            om, rho, xi, pe = curves(g)
            label = (f"gen_alpha_grid $\\rho_b$=0.8, particle on node = Hulbert-Chung "
                     f"($\\Omega_c$ = {g.attrs['omega_crit']:.3f})")
            ax[0].plot(om, rho, color="grey", ls="--", lw=1.2, label=label)
            ax[1].plot(om, xi, color="grey", ls="--", lw=1.2)
            ax[2].plot(om, pe, color="grey", ls="--", lw=1.2)
    ax[0].axhline(1.0, color="k", lw=0.6)
    ax[0].set_ylim(0.0, 1.3)
    ax[0].set_ylabel(r"spectral radius $\rho$")
    ax[1].set_ylim(-0.02, 0.6)
    ax[1].set_ylabel(r"damping ratio $\bar\xi$")
    ax[2].set_ylim(-0.5, 0.05)
    ax[2].set_ylabel(r"period error $(\bar T - T)/T$")
    for a in ax:
        a.set_xlim(0.0, 2.5)
        a.set_xlabel(r"$\Omega = \omega\Delta t$ (= CFL, $\omega = c/h$)")
        a.grid(alpha=0.3)
    handles, labels = ax[0].get_legend_handles_labels()
    fig.legend(handles, labels, loc="lower center", ncol=4, fontsize=8, frameon=False)
    fig.suptitle("One-cell oscillator (1 particle at the cell centre, linear shape functions): "
                 "amplification matrices of the empm integrators", fontsize=11)
    fig.tight_layout(rect=(0.0, 0.12, 1.0, 1.0))
    fig.savefig(dst, dpi=110)
    print("wrote", dst)


if __name__ == "__main__":
    main()
