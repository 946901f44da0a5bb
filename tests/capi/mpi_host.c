/* A C host that runs empm on its own MPI communicator (CTest capi_mpi_c, under mpirun -n 3;
 * docs/embedding.md, "MPI"). Every process builds the same 2D model three times: alone, and on
 * the host's communicator with empm_model_set_comm called before the particles (dealt out as
 * they are added) and after them (each process holds every one until finalize). After the same
 * steps the parallel models' particles (this process's share, found by their "id") equal the
 * serial model's to 1e-12, and so do the energies; the results written by a parallel model hold
 * every particle. Adding many particles after set_comm takes a process about 1/P of the memory
 * they take when it is called after them. Then a case file runs on the communicator, and misuse
 * is refused with a status.
 * Usage: mpi_host case.nml out_dir */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <mpi.h>

#include "empm.h"

#define NX 48
#define NY 8
#define NP (NX * NY)

#include "check.h"

/* Resident memory of this process [KiB] (VmRSS). */
static long resident_kib(void)
{
  char line[256];
  long kib = -1;
  FILE *f = fopen("/proc/self/status", "r");
  if (!f) return -1;
  while (fgets(line, sizeof line, f))
    if (strncmp(line, "VmRSS:", 6) == 0) kib = strtol(line + 6, NULL, 10);
  fclose(f);
  return kib;
}

/* The memory [KiB] a process's model holds after `n` particles are added in 2D, with
 * set_comm called before them (first = 1) or after them (first = 0). */
static long held_after_adding(int first, int n, MPI_Comm comm)
{
  double origin[2] = {0, 0}, h[2] = {1.0 / 512, 1.0 / 512};
  int ncell[2] = {512, 512}, imat = 0, p;
  double *x = malloc(sizeof *x * 2 * (size_t)n), *vol = malloc(sizeof *vol * (size_t)n);
  double *rho = malloc(sizeof *rho * (size_t)n);
  int *mat = malloc(sizeof *mat * (size_t)n);
  char err[256];
  long before, after;
  empm_model *m = NULL;
  CHECK(empm_model_create(2, origin, h, ncell, &m, err, sizeof err) == EMPM_OK);
  CHECK(empm_model_add_material(m, "linear_elastic", "E = 1e6, nu = 0.25, density = 2000",
                                &imat) == EMPM_OK);
  for (p = 0; p < n; p++) {
    x[2 * p] = (p % 1000 + 0.5) / 1000.0; x[2 * p + 1] = (p / 1000 + 0.5) / (n / 1000 + 1.0);
    vol[p] = 1e-6; rho[p] = 2000; mat[p] = imat;
  }
  if (first) CHECK(empm_model_set_comm(m, (int)MPI_Comm_c2f(comm)) == EMPM_OK);
  before = resident_kib();
  CHECK(empm_model_add_particles(m, n, x, vol, rho, mat) == EMPM_OK);
  after = resident_kib();
  if (!first) CHECK(empm_model_set_comm(m, (int)MPI_Comm_c2f(comm)) == EMPM_OK);
  CHECK(empm_model_finalize(m) == EMPM_OK);
  empm_model_destroy(m);
  free(x); free(vol); free(rho); free(mat);
  return after - before;
}

/* A strip of NP particles on a frictional base under gravity, moving along x with a wave in its
 * velocity; alone (use_comm = 0) or on `comm`, set before the particles (1) or after them (2).
 * Initial velocities and stresses are set by id. */
