/* The stages of LAPACK's dense generalized symmetric-definite solve (dsygvd = dpotrf + dsygst
 * + dsytrd + dstedc + dormtr + dtrsm, and dsterf for values only), timed one by one through the
 * system OpenBLAS, to set beside mechanica's `DenseTimings` and `symmetric_eigen` stages.
 *
 *   gcc -O2 tools/modal_lapack_stages.c -o /tmp/modal_lapack_stages -lopenblas
 *   OPENBLAS_CORETYPE=Haswell /tmp/modal_lapack_stages 2000
 *
 * Matrices: a random symmetric C (entries uniform in [-0.5, 0.5]) for the eigen stages, and an
 * SPD A = G Gᵀ + n I for dpotrf/dsygst/dtrsm. Three repetitions each, every buffer fresh. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

void dsytrd_(char *, int *, double *, int *, double *, double *, double *, double *, int *, int *, size_t);
void dstedc_(char *, int *, double *, double *, double *, int *, double *, int *, int *, int *, int *, size_t);
void dormtr_(char *, char *, char *, int *, int *, double *, int *, double *, double *, int *, double *, int *,
             int *, size_t, size_t, size_t);
void dsterf_(int *, double *, double *, int *);
void dpotrf_(char *, int *, double *, int *, int *, size_t);
void dsygst_(int *, char *, int *, double *, int *, double *, int *, int *, size_t);
void dtrsm_(char *, char *, char *, char *, int *, int *, double *, double *, int *, double *, int *, size_t, size_t,
            size_t, size_t);
void dgemm_(char *, char *, int *, int *, int *, double *, double *, int *, double *, int *, double *, double *,
            int *, size_t, size_t);

static double now(void) {
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return t.tv_sec + 1e-9 * t.tv_nsec;
}

static double *fresh(size_t count) { return malloc(sizeof(double) * count); }

int main(int argc, char **argv) {
    int n = argc > 1 ? atoi(argv[1]) : 2000;
    size_t nn = (size_t)n * n;
    double one = 1.0, zero = 0.0, q;
    int info, itype = 1;
    srand(1);
    double *c0 = fresh(nn), *g = fresh(nn), *spd = fresh(nn);
    for (int j = 0; j < n; j++)
        for (int i = j; i < n; i++) c0[i + (size_t)j * n] = c0[j + (size_t)i * n] = rand() / (double)RAND_MAX - 0.5;
    for (size_t i = 0; i < nn; i++) g[i] = rand() / (double)RAND_MAX - 0.5;
    dgemm_("N", "T", &n, &n, &n, &one, g, &n, g, &n, &zero, spd, &n, 1, 1);
    for (int i = 0; i < n; i++) spd[i + (size_t)i * n] += n;
    for (int r = 0; r < 3; r++) {
        double *a = fresh(nn), *d = fresh(n), *e = fresh(n), *tau = fresh(n), *d2 = fresh(n), *e2 = fresh(n);
        memcpy(a, c0, sizeof(double) * nn);
        int lwork = -1;
        dsytrd_("L", &n, a, &n, d, e, tau, &q, &lwork, &info, 1);
        lwork = (int)q;
        double *work = fresh(lwork);
        double t0 = now();
        dsytrd_("L", &n, a, &n, d, e, tau, work, &lwork, &info, 1);
        double t_sytrd = now() - t0;
        memcpy(d2, d, sizeof(double) * n);
        memcpy(e2, e, sizeof(double) * n);
        t0 = now();
        dsterf_(&n, d2, e2, &info);
        double t_sterf = now() - t0;
        double *z = fresh(nn);
        int lwz = -1, liw = -1, iq;
        dstedc_("I", &n, d, e, z, &n, &q, &lwz, &iq, &liw, &info, 1);
        lwz = (int)q;
        liw = iq;
        double *wz = fresh(lwz);
        int *iw = malloc(sizeof(int) * liw);
        t0 = now();
        dstedc_("I", &n, d, e, z, &n, wz, &lwz, iw, &liw, &info, 1);
        double t_stedc = now() - t0;
        int lwo = -1;
        dormtr_("L", "L", "N", &n, &n, a, &n, tau, z, &n, &q, &lwo, &info, 1, 1, 1);
        lwo = (int)q;
        double *wo = fresh(lwo);
        t0 = now();
        dormtr_("L", "L", "N", &n, &n, a, &n, tau, z, &n, wo, &lwo, &info, 1, 1, 1);
        double t_ormtr = now() - t0;
        double *l = fresh(nn), *b = fresh(nn);
        memcpy(l, spd, sizeof(double) * nn);
        memcpy(b, spd, sizeof(double) * nn);
        t0 = now();
        dpotrf_("L", &n, l, &n, &info, 1);
        double t_potrf = now() - t0;
        t0 = now();
        dsygst_(&itype, "L", &n, b, &n, l, &n, &info, 1);
        double t_sygst = now() - t0;
        t0 = now();
        dtrsm_("L", "L", "T", "N", &n, &n, &one, l, &n, b, &n, 1, 1, 1, 1);
        double t_trsm = now() - t0;
        printf("n %d  dpotrf %.3f  dsygst %.3f  dsytrd %.3f  dsterf %.3f  dstedc %.3f  dormtr %.3f  dtrsm %.3f s\n", n,
               t_potrf, t_sygst, t_sytrd, t_sterf, t_stedc, t_ormtr, t_trsm);
        free(a), free(d), free(e), free(tau), free(d2), free(e2), free(work), free(z), free(wz), free(iw), free(wo);
        free(l), free(b);
    }
    free(c0), free(g), free(spd);
    return 0;
}
