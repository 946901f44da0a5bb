#!/usr/bin/python3
"""Cost model of a parallel empm step (docs/parallel.md, issue 18 item 6): strong and weak
scaling to 1,024 processes of a 3D LME case with 1e8 particles, for the block-local design
(each process its box of cells plus ghost node layers, shared nodes summed with its 26
neighbours), from a measured per-particle cost and the network figures of a typical cluster.
It models the block-local design with ghost layers as deep as the family's support; the last
two columns compare today's design (each process stores a window of the grid, its region -- the
nodes its particles reach widened by the margin of docs/parallel.md -- plus 4 to 8 spare nodes
a side, passes over it at 25 ns a node-step in 3D (`--node-pass-ns`), and exchanges the nodal
sums over the regions' overlaps) and the all-reduce of whole nodal arrays with every process
passing over the whole grid, two designs before it.

Usage: mpi_cost_model.py [--alpha-us 1.5] [--gbytes 12.5] [--node-lme 0.85]
       [--node-linear 0.77] [--imbalance 1.05] [--node-pass-ns 25]
  --alpha-us  message latency [us]; --gbytes link bandwidth [GB/s] (InfiniBand HDR100-class)
  --node-lme, --node-linear
              a process's speed when every core of its node is busy, over its speed alone,
              measured by benchmarks/mpi_scaling.py (2 processes on this 2-core machine, weak,
              2.6e5 particles each): the LME step, compute-bound, 0.85 (the lower of two 3D
              runs, 0.85 and 0.89; 0.87 and 0.91 in 2D); the
              linear step, bound by the memory bandwidth the cores share, 0.77 (STREAM triad:
              two cores 1.23 times one)
  --imbalance the largest process's particles over the mean (measured 1.14-1.20 on small
              collapsing columns, tests/mpi/balance.py; the cut's grain shrinks with size)
Two per-particle costs of one core, both measured (reports/performance.md): 3D LME gamma = 3
with real motion (empm bench --motion rotate, 1.43e5 particle-steps/s: 7.0 us), and 3D linear
shapes (3.94e6 particle-steps/s: 0.25 us), with 3 and 1 ghost node layers.
"""
import math
import sys


def opt(name, default):
    if name in sys.argv:
        return type(default)(sys.argv[sys.argv.index(name) + 1])
    return default


ALPHA = opt("--alpha-us", 1.5) * 1e-6       # s per message
BETA = 1.0 / (opt("--gbytes", 12.5) * 1e9)  # s per byte
NODE_LME = opt("--node-lme", 0.85)          # on-node speed factor with every core busy
NODE_LINEAR = opt("--node-linear", 0.77)
NODE = NODE_LME                             # set per table in main()
IMB = opt("--imbalance", 1.05)              # largest process's share over the mean
# The per-node passes (zeroing, divisions, constraints, the search for nearly-empty nodes,
# the nodal screen), per node and step of pc_newmark: 3D, one process, a 100^3-cell grid
# holding 8 particles (1.28 s for 49 steps; 2D: 16 ns).
NODE_PASS = opt("--node-pass-ns", 25.0) * 1e-9
REACH = 0                                   # the family's reach in cells (set in main())
COST, W = 7.0e-6, 3                         # set per table in main()
PPC = 8                                     # particles per cell (2 per direction)
ROW = 8 * (10 * 3 + 4 + 12 + 9 + 3 + 2)     # bytes of a migrating particle (pack_rows, 2 state)
CROSS = 0.01                                # share of a block's surface particles that cross
                                            # a face per step (fast flow: 1 % of a cell a step)
# Per step of pc_newmark: two rounds of nodal sums (mass, momentum and filled volume after the
# drift: 5 doubles a node; forces of the kick: 3), plus 2 global reductions (dt, energies).
SUMS = (5, 3)