static empm_model *strip(int use_comm, MPI_Comm comm)
{
  static double x[2 * NP], vol[NP], rho[NP];
  static int mat[NP];
  double origin[2] = {0, 0}, h[2] = {0.0625, 0.0625}, g[3] = {0, -10, 0};
  double lo[3] = {0, 0, 0}, hi[3] = {8, 0, 0}, *id, *v, *s;
  int ncell[2] = {64, 6}, imat = 0, i, j, p, nsel, ndim, np, nstep;
  double t;
  char err[256];
  size_t n;
  empm_model *m = NULL;
  CHECK(empm_model_create(2, origin, h, ncell, &m, err, sizeof err) == EMPM_OK);
  if (use_comm == 1) CHECK(empm_model_set_comm(m, (int)MPI_Comm_c2f(comm)) == EMPM_OK);
  CHECK(empm_model_set_integrator(m, "pc_newmark", NULL) == EMPM_OK);
  CHECK(empm_model_add_material(m, "linear_elastic", "E = 1e6, nu = 0.25, density = 2000",
                                &imat) == EMPM_OK);
  for (i = 0, p = 0; i < NX; i++)
    for (j = 0; j < NY; j++, p++) {
      x[2 * p] = (i + 0.5) * 0.03125; x[2 * p + 1] = (j + 0.5) * 0.03125;
      vol[p] = 0.03125 * 0.03125; rho[p] = 2000; mat[p] = imat;
    }
  CHECK(empm_model_add_particles(m, NP, x, vol, rho, mat) == EMPM_OK);
  if (use_comm == 2) CHECK(empm_model_set_comm(m, (int)MPI_Comm_c2f(comm)) == EMPM_OK);
  CHECK(empm_model_set_gravity(m, g) == EMPM_OK);
  CHECK(empm_model_friction_box(m, lo, hi, 2, 10.0, &nsel) == EMPM_OK);
  CHECK(empm_model_finalize(m) == EMPM_OK);
  /* This process's particles: their ids say which of the NP they are. */
  CHECK(empm_model_info(m, &ndim, &np, &t, &nstep) == EMPM_OK);
  id = malloc(sizeof *id * (size_t)(np > 0 ? np : 1));
  v = malloc(sizeof *v * 2 * (size_t)(np > 0 ? np : 1));
  s = calloc(6 * (size_t)(np > 0 ? np : 1), sizeof *s);
  CHECK(empm_model_field_size(m, "id", &n) == EMPM_OK && n == (size_t)np);
  CHECK(empm_model_get_field(m, "id", id, (size_t)np) == EMPM_OK);
  for (p = 0; p < np; p++) {
    int k = (int)id[p] - 1;
    v[2 * p] = 1.0 + 0.3 * sin(x[2 * k]); v[2 * p + 1] = 0.05 * sin(2 * x[2 * k]);
    s[6 * p + 1] = -2000.0 * 10.0 * (0.25 - x[2 * k + 1]);
  }
  CHECK(empm_model_set_field(m, "v", v, 2 * (size_t)np) == EMPM_OK);
  CHECK(empm_model_set_field(m, "stress", s, 6 * (size_t)np) == EMPM_OK);
  free(id); free(v); free(s);
  return m;
}

/* The parallel model's particles where the serial model has them (1e-12 of the largest
 * coordinate), every particle once over the processes, and the same energies. */
