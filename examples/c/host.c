/* A C host for empm (docs/embedding.md): a 1D elastic bar, fixed at x = 0 and set vibrating in
 * its first mode, built through the C API, stepped in the host's own loop, with the stresses
 * read back. Usage: host [output.h5]. Build:
 *   cc host.c $(pkg-config --cflags --libs empm) -o host */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include <empm.h>

#define NP 50 /* particles: two per cell on [0, 25] */

static int check(int rc, const empm_model *m, const char *what)
{
  if (rc != EMPM_OK) {
    char msg[512];
    empm_model_error(m, msg, sizeof msg);
    fprintf(stderr, "%s failed (status %d): %s\n", what, rc, msg);
  }
  return rc;
}

int main(int argc, char **argv)
{
  const double L = 25.0, E = 100.0, rho = 1.0, v0 = 1e-3, beta = 3.14159265358979 / (2 * L);
  double origin[1] = {0.0}, h[1] = {1.0};
  int ncell[1] = {27};
  double x[NP], vol[NP], dens[NP], v[NP], stress[6 * NP];
  int mat[NP], id, nsel, p, k;
  char version[32], err[512];
  empm_model *m = NULL;

  empm_version_string(version, sizeof version);
  if (empm_model_create(1, origin, h, ncell, &m, err, sizeof err) != EMPM_OK) {
    fprintf(stderr, "empm_model_create: %s\n", err);
    return 1;
  }
  if (check(empm_model_add_material(m, "linear_elastic", "E = 100, nu = 0, density = 1", &id),
            m, "add_material"))
    return 1;
  for (p = 0; p < NP; p++) {
    x[p] = (p + 0.5) * L / NP;
    vol[p] = L / NP;
    dens[p] = rho;
    mat[p] = id;
  }
  {
    const double lo[3] = {0, 0, 0}, hi[3] = {0, 0, 0}, zero[3] = {0, 0, 0};
    const int mask[3] = {1, 0, 0};
    if (check(empm_model_add_particles(m, NP, x, vol, dens, mat), m, "add_particles") ||
        check(empm_model_fix_box(m, lo, hi, mask, zero, &nsel), m, "fix_box") ||
        check(empm_model_set_shape(m, "linear", NULL), m, "set_shape") ||
        check(empm_model_set_integrator(m, "musl", NULL), m, "set_integrator") ||
        check(empm_model_set_time_step(m, 0.5, 0.0), m, "set_time_step") ||
        check(empm_model_finalize(m), m, "finalize"))
      return 1;
  }
  for (p = 0; p < NP; p++) v[p] = v0 * sin(beta * x[p]);
  if (check(empm_model_set_field(m, "v", v, NP), m, "set_field v")) return 1;

  /* The host's own loop: a quarter period T/4 = L/c in ten pieces. */
  for (k = 1; k <= 10; k++) {
    double t, ekin, estrain, egrav;
    int ndim, np, nstep;
    if (check(empm_model_advance_to(m, k * 0.25), m, "advance_to")) return 1;
    empm_model_info(m, &ndim, &np, &t, &nstep);
    empm_model_energies(m, &ekin, &estrain, &egrav);
    printf("t = %5.2f  steps = %3d  E_kin = %.4e  E_strain = %.4e\n", t, nstep, ekin, estrain);
  }
  if (check(empm_model_get_field(m, "stress", stress, 6 * NP), m, "get_field stress")) return 1;
  /* At T/4 the bar is at rest and stretched: sigma_xx = E v0/c cos(beta x) (c = 10). */
  printf("empm %s: sigma_xx(x = %.3f) = %.4e Pa (exact %.4e)\n", version, x[0], stress[0],
         E * v0 / sqrt(E / rho) * cos(beta * x[0]));
  if (argc > 1 && check(empm_model_write(m, argv[1]), m, "write")) return 1;
  empm_model_destroy(m);
  return 0;
}
