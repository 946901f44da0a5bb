#!/usr/bin/python3
"""Plot reports/integrators/energy.h5 (benchmarks/energy_histories.f90) as energy.png.

Rows: the vibrating bar (CFL 0.5, 4 periods), the colliding disks at CFL 0.1 and at CFL 0.5.
Columns: total, kinetic and strain energy, each divided by the initial total energy, against
time (the bar: t/T). A run stopped by a solver guard ends with a cross.

Usage: /usr/bin/python3 plot_energy.py [energy.h5] [energy.png]
"""
import os
import sys

import h5py
import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

from scheme_style import STYLE  # noqa: E402  (same folder as this script)

HERE = os.path.dirname(os.path.abspath(__file__))
ROWS = [
    ("vibrating_bar", "vibrating bar, h = 1, CFL 0.5", 10.0, "t / T"),
    ("colliding_disks_cfl0.1", "colliding disks, CFL 0.1", 1.0, "t [s]"),
    ("colliding_disks_cfl0.5", "colliding disks, CFL 0.5", 1.0, "t [s]"),
]
COLS = [("total", "total"), ("kinetic", "kinetic"), ("strain", "strain")]


def main():
    src = sys.argv[1] if len(sys.argv) > 1 else os.path.join(HERE, "energy.h5")
    dst = sys.argv[2] if len(sys.argv) > 2 else os.path.join(HERE, "energy.png")
    fig, ax = plt.subplots(len(ROWS), len(COLS), figsize=(16, 12.5))
    with h5py.File(src, "r") as f:
        for r, (case, title, tscale, tlabel) in enumerate(ROWS):
            if case not in f:
                continue
            for name, (colour, ls) in STYLE.items():
                if name not in f[case]:
                    continue
                g = f[case][name]
                t = g["t"][()] / tscale
                e0 = g["total"][0]
                for c, (key, _) in enumerate(COLS):
                    y = g[key][()] / e0
                    ax[r, c].plot(t, y, color=colour, ls=ls, lw=1.1,
                                  label=name if (r, c) == (0, 0) else None)
                    if g.attrs["completed"] == 0:
                        ax[r, c].plot(t[-1], y[-1], "x", color=colour, ms=8, mew=2)
            for c, (_, what) in enumerate(COLS):
                ax[r, c].set_title(f"{title}: {what} energy / E(0)", fontsize=10)
                ax[r, c].set_xlabel(tlabel)
                ax[r, c].grid(alpha=0.3)
        ax[0, 0].set_ylim(0.6, 1.05)
        for r in (1, 2):
            ax[r, 0].set_ylim(0.4, 1.6)
    handles, labels = ax[0, 0].get_legend_handles_labels()
    fig.legend(handles, labels, loc="lower center", ncol=5, fontsize=9, frameon=False)
    fig.suptitle("Energy histories of the empm integrators (x: run stopped by a solver guard)",
                 fontsize=12)
    fig.tight_layout(rect=(0.0, 0.05, 1.0, 0.97))
    fig.savefig(dst, dpi=100)
    print("wrote", dst)


if __name__ == "__main__":
    main()