static void compare(empm_model *serial, empm_model *par, const char *label, int rank, int nranks)
{
  int np, ndim, nstep, p, k, all;
  double t, ek[2], es[2], eg[2], *xs, *xp, *id, worst = 0, scale = 0, gworst;
  CHECK(empm_model_info(par, &ndim, &np, &t, &nstep) == EMPM_OK);
  MPI_Allreduce(&np, &all, 1, MPI_INT, MPI_SUM, MPI_COMM_WORLD);
  CHECK(all == NP);
  CHECK(nranks == 1 || np < NP);
  xs = malloc(sizeof *xs * 2 * NP);
  xp = malloc(sizeof *xp * 2 * (size_t)(np > 0 ? np : 1));
  id = malloc(sizeof *id * (size_t)(np > 0 ? np : 1));
  CHECK(empm_model_get_field(serial, "x", xs, 2 * NP) == EMPM_OK);
  CHECK(empm_model_get_field(par, "x", xp, 2 * (size_t)np) == EMPM_OK);
  CHECK(empm_model_get_field(par, "id", id, (size_t)np) == EMPM_OK);
  for (p = 0; p < 2 * NP; p++) scale = fmax(scale, fabs(xs[p]));
  for (p = 0; p < np; p++)
    for (k = 0; k < 2; k++)
      worst = fmax(worst, fabs(xp[2 * p + k] - xs[2 * ((int)id[p] - 1) + k]) / scale);
  MPI_Allreduce(&worst, &gworst, 1, MPI_DOUBLE, MPI_MAX, MPI_COMM_WORLD);
  CHECK(gworst <= 1e-12);
  CHECK(empm_model_energies(serial, &ek[0], &es[0], &eg[0]) == EMPM_OK);
  CHECK(empm_model_energies(par, &ek[1], &es[1], &eg[1]) == EMPM_OK);
  CHECK(fabs(ek[1] - ek[0]) <= 1e-12 * fabs(ek[0]) && fabs(es[1] - es[0]) <= 1e-12 * fabs(es[0]));
  CHECK(fabs(eg[1] - eg[0]) <= 1e-12 * fabs(eg[0]));
  if (rank == 0)
    printf("%d processes, %s: largest particle share %d of %d, positions within %.2e, kinetic "
           "energy %.12e (alone %.12e)\n", nranks, label, np, NP, gworst, ek[1], ek[0]);
  free(xs); free(xp); free(id);
}

