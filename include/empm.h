/* empm C API (C99). Embedding guide: docs/embedding.md.
 *
 * Conventions
 *  - Every function returns an int status: EMPM_OK (0) or an EMPM_ERR_* code. Nothing in the
 *    library exits the process.
 *  - A model is an opaque handle (empm_model *). The library keeps no global state: any number
 *    of models may live in one process (use one handle per thread at a time).
 *  - The message of the last failed call on a handle: empm_model_error(m, buf, len).
 *    Functions that create a handle take (errbuf, errlen) instead (either may be NULL/0).
 *  - Strings are NUL-terminated; "params" strings are a case-file group's keys as text,
 *    e.g. "E = 1e7, nu = 0.3, density = 1000" (may be NULL for none).
 *  - Particle fields are copied with explicit sizes, component fastest: field "x" holds
 *    ndim values per particle, "stress" and "strain" 6 Voigt values (xx, yy, zz, yz, xz, xy).
 *  - All doubles are IEEE double, all ints C int (Fortran default kinds of empm).
 */
#ifndef EMPM_H
#define EMPM_H

#include <stddef.h>

#ifdef __cplusplus
extern "C" {
#endif

#define EMPM_OK 0
#define EMPM_ERR_USAGE 1   /* API misuse: null handle, unknown field, wrong size, order */
#define EMPM_ERR_INPUT 2   /* invalid case file or input value */
#define EMPM_ERR_RUNTIME 3 /* run-time guard tripped (NaN, particle left grid, dt) */
#define EMPM_ERR_IO 4      /* file system or HDF5 failure, out of memory */
#define EMPM_ERR_INTERRUPTED 6 /* a run asked to stop (empm run: SIGINT/SIGTERM) */

/* info codes of empm_lme_basis */
#define EMPM_LME_BAD_ARGUMENT (-1)
#define EMPM_LME_NOT_CONVERGED 3
#define EMPM_LME_OUTSIDE_HULL 4
#define EMPM_LME_SINGULAR 5

typedef struct empm_model_s empm_model;

/* Library version "major.minor.patch" into buf (size len). */
int empm_version_string(char *buf, size_t len);

/* Local max-ent shape functions at x from nnodes nodes xa[a*ndim + i] (all by reference;
 * info 0 or an EMPM_LME_* code). Unchanged ABI of empm 0.1. */
void empm_lme_basis(const int *ndim, const int *nnodes, const double *x, const double *xa,
                    const double *gamma, const double *h, const double *tol0, double *p,
                    double *dp, double *lambda, int *info);

/* Run a case file as `empm run` does, without progress output. output may be NULL (the
 * case's &output file). */
int empm_run_case_file(const char *path, const char *output, char *errbuf, size_t errlen);

/* MPI (a build with -DEMPM_USE_MPI=ON; otherwise EMPM_ERR_USAGE): the processes of a host's
 * communicator, passed as its Fortran handle, fcomm = MPI_Comm_c2f(comm) (no mpi.h needed
 * here). empm works on a private duplicate; MPI stays the host's to start and end.
 * empm_run_case_file_comm: every process calls with the same arguments; the root writes the
 * results; every process gets the same status and message (docs/parallel.md). */
int empm_run_case_file_comm(const char *path, const char *output, int fcomm, char *errbuf,
                            size_t errlen);
/* Before finalize: the model runs on the communicator's processes. Every process makes the
 * same calls and adds every particle; finalize gives each process those of its box. Called
 * before the first particle, each process stores only its share of them as they are added
 * (every P-th), and no nodal field of the whole grid, and its fields are read and set after
 * finalize only; called later, every particle until finalize (docs/embedding.md, "MPI").
 * Afterwards info, the
 * fields (get and set) and probe values are this process's particles, in the order they were
 * added (field "id": that number, from 1); steps, energies and write (the root writes every
 * particle) are collective: every process calls them. */
int empm_model_set_comm(empm_model *m, int fcomm);

/* A model from a case file (groups &verify skipped), ready to step. *out is NULL on failure. */
int empm_model_from_case(const char *path, empm_model **out, char *errbuf, size_t errlen);

/* An empty model on a grid of ncell[i] cells of size h[i] from origin (ndim entries each).
 * Then: set_shape, set_integrator (defaults "linear" and "musl"), add_material, add_particles,
 * fix_box, set_gravity, friction_box, set_time_step, and finalize. */
int empm_model_create(int ndim, const double *origin, const double *h, const int *ncell,
                      empm_model **out, char *errbuf, size_t errlen);

/* Last error message of m ("" after a success) into buf (size len). */
int empm_model_error(const empm_model *m, char *buf, size_t len);

int empm_model_set_shape(empm_model *m, const char *id, const char *params);
int empm_model_set_integrator(empm_model *m, const char *name, const char *params);
/* Add a material model ("linear_elastic", "neohookean", ...); *id is its 1-based id. */
int empm_model_add_material(empm_model *m, const char *model, const char *params, int *id);
/* Append n particles at rest: x[p*ndim + i], volumes, densities, material ids. */
int empm_model_add_particles(empm_model *m, int n, const double *x, const double *vol,
                             const double *rho, const int *mat);
/* Prescribe velocity components (mask[i] != 0) at the nodes in the box [lo, hi]; 3 entries
 * each; *nsel receives the number of nodes selected. */
int empm_model_fix_box(empm_model *m, const double lo[3], const double hi[3], const int mask[3],
                       const double value[3], int *nsel);
/* Constant gravity g[3] [m/s^2] (the first ndim entries are used). */
int empm_model_set_gravity(empm_model *m, const double g[3]);
/* A frictional wall at rest on the nodes in the box [lo, hi], flat along the normal's axis:
 * normal component fixed at zero, Coulomb friction tan(friction_angle) [deg] on the others;
 * normal = +axis or -axis (1..ndim), the direction from the wall into the body (+2: a base
 * under the body in 2D). Schemes usf, usl, musl, pc_published, pc_newmark. */
int empm_model_friction_box(empm_model *m, const double lo[3], const double hi[3], int normal,
                            double friction_angle, int *nsel);
/* Time step: dt = cfl * stable step when dt == 0 (default cfl 0.5), else the fixed dt. */
int empm_model_set_time_step(empm_model *m, double cfl, double dt);
/* Finish the set-up; the model can then step (case-file models are finalized already). */
int empm_model_finalize(empm_model *m);

/* Take n steps / advance to time t, through the solver and its guards. A tripped guard
 * restores the last good state and returns EMPM_ERR_RUNTIME. */
int empm_model_step(empm_model *m, int n);
int empm_model_advance_to(empm_model *m, double t);

int empm_model_info(const empm_model *m, int *ndim, int *np, double *t, int *nstep);

/* Particle fields by name: "x", "v", "stress", "strain", "mass", "volume", "density" or a
 * state variable's name. n must equal the field size (empm_model_field_size). */
int empm_model_field_size(const empm_model *m, const char *field, size_t *n);
int empm_model_get_field(const empm_model *m, const char *field, double *buf, size_t n);
int empm_model_set_field(empm_model *m, const char *field, const double *buf, size_t n);

/* Kinetic, stored and gravitational energy [J]. */
int empm_model_energies(const empm_model *m, double *ekin, double *estrain, double *egrav);
/* A field's values at a case file's probe (n = components of the field). */
int empm_model_probe(const empm_model *m, const char *probe, const char *field, double *buf,
                     size_t n);

/* Write the state and history to HDF5 (+ XDMF next to it). */
int empm_model_write(const empm_model *m, const char *path);

/* Free a model (NULL is ignored). */
void empm_model_destroy(empm_model *m);

#ifdef __cplusplus
}
#endif
#endif /* EMPM_H */
