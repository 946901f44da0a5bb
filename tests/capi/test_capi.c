/* C API checks (CTest capi_c): two models in one process, fields in and out, a case file, and
 * bad input (null handle, unknown field, wrong size, case-file error, misuse order) returning
 * a status and a message, never a crash. Usage: test_capi good.nml bad.nml out.h5 */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "empm.h"

#include "check.h"

/* A 1D bar of n particles on [0, 10], optionally moving at speed v0. */
static empm_model *bar(int n, double v0)
{
  double origin[1] = {0}, h[1] = {1}, x[64], vol[64], rho[64], v[64];
  int ncell[1] = {12}, mat[64], id = 0, p;
  char err[256];
  empm_model *m = NULL;
  CHECK(empm_model_create(1, origin, h, ncell, &m, err, sizeof err) == EMPM_OK);
  CHECK(empm_model_add_material(m, "linear_elastic", "E = 100, nu = 0, density = 1", &id) ==
        EMPM_OK);
  CHECK(id == 1);
  for (p = 0; p < n; p++) {
    x[p] = (p + 0.5) * 10.0 / n; vol[p] = 10.0 / n; rho[p] = 1; mat[p] = id; v[p] = v0;
  }
  CHECK(empm_model_add_particles(m, n, x, vol, rho, mat) == EMPM_OK);
  CHECK(empm_model_finalize(m) == EMPM_OK);
  CHECK(empm_model_set_field(m, "v", v, (size_t)n) == EMPM_OK);
  return m;
}