int main(int argc, char **argv)
{
  int rank, nranks, rc, order, k;
  long held[2], most[2];
  char msg[512], path[1024];
  empm_model *serial, *par[2], *late;
  if (argc < 3) return 2;
  MPI_Init(&argc, &argv);
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  MPI_Comm_size(MPI_COMM_WORLD, &nranks);

  serial = strip(0, MPI_COMM_WORLD);
  CHECK(empm_model_advance_to(serial, 0.1) == EMPM_OK);
  CHECK(empm_model_step(serial, 20) == EMPM_OK);
  for (order = 0; order < 2; order++) {
    par[order] = strip(order + 1, MPI_COMM_WORLD);
    CHECK(empm_model_advance_to(par[order], 0.1) == EMPM_OK);
    CHECK(empm_model_step(par[order], 20) == EMPM_OK);
    compare(serial, par[order], order == 0 ? "set_comm before the particles"
                                           : "set_comm after the particles", rank, nranks);
  }

  /* 600,000 particles: dealt out as they are added, a process holds about 1/P of them. */
  held[0] = held_after_adding(1, 600000, MPI_COMM_WORLD);
  held[1] = held_after_adding(0, 600000, MPI_COMM_WORLD);
  MPI_Allreduce(held, most, 2, MPI_LONG, MPI_MAX, MPI_COMM_WORLD);
  if (rank == 0)
    printf("600000 particles added: at most %ld KiB a process with set_comm before them, "
           "%ld KiB after them\n", most[0], most[1]);
  CHECK(most[1] > 0 && most[0] * nranks < 1.5 * most[1]);

  empm_model_destroy(par[1]);
  snprintf(path, sizeof path, "%s/mpi_host_model.h5", argv[2]);
  CHECK(empm_model_write(par[0], path) == EMPM_OK);

  /* A case file on the communicator: the same status everywhere, one file. */
  snprintf(path, sizeof path, "%s/mpi_host_case.h5", argv[2]);
  rc = empm_run_case_file_comm(argv[1], path, (int)MPI_Comm_c2f(MPI_COMM_WORLD), msg,
                               sizeof msg);
  CHECK(rc == EMPM_OK);
  rc = empm_run_case_file_comm("no-such-case.nml", path, (int)MPI_Comm_c2f(MPI_COMM_WORLD), msg,
                               sizeof msg);
  CHECK(rc != EMPM_OK && strstr(msg, "no-such-case.nml") != NULL);

  /* Misuse: a communicator after finalize, and MPI_COMM_NULL. */
  CHECK(empm_model_set_comm(par[0], (int)MPI_Comm_c2f(MPI_COMM_WORLD)) == EMPM_ERR_USAGE);
  {
    double origin[1] = {0}, h[1] = {1};
    int ncell[1] = {4};
    CHECK(empm_model_create(1, origin, h, ncell, &late, msg, sizeof msg) == EMPM_OK);
    CHECK(empm_model_set_comm(late, (int)MPI_Comm_c2f(MPI_COMM_NULL)) == EMPM_ERR_USAGE);
    CHECK(empm_model_error(late, msg, sizeof msg) == EMPM_OK && strstr(msg, "MPI_COMM_NULL"));
    empm_model_destroy(late);
  }
  /* A dealt model: set_comm again before its particles (accepted), after them (refused);
   * fields before finalize (refused, saying why); a particle refused on one process only
   * (outside the grid there): finalize fails on every process, none waits. */
  {
    double origin[1] = {0}, h[1] = {1}, x[4] = {0.5, 1.5, 2.5, 3.5}, vol[4] = {1, 1, 1, 1};
    double rho[4] = {1, 1, 1, 1}, v[4] = {0, 0, 0, 0};
    int ncell[1] = {4}, mat[4] = {0, 0, 0, 0}, imat = 0, refused;
    size_t n;
    CHECK(empm_model_create(1, origin, h, ncell, &late, msg, sizeof msg) == EMPM_OK);
    CHECK(empm_model_set_comm(late, (int)MPI_Comm_c2f(MPI_COMM_WORLD)) == EMPM_OK);
    CHECK(empm_model_set_comm(late, (int)MPI_Comm_c2f(MPI_COMM_WORLD)) == EMPM_OK);
    CHECK(empm_model_add_material(late, "linear_elastic", "E = 100, nu = 0, density = 1",
                                  &imat) == EMPM_OK);
    for (k = 0; k < 4; k++) mat[k] = imat;
    CHECK(empm_model_add_particles(late, 4, x, vol, rho, mat) == EMPM_OK);
    CHECK(empm_model_set_comm(late, (int)MPI_Comm_c2f(MPI_COMM_WORLD)) == EMPM_ERR_USAGE);
    CHECK(empm_model_field_size(late, "v", &n) == EMPM_ERR_USAGE);
    CHECK(empm_model_set_field(late, "v", v, 4) == EMPM_ERR_USAGE);
    CHECK(empm_model_error(late, msg, sizeof msg) == EMPM_OK && strstr(msg, "after empm_model_finalize"));
    CHECK(empm_model_finalize(late) == EMPM_OK);
    empm_model_destroy(late);
    CHECK(empm_model_create(1, origin, h, ncell, &late, msg, sizeof msg) == EMPM_OK);
    CHECK(empm_model_set_comm(late, (int)MPI_Comm_c2f(MPI_COMM_WORLD)) == EMPM_OK);
    CHECK(empm_model_add_material(late, "linear_elastic", "E = 100, nu = 0, density = 1",
                                  &imat) == EMPM_OK);
    if (rank == nranks - 1) x[3] = 9.5;
    refused = empm_model_add_particles(late, 4, x, vol, rho, mat) != EMPM_OK;
    CHECK(refused == (rank == nranks - 1));
    CHECK(empm_model_finalize(late) == EMPM_ERR_USAGE);
    empm_model_destroy(late);
  }
  empm_model_destroy(serial);
  empm_model_destroy(par[0]);
  MPI_Allreduce(MPI_IN_PLACE, &failures, 1, MPI_INT, MPI_SUM, MPI_COMM_WORLD);
  if (rank == 0 && failures == 0) printf("MPI host: all checks passed\n");
  MPI_Finalize();
  return failures != 0;
}
