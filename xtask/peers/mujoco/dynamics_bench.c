// MuJoCo peer benchmark for anim-rigid's dynamics (`cargo xtask bench --peers`).
//
// Loads a URDF with MuJoCo's own URDF compiler (the xtask writes the robot's URDF without visual
// and collision geometry and with locked joints made fixed), sets gravity to the given vector,
// no contact, no joint damping, armature or friction loss, then reads the same samples that
// anim-rigid is timed on together with anim-rigid's results for them, and checks that MuJoCo
// computes the same quantities before timing anything:
//
//   inverse dynamics  mj_kinematics + mj_comPos + mj_comVel + mj_rne(flg_acc = 1)  (qacc set)
//   mass matrix       mj_kinematics + mj_comPos + mj_crb                (compared with mj_fullM)
//   forward dynamics  mj_kinematics + mj_comPos + mj_crb + mj_factorM + mj_comVel
//                     + mj_rne(flg_acc = 0) + mj_solveM(tau - bias)
//
// usage: dynamics_bench URDF SAMPLES CALLS_PER_BATCH TOLERANCE INERTIAS
// INERTIAS: one line per moving body, "LINK MASS CX CY CZ I00..I22" (anim-rigid's inertia in the
// body frame, about the centre of mass): mass and centre of mass are checked against MuJoCo's,
// and the principal moments and their orientation are set from the matrix (mju_eig3), undoing
// the compiler's `balanceinertia` where a body needed it.
// SAMPLES: first line "NV N GX GY GZ"; then N lines of q (NV hinge angles), v, a, tau, then
// anim-rigid's rnea (NV), mass matrix (NV x NV, row-major) and forward dynamics (NV).
// Prints one JSON object per line: {"kernel": "check", ...} with the largest relative
// differences, then {"kernel": ..., "ns_per_call": ..., "checksum": ...} for rnea, crba and
// forward_dynamics; exits 3 without timing when a difference exceeds TOLERANCE.

#include <mujoco/mujoco.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

static double now_ns(void) {
  struct timespec t;
  clock_gettime(CLOCK_MONOTONIC, &t);
  return (double)t.tv_sec * 1e9 + (double)t.tv_nsec;
}

static int cmp_double(const void* a, const void* b) {
  const double x = *(const double*)a, y = *(const double*)b;
  return (x > y) - (x < y);
}

enum { BATCHES = 15 };

typedef struct {
  int nv, n;
  const double* q;
  const double* v;
  const double* a;
  const double* tau;
} Samples;

static void set_state(const mjModel* m, mjData* d, const Samples* s, int k) {
  memcpy(d->qpos, s->q + (size_t)k * m->nq, sizeof(double) * m->nq);
  memcpy(d->qvel, s->v + (size_t)k * m->nv, sizeof(double) * m->nv);
}

static double rnea(const mjModel* m, mjData* d, const Samples* s, int k, double* out) {
  set_state(m, d, s, k);
  memcpy(d->qacc, s->a + (size_t)k * m->nv, sizeof(double) * m->nv);
  mj_kinematics(m, d);
  mj_comPos(m, d);
  mj_comVel(m, d);
  mj_rne(m, d, 1, out);
  return out[m->nv - 1];
}

static double crba(const mjModel* m, mjData* d, const Samples* s, int k) {
  memcpy(d->qpos, s->q + (size_t)k * m->nq, sizeof(double) * m->nq);
  mj_kinematics(m, d);
  mj_comPos(m, d);
  mj_crb(m, d);
  return d->M[0];
}

static double forward(const mjModel* m, mjData* d, const Samples* s, int k, double* rhs) {
  set_state(m, d, s, k);
  mj_kinematics(m, d);
  mj_comPos(m, d);
  mj_crb(m, d);
  mj_factorM(m, d);
  mj_comVel(m, d);
  mj_rne(m, d, 0, d->qfrc_bias);
  const double* tau = s->tau + (size_t)k * m->nv;
  for (int i = 0; i < m->nv; ++i) rhs[i] = tau[i] - d->qfrc_bias[i];
  mj_solveM(m, d, d->qacc, rhs, 1);
  return d->qacc[m->nv - 1];
}