def step_time(n_particles, procs):
    """(compute, halo, migration, reductions, replicated-grid sums, today's extra) in seconds
    a step."""
    n = n_particles / procs
    cells = n / PPC
    m = cells ** (1.0 / 3.0)                 # cells a side of a cubic block
    # The slowest process: the largest share, at the speed of a full node.
    compute = n * COST * (IMB / NODE if procs > 1 else 1.0)
    # Shared nodes: the 6 faces, 12 edges and 8 corners of the block, W layers deep.
    halo_nodes = 6 * (m + 1) ** 2 * W + 12 * (m + 1) * W * W + 8 * W ** 3
    halo = 0.0
    if procs > 1:
        for doubles in SUMS:
            # Each neighbour's share sent and received once (26 messages each way).
            halo += 26 * ALPHA + 2 * halo_nodes * doubles * 8 * BETA
    surface = 6 * m * m * PPC ** (2.0 / 3.0)  # particles in the block's outer cell layer
    migration = (26 * ALPHA + CROSS * surface * ROW * BETA) if procs > 1 else 0.0
    reductions = 2 * math.ceil(math.log2(procs)) * ALPHA if procs > 1 else 0.0
    nodes_all = n_particles / PPC
    replicated = 0.0
    if procs > 1:
        # Today's design: every nodal array summed in full (ring allreduce: 2 (P-1)/P of it).
        replicated = sum(2 * (procs - 1) / procs * nodes_all * d * 8 * BETA
                         + 2 * math.ceil(math.log2(procs)) * ALPHA for d in SUMS)
    # Today: a process passes over its window, the block's nodes widened by the reach, the
    # margin (8 + 2 (reach + 1)) and 6 spare nodes (4 to 8) a side; the neighbours' regions
    # overlap 2 (margin + reach + 1) layers deep. One process: the whole grid.
    margin = 8 + 2 * (REACH + 1)
    side = m + 1 + 2 * (REACH + margin + 6)
    today = (min(side ** 3, nodes_all) if procs > 1 else nodes_all) * NODE_PASS
    if procs > 1:
        depth = 2 * (margin + REACH + 1)
        shared = 6 * (m + 1) ** 2 * depth + 12 * (m + 1) * depth ** 2 + 8 * depth ** 3
        for doubles in SUMS:
            today += 26 * ALPHA + 2 * shared * doubles * 8 * BETA
    return compute, halo, migration, reductions, replicated, today


def table(title, rows):
    print(title)
    print(f"{'P':>5} {'particles/P':>12} {'step [ms]':>10} {'compute':>8} {'halo':>8} "
          f"{'migr.':>7} {'reduce':>7} {'eff.':>6} {'eff. today':>11} {'eff. all-reduce':>16}")
    for procs, n_total, t1 in rows:
        c, h, mg, r, rep, tod = step_time(n_total, procs)
        t = c + h + mg + r
        eff = t1 / t if t1 else c / t
        trep = c + rep + r + (n_total / PPC) * NODE_PASS
        eff_rep = t1 / trep if t1 else c / trep
        ttod = c + tod + mg + r
        eff_tod = t1 / ttod if t1 else c / ttod
        print(f"{procs:5d} {n_total / procs:12.3g} {1e3 * t:10.3f} {c / t:8.1%} {h / t:8.1%} "
              f"{mg / t:7.1%} {r / t:7.1%} {eff:6.2f} {eff_tod:11.2f} {eff_rep:16.2f}")
    print()


def main():
    global COST, W, REACH, NODE
    print(f"latency {ALPHA * 1e6:.1f} us, {1 / BETA / 1e9:.1f} GB/s; on-node factor "
          f"{NODE_LME} (LME), {NODE_LINEAR} (linear); imbalance {IMB}; {PPC} particles per "
          f"cell\n")
    procs = [1, 2, 8, 64, 128, 256, 512, 1024]
    for label, cost, width in [("3D LME gamma = 3 (7.0 us a particle-step)", 7.0e-6, 3),
                               ("3D linear (0.25 us a particle-step)", 0.254e-6, 1)]:
        COST, W = cost, width
        NODE = NODE_LME if width == 3 else NODE_LINEAR
        REACH = 3 if width == 3 else 0  # LME gamma = 3: ceil(R/h) = 3; linear: 0
        big = 1.0e8
        t_one = step_time(big, 1)[0]
        table(f"{label}: strong scaling, 1e8 particles (efficiency = T1 / (P T_P))",
              [(p, big, t_one / p) for p in procs])
        per = 2.5e5
        table(f"{label}: weak scaling, 2.5e5 particles per process (efficiency = T1 / T_P)",
              [(p, per * p, step_time(per, 1)[0]) for p in procs])


if __name__ == "__main__":
    main()