int main(int argc, char **argv)
{
  char msg[512], version[32];
  double buf[64], ek1, ek2, es, eg, t;
  int ndim, np, nstep, id;
  size_t n;
  empm_model *a, *b, *c = NULL, *null = NULL;
  if (argc < 4) return 2;

  CHECK(empm_version_string(version, sizeof version) == EMPM_OK && strlen(version) >= 5);

  /* Two independent models in one process. */
  a = bar(20, 1.0);
  b = bar(40, 0.0);
  CHECK(empm_model_step(a, 5) == EMPM_OK);
  CHECK(empm_model_info(a, &ndim, &np, &t, &nstep) == EMPM_OK);
  CHECK(ndim == 1 && np == 20 && nstep == 5 && t > 0);
  CHECK(empm_model_info(b, &ndim, &np, &t, &nstep) == EMPM_OK);
  CHECK(np == 40 && nstep == 0 && t == 0);
  CHECK(empm_model_energies(a, &ek1, &es, &eg) == EMPM_OK);
  CHECK(fabs(ek1 - 5.0) < 1e-9); /* rigid motion: 1/2 m v^2, m = 10 */
  CHECK(empm_model_energies(b, &ek2, &es, &eg) == EMPM_OK && ek2 == 0);
  CHECK(empm_model_advance_to(b, 0.5) == EMPM_OK);
  CHECK(empm_model_info(b, &ndim, &np, &t, &nstep) == EMPM_OK && fabs(t - 0.5) < 1e-12);
  CHECK(empm_model_field_size(a, "stress", &n) == EMPM_OK && n == 6 * 20);
  CHECK(empm_model_get_field(a, "x", buf, 20) == EMPM_OK && buf[0] > 0.25);

  /* Positions set between steps are the positions the next step starts from: pc_newmark
   * keeps a position correction for the next drift, which set_field("x") drops. A bar in
   * non-uniform motion for 3 steps, then put at rest, unstressed, at new positions: one more
   * step leaves them where they were put. */
  {
    double origin[1] = {0}, h[1] = {1}, x[10], vol[10], rho[10], v[10], zero[60], moved = 0;
    int ncell[1] = {12}, mat[10], id = 0, p;
    char err[256];
    empm_model *m = NULL;
    CHECK(empm_model_create(1, origin, h, ncell, &m, err, sizeof err) == EMPM_OK);
    CHECK(empm_model_set_integrator(m, "pc_newmark", NULL) == EMPM_OK);
    CHECK(empm_model_add_material(m, "linear_elastic", "E = 100, nu = 0, density = 1", &id) ==
          EMPM_OK);
    for (p = 0; p < 10; p++) {
      x[p] = p + 0.5; vol[p] = 1; rho[p] = 1; mat[p] = id; v[p] = sin(0.3 * p);
    }
    CHECK(empm_model_add_particles(m, 10, x, vol, rho, mat) == EMPM_OK);
    CHECK(empm_model_finalize(m) == EMPM_OK);
    CHECK(empm_model_set_field(m, "v", v, 10) == EMPM_OK);
    CHECK(empm_model_step(m, 3) == EMPM_OK);
    memset(zero, 0, sizeof zero);
    for (p = 0; p < 10; p++) x[p] = p + 0.8;
    CHECK(empm_model_set_field(m, "x", x, 10) == EMPM_OK);
    CHECK(empm_model_set_field(m, "v", zero, 10) == EMPM_OK);
    CHECK(empm_model_set_field(m, "stress", zero, 60) == EMPM_OK);
    CHECK(empm_model_step(m, 1) == EMPM_OK);
    CHECK(empm_model_get_field(m, "x", buf, 10) == EMPM_OK);
    for (p = 0; p < 10; p++) moved = fmax(moved, fabs(buf[p] - x[p]));
    CHECK(moved == 0.0);
    printf("bar put at rest at new positions: moved by %.3g in one step\n", moved);
    empm_model_destroy(m);
  }

  /* Gravity and a frictional base through the builder: a block (E = 1 MPa) launched at 1 m/s
   * slides to rest after v0^2/(2 mu g), mu = tan 10 deg, as in the case-file test
   * (tests/unit/test_loads.pf); its weight in equilibrium from the start (stress set by the
   * host: sigma_yy = -rho g (H - y), sigma_xx = 0). Then the wall's bad input. */
  {
    const double hc = 0.0625, H = 0.25, mu = tan(10.0 * 3.14159265358979 / 180.0);
    double origin[2] = {0, 0}, h[2] = {0.0625, 0.0625}, g[3] = {0, -10, 0};
    double x[2 * 128], vol[128], rho[128], v[2 * 128], s[6 * 128], xe[2 * 128];
    double lo[3] = {0, 0, 0}, hi[3] = {1, 0, 0}, dx = 0, d = 1.0 / (2 * mu * 10);
    int ncell[2] = {16, 6}, mat[128], id = 0, p, i, j, nsel = 0;
    char err[256];
    empm_model *m = NULL;
    CHECK(empm_model_create(2, origin, h, ncell, &m, err, sizeof err) == EMPM_OK);
    CHECK(empm_model_add_material(m, "linear_elastic", "E = 1e6, nu = 0.25, density = 2000",
                                  &id) == EMPM_OK);
    for (p = 0, i = 0; i < 16; i++)
      for (j = 0; j < 8; j++, p++) {
        x[2 * p] = (i + 0.5) * hc / 2; x[2 * p + 1] = (j + 0.5) * hc / 2;
        vol[p] = hc * hc / 4; rho[p] = 2000; mat[p] = id;
        v[2 * p] = 1; v[2 * p + 1] = 0;
        memset(&s[6 * p], 0, 6 * sizeof(double));
        s[6 * p + 1] = -2000 * 10 * (H - x[2 * p + 1]);
      }
    CHECK(empm_model_add_particles(m, 128, x, vol, rho, mat) == EMPM_OK);
    CHECK(empm_model_set_gravity(m, g) == EMPM_OK);
    CHECK(empm_model_friction_box(m, lo, hi, 3, 10.0, &nsel) == EMPM_ERR_USAGE); /* 2D */
    CHECK(empm_model_error(m, msg, sizeof msg) == EMPM_OK && strstr(msg, "normal") != NULL);
    CHECK(empm_model_friction_box(m, lo, hi, 2, 90.0, &nsel) == EMPM_ERR_USAGE);
    hi[1] = hc;
    CHECK(empm_model_friction_box(m, lo, hi, 2, 10.0, &nsel) == EMPM_ERR_USAGE); /* not flat */
    CHECK(empm_model_error(m, msg, sizeof msg) == EMPM_OK && strstr(msg, "flat") != NULL);
    hi[1] = 0;
    CHECK(empm_model_friction_box(m, lo, hi, 2, 10.0, &nsel) == EMPM_OK && nsel == 17);
    CHECK(empm_model_set_integrator(m, "gen_alpha_grid", NULL) == EMPM_OK);
    CHECK(empm_model_finalize(m) == EMPM_ERR_USAGE); /* no frictional walls in gen_alpha */
    CHECK(empm_model_error(m, msg, sizeof msg) == EMPM_OK && strstr(msg, "frictional") != NULL);
    CHECK(empm_model_set_integrator(m, "musl", NULL) == EMPM_OK);
    CHECK(empm_model_finalize(m) == EMPM_OK);
    CHECK(empm_model_set_field(m, "v", v, 2 * 128) == EMPM_OK);
    CHECK(empm_model_set_field(m, "stress", s, 6 * 128) == EMPM_OK);
    CHECK(empm_model_advance_to(m, 0.7) == EMPM_OK);
    CHECK(empm_model_get_field(m, "x", xe, 2 * 128) == EMPM_OK);
    for (p = 0; p < 128; p++) dx += (xe[2 * p] - x[2 * p]) / 128;
    CHECK(fabs(dx - d) < 0.01 * d);
    printf("block on a frictional base: slid %.5f m (v0^2/(2 mu g) = %.5f m)\n", dx, d);
    empm_model_destroy(m);
  }

  /* Bad input: a status and a message. */
  CHECK(empm_model_step(null, 1) == EMPM_ERR_USAGE);
  CHECK(empm_model_get_field(null, "x", buf, 20) == EMPM_ERR_USAGE);
  CHECK(empm_model_error(null, msg, sizeof msg) == EMPM_ERR_USAGE && strlen(msg) > 0);
  CHECK(empm_model_get_field(a, "pressure", buf, 20) == EMPM_ERR_USAGE);
  CHECK(empm_model_error(a, msg, sizeof msg) == EMPM_OK && strstr(msg, "pressure") != NULL);
  CHECK(empm_model_get_field(a, "x", buf, 19) == EMPM_ERR_USAGE);
  CHECK(empm_model_error(a, msg, sizeof msg) == EMPM_OK && strstr(msg, "19") != NULL);
  CHECK(empm_model_set_field(a, "stress", buf, 7) == EMPM_ERR_USAGE);
  CHECK(empm_model_add_material(a, "linear_elastic", "E = 1", &id) == EMPM_ERR_USAGE);
  CHECK(empm_model_set_shape(a, "nonsense", NULL) == EMPM_ERR_USAGE); /* finalized already */
  CHECK(empm_model_get_field(a, "x", buf, 20) == EMPM_OK);
  CHECK(empm_model_error(a, msg, sizeof msg) == EMPM_OK && msg[0] == '\0');
  CHECK(empm_model_advance_to(a, 0.0) != EMPM_OK); /* not after the current time */
  CHECK(empm_model_probe(a, "nowhere", "x", buf, 1) == EMPM_ERR_USAGE);
  /* a message cut to a small buffer stays NUL-terminated */
  empm_model_get_field(a, "pressure", buf, 20);
  CHECK(empm_model_error(a, msg, 8) == EMPM_OK && strlen(msg) == 7);
  {
    double origin[1] = {0}, h[1] = {-1};
    int ncell[1] = {4};
    CHECK(empm_model_create(1, origin, h, ncell, &c, msg, sizeof msg) == EMPM_ERR_INPUT);
    CHECK(c == NULL && strlen(msg) > 0);
    CHECK(empm_model_create(4, origin, h, ncell, &c, msg, sizeof msg) == EMPM_ERR_USAGE);
  }
  {
    empm_model *d = NULL;
    double origin[1] = {0}, h[1] = {1}, x[1] = {50}, one[1] = {1};
    int ncell[1] = {4}, mat[1] = {1};
    CHECK(empm_model_create(1, origin, h, ncell, &d, NULL, 0) == EMPM_OK);
    CHECK(empm_model_step(d, 1) == EMPM_ERR_USAGE); /* not finalized */
    CHECK(empm_model_finalize(d) == EMPM_ERR_USAGE); /* nothing in it */
    CHECK(empm_model_add_material(d, "no_such_model", "", &id) != EMPM_OK && id == 0);
    CHECK(empm_model_add_material(d, "linear_elastic", "E = 1, nu = 0, density = 1", &id) ==
          EMPM_OK);
    CHECK(empm_model_add_particles(d, 1, x, one, one, mat) == EMPM_ERR_USAGE); /* off grid */
    x[0] = 1.5; mat[0] = 7;
    CHECK(empm_model_add_particles(d, 1, x, one, one, mat) == EMPM_ERR_USAGE); /* no mat 7 */
    CHECK(empm_model_set_integrator(d, "no_such_scheme", NULL) != EMPM_OK);
    empm_model_error(d, msg, sizeof msg);
    CHECK(strlen(msg) > 0);
    empm_model_destroy(d);
  }

  /* Case files: a good one (model, probe, write) and a bad one. */
  CHECK(empm_model_from_case(argv[1], &c, msg, sizeof msg) == EMPM_OK);
  if (c) {
    CHECK(empm_model_step(c, 3) == EMPM_OK);
    CHECK(empm_model_probe(c, "tip", "x", buf, 1) == EMPM_OK);
    CHECK(empm_model_probe(c, "tip", "stress", buf, 1) == EMPM_ERR_USAGE);
    CHECK(empm_model_write(c, argv[3]) == EMPM_OK);
    empm_model_destroy(c);
  }
  c = NULL;
  CHECK(empm_model_from_case(argv[2], &c, msg, sizeof msg) == EMPM_ERR_INPUT);
  CHECK(c == NULL && strlen(msg) > 0);
  printf("bad case file: %s\n", msg);
  CHECK(empm_model_from_case("/nonexistent/case.nml", &c, msg, sizeof msg) != EMPM_OK);
  CHECK(empm_run_case_file(argv[2], NULL, msg, sizeof msg) == EMPM_ERR_INPUT);
  CHECK(empm_run_case_file(NULL, NULL, msg, sizeof msg) == EMPM_ERR_USAGE);

  /* A communicator where MPI cannot serve it (a build without MPI, or MPI not started, as
   * here): a usage error saying why (the MPI hosts are capi_mpi_c and capi_mpi_f77). */
  {
    double origin[1] = {0}, h[1] = {1};
    int ncell[1] = {4};
    empm_model *m = NULL;
    CHECK(empm_model_create(1, origin, h, ncell, &m, msg, sizeof msg) == EMPM_OK);
    CHECK(empm_model_set_comm(m, 0) == EMPM_ERR_USAGE);
    CHECK(empm_model_error(m, msg, sizeof msg) == EMPM_OK && strstr(msg, "MPI") != NULL);
    printf("communicator refused: %s\n", msg);
    empm_model_destroy(m);
    CHECK(empm_run_case_file_comm(argv[1], NULL, 0, msg, sizeof msg) == EMPM_ERR_USAGE);
    CHECK(strstr(msg, "MPI") != NULL);
  }

  empm_model_destroy(a);
  empm_model_destroy(b);
  empm_model_destroy(NULL);
  if (failures) fprintf(stderr, "%d check(s) failed\n", failures);
  else printf("C API: all checks passed (empm %s)\n", version);
  return failures ? 1 : 0;
}