static double max_abs(const double* x, int n) {
  double a = 0.0;
  for (int i = 0; i < n; ++i) a = fmax(a, fabs(x[i]));
  return a;
}

// Largest |x - y| relative to the largest |y|.
static double rel_diff(const double* x, const double* y, int n) {
  double e = 0.0;
  for (int i = 0; i < n; ++i) e = fmax(e, fabs(x[i] - y[i]));
  const double scale = max_abs(y, n);
  return scale > 0.0 ? e / scale : e;
}

int main(int argc, char** argv) {
  if (argc < 6) {
    fprintf(stderr, "usage: %s URDF SAMPLES CALLS_PER_BATCH TOLERANCE INERTIAS\n", argv[0]);
    return 2;
  }
  char error[1000] = "";
  mjModel* m = mj_loadXML(argv[1], NULL, error, sizeof(error));
  if (!m) {
    fprintf(stderr, "MuJoCo could not load %s: %s\n", argv[1], error);
    return 2;
  }
  FILE* fi = fopen(argv[5], "r");
  if (!fi) {
    fprintf(stderr, "cannot open %s\n", argv[5]);
    return 2;
  }
  char link[256];
  double mass, c[3], inertia[9];
  int bodies = 0;
  while (fscanf(fi, "%255s %lf %lf %lf %lf", link, &mass, &c[0], &c[1], &c[2]) == 5) {
    for (int i = 0; i < 9; ++i)
      if (fscanf(fi, "%lf", &inertia[i]) != 1) {
        fprintf(stderr, "%s: incomplete line for %s\n", argv[5], link);
        return 2;
      }
    const int id = mj_name2id(m, mjOBJ_BODY, link);
    if (id < 0) {
      fprintf(stderr, "MuJoCo's model of %s has no body %s\n", argv[1], link);
      return 2;
    }
    const double* ipos = m->body_ipos + 3 * id;
    const double dc = fmax(fabs(ipos[0] - c[0]), fmax(fabs(ipos[1] - c[1]), fabs(ipos[2] - c[2])));
    if (fabs(m->body_mass[id] - mass) > 1e-12 * mass || dc > 1e-12) {
      fprintf(stderr, "body %s: MuJoCo has mass %.17g, centre of mass (%g %g %g); anim-rigid %.17g, (%g %g %g)\n",
              link, m->body_mass[id], ipos[0], ipos[1], ipos[2], mass, c[0], c[1], c[2]);
      return 2;
    }
    double eigvec[9];
    mju_eig3(m->body_inertia + 3 * id, eigvec, m->body_iquat + 4 * id, inertia);
    ++bodies;
  }
  fclose(fi);
  if (bodies != m->nbody - 1) {
    fprintf(stderr, "%s: %d bodies, MuJoCo's model has %d moving bodies\n", argv[5], bodies, (int)m->nbody - 1);
    return 2;
  }
  FILE* f = fopen(argv[2], "r");
  if (!f) {
    fprintf(stderr, "cannot open %s\n", argv[2]);
    return 2;
  }
  int nv = 0, n = 0;
  double g[3];
  if (fscanf(f, "%d %d %lf %lf %lf", &nv, &n, &g[0], &g[1], &g[2]) != 5 || nv <= 0 || n <= 0) {
    fprintf(stderr, "%s: bad header\n", argv[2]);
    return 2;
  }
  if (m->nv != nv || m->nq != nv) {
    fprintf(stderr, "MuJoCo's model of %s has nq %d, nv %d; anim-rigid's has nv %d\n", argv[1], (int)m->nq,
            (int)m->nv, nv);
    return 2;
  }
  for (int j = 0; j < m->njnt; ++j) {
    if (m->jnt_type[j] != mjJNT_HINGE && m->jnt_type[j] != mjJNT_SLIDE) {
      fprintf(stderr, "joint %d of MuJoCo's model is neither hinge nor slide\n", j);
      return 2;
    }
  }
  // The same rigid-body model as anim-rigid's: no armature, damping or friction loss (none of
  // them enters the pipelines timed, armature would enter the mass matrix), the same gravity,
  // nothing but smooth dynamics.
  double armature = 0.0;
  for (int i = 0; i < nv; ++i) {
    armature = fmax(armature, fabs(m->dof_armature[i]));
    m->dof_armature[i] = 0.0;
    m->dof_damping[i] = 0.0;
    m->dof_frictionloss[i] = 0.0;
  }
  mju_copy3(m->opt.gravity, g);
  m->opt.disableflags |= mjDSBL_CONTACT | mjDSBL_CONSTRAINT;
  const size_t total = (size_t)n * nv;
  double* buf = (double*)malloc(sizeof(double) * total * (7 + (size_t)nv));
  double *q = buf, *v = q + total, *a = v + total, *tau = a + total;
  double *ref_rnea = tau + total, *ref_fd = ref_rnea + total, *ref_m = ref_fd + total;
  for (int k = 0; k < n; ++k) {
    double* rows[4] = {q, v, a, tau};
    int ok = 1;
    for (int r = 0; r < 4; ++r)
      for (int i = 0; i < nv; ++i) ok &= fscanf(f, "%lf", &rows[r][(size_t)k * nv + i]) == 1;
    for (int i = 0; i < nv; ++i) ok &= fscanf(f, "%lf", &ref_rnea[(size_t)k * nv + i]) == 1;
    for (int i = 0; i < nv * nv; ++i) ok &= fscanf(f, "%lf", &ref_m[(size_t)k * nv * nv + i]) == 1;
    for (int i = 0; i < nv; ++i) ok &= fscanf(f, "%lf", &ref_fd[(size_t)k * nv + i]) == 1;
    if (!ok) {
      fprintf(stderr, "%s: sample %d is incomplete\n", argv[2], k);
      return 2;
    }
  }
  fclose(f);
  const Samples s = {nv, n, q, v, a, tau};
  mjData* d = mj_makeData(m);
  double* out = (double*)malloc(sizeof(double) * nv);
  double* full = (double*)malloc(sizeof(double) * nv * nv);
  double e_rnea = 0.0, e_m = 0.0, e_fd = 0.0;
  for (int k = 0; k < n; ++k) {
    rnea(m, d, &s, k, out);
    e_rnea = fmax(e_rnea, rel_diff(out, ref_rnea + (size_t)k * nv, nv));
    crba(m, d, &s, k);
    mj_fullM(m, d, full);
    e_m = fmax(e_m, rel_diff(full, ref_m + (size_t)k * nv * nv, nv * nv));
    forward(m, d, &s, k, out);
    e_fd = fmax(e_fd, rel_diff(d->qacc, ref_fd + (size_t)k * nv, nv));
  }
  const double tol = atof(argv[4]);
  printf("{\"kernel\": \"check\", \"version\": \"%s\", \"samples\": %d, \"armature_removed\": %.3e, "
         "\"rnea\": %.3e, \"crba\": %.3e, \"forward_dynamics\": %.3e}\n",
         mj_versionString(), n, armature, e_rnea, e_m, e_fd);
  fflush(stdout);
  if (!(e_rnea <= tol && e_m <= tol && e_fd <= tol)) {
    fprintf(stderr, "MuJoCo and anim-rigid disagree (tolerance %.1e): not timed\n", tol);
    return 3;
  }
  const int calls = atoi(argv[3]);
  for (int kernel = 0; kernel < 3; ++kernel) {
    double t[BATCHES], sink = 0.0;
    for (int b = 0; b < BATCHES; ++b) {
      const double start = now_ns();
      for (int i = 0; i < calls; ++i) {
        const int k = i % n;
        if (kernel == 0) sink += rnea(m, d, &s, k, out);
        else if (kernel == 1) sink += crba(m, d, &s, k);
        else sink += forward(m, d, &s, k, out);
      }
      t[b] = (now_ns() - start) / calls;
    }
    qsort(t, BATCHES, sizeof(double), cmp_double);
    static const char* names[3] = {"rnea", "crba", "forward_dynamics"};
    printf("{\"kernel\": \"%s\", \"ns_per_call\": %.3f, \"checksum\": %.17g}\n", names[kernel],
           t[BATCHES / 2], sink);
  }
  free(full);
  free(out);
  free(buf);
  mj_deleteData(d);
  mj_deleteModel(m);
  return 0;
}
