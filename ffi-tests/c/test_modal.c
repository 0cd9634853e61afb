/* C test of the modal entry points: det(λA + B) = 0 on a fixed–fixed unit spring chain
 * (closed form ω²_k = 4 sin²(kπ/(2(n+1)))), a massless coordinate, and every error path. */
#include "check.h"
#include <string.h>

#define N 6

static void fixed_chain(double *a, double *b) {
    for (int j = 0; j < N; ++j) {
        for (int i = 0; i < N; ++i) {
            a[i + N * j] = (i == j) ? 1.0 : 0.0;
            b[i + N * j] = (i == j) ? 2.0 : ((i - j == 1 || j - i == 1) ? -1.0 : 0.0);
        }
    }
}

static mech_modal_options_t default_options(void) {
    mech_modal_options_t o;
    memset(&o, 0, sizeof o);
    o.selection = MECH_MODAL_SELECTION_ALL;
    o.vectors = 1;
    o.refinement = MECH_MODAL_REFINEMENT_AUTO;
    return o;
}

static void all_pairs(void) {
    double a[N * N], b[N * N];
    fixed_chain(a, b);
    mech_modal_options_t o = default_options();
    mech_modal_result_t *r = NULL;
    CHECK_STATUS(mech_modal_solve(N, a, b, &o, &r), MECH_STATUS_OK);
    CHECK(r != NULL);
    size_t m = 0, dim = 0;
    CHECK_STATUS(mech_modal_result_size(r, &m, &dim), MECH_STATUS_OK);
    CHECK(m == N && dim == N);

    double lambda[N];
    CHECK_STATUS(mech_modal_result_eigenvalues(r, lambda, N), MECH_STATUS_OK);
    mech_modal_mode_t modes[N];
    CHECK_STATUS(mech_modal_result_modes(r, modes, N), MECH_STATUS_OK);
    const double pi = 3.14159265358979323846;
    for (int k = 0; k < N; ++k) {
        double s = sin((k + 1) * pi / (2.0 * (N + 1)));
        double w2 = 4.0 * s * s;
        CHECK_NEAR(-lambda[k], w2, modes[k].error_bound + 1e-15);
        CHECK(modes[k].kind == MECH_MODAL_KIND_OSCILLATORY);
        CHECK_NEAR(modes[k].rate, sqrt(w2), 1e-14);
        CHECK(modes[k].backward_error >= 0.0 && modes[k].backward_error <= 10.0 * N * 2.2e-16);
        CHECK(modes[k].multiplicity == 1);
    }

    double x[N * N];
    CHECK_STATUS(mech_modal_result_vectors(r, x, N * N), MECH_STATUS_OK);
    /* A = I: the columns are orthonormal and satisfy B x = ω² x. */
    for (int k = 0; k < N; ++k) {
        double nrm = 0.0;
        for (int i = 0; i < N; ++i) nrm += x[i + N * k] * x[i + N * k];
        CHECK_NEAR(nrm, 1.0, 1e-14);
        for (int i = 0; i < N; ++i) {
            double bx = 0.0;
            for (int j = 0; j < N; ++j) bx += b[i + N * j] * x[j + N * k];
            CHECK_NEAR(bx, -lambda[k] * x[i + N * k], 1e-14);
        }
    }

    mech_modal_accuracy_t acc;
    CHECK_STATUS(mech_modal_result_accuracy(r, &acc), MECH_STATUS_OK);
    CHECK(acc.max_backward_error >= 0.0 && acc.max_backward_error <= 10.0 * N * 2.2e-16);
    CHECK(acc.orthogonality_error >= 0.0 && acc.orthogonality_error <= 10.0 * N * 2.2e-16);
    CHECK(acc.inertia_checked == 1 && acc.inertia_consistent == 1);
    CHECK(acc.inertia_below == acc.computed_below);
    CHECK(acc.massless == 0);

    /* Buffers too small: error, nothing written. */
    double small[N * N];
    FILL_SENTINEL(small, sizeof small);
    CHECK_STATUS(mech_modal_result_eigenvalues(r, small, N - 1), MECH_STATUS_BUFFER_TOO_SMALL);
    CHECK_STATUS(mech_modal_result_vectors(r, small, N * N - 1), MECH_STATUS_BUFFER_TOO_SMALL);
    mech_modal_mode_t small_modes[N];
    FILL_SENTINEL(small_modes, sizeof small_modes);
    CHECK_STATUS(mech_modal_result_modes(r, small_modes, 2), MECH_STATUS_BUFFER_TOO_SMALL);
    CHECK(mech_untouched(small, sizeof small));
    CHECK(mech_untouched(small_modes, sizeof small_modes));
    /* NULL outputs. */
    CHECK_STATUS(mech_modal_result_eigenvalues(r, NULL, N), MECH_STATUS_NULL_POINTER);
    CHECK_STATUS(mech_modal_result_accuracy(r, NULL), MECH_STATUS_NULL_POINTER);
    CHECK_STATUS(mech_modal_result_size(r, NULL, &dim), MECH_STATUS_NULL_POINTER);
    mech_modal_result_destroy(r);
}

static void subsets_and_values_only(void) {
    double a[N * N], b[N * N];
    fixed_chain(a, b);
    mech_modal_options_t o = default_options();
    o.selection = MECH_MODAL_SELECTION_LOWEST;
    o.count = 2;
    mech_modal_result_t *r = NULL;
    CHECK_STATUS(mech_modal_solve(N, a, b, &o, &r), MECH_STATUS_OK);
    size_t m = 0, dim = 0;
    CHECK_STATUS(mech_modal_result_size(r, &m, &dim), MECH_STATUS_OK);
    CHECK(m == 2);
    double x[N * 2];
    CHECK_STATUS(mech_modal_result_vectors(r, x, N * 2), MECH_STATUS_OK);
    mech_modal_result_destroy(r);

    o.selection = MECH_MODAL_SELECTION_INTERVAL;
    o.lower = 1.0;
    o.upper = 3.0;
    o.vectors = 0;
    CHECK_STATUS(mech_modal_solve(N, a, b, &o, &r), MECH_STATUS_OK);
    CHECK_STATUS(mech_modal_result_size(r, &m, &dim), MECH_STATUS_OK);
    /* ω² = 4 sin²(kπ/14) = 1.55 (k = 3) and 2.45 (k = 4) lie in [1, 3]; k = 2, 5 give 0.75, 3.25. */
    CHECK(m == 2);
    mech_modal_mode_t modes[2];
    CHECK_STATUS(mech_modal_result_modes(r, modes, 2), MECH_STATUS_OK);
    CHECK(modes[0].backward_error == -1.0);
    CHECK_STATUS(mech_modal_result_vectors(r, x, N * 2), MECH_STATUS_INVALID_ARGUMENT);
    mech_modal_accuracy_t acc;
    CHECK_STATUS(mech_modal_result_accuracy(r, &acc), MECH_STATUS_OK);
    CHECK(acc.max_backward_error == -1.0 && acc.orthogonality_error == -1.0);
    mech_modal_result_destroy(r);

    size_t below = 0;
    CHECK_STATUS(mech_modal_count_below(N, a, b, 2.0, &below), MECH_STATUS_OK);
    CHECK(below == 3);
}

static void massless_coordinate(void) {
    /* ground–m–(massless)–m–ground with unit springs: ω² = 1, 2 and one infinite mode. */
    double a[9] = {1, 0, 0, 0, 0, 0, 0, 0, 1};
    double b[9] = {2, -1, 0, -1, 2, -1, 0, -1, 2};
    mech_modal_options_t o = default_options();
    mech_modal_result_t *r = NULL;
    CHECK_STATUS(mech_modal_solve(3, a, b, &o, &r), MECH_STATUS_OK);
    mech_modal_mode_t modes[3];
    CHECK_STATUS(mech_modal_result_modes(r, modes, 3), MECH_STATUS_OK);
    CHECK_NEAR(modes[0].omega_sq, 1.0, modes[0].error_bound);
    CHECK_NEAR(modes[1].omega_sq, 2.0, modes[1].error_bound);
    CHECK(modes[2].kind == MECH_MODAL_KIND_INFINITE);
    CHECK(isinf(modes[2].omega_sq) && modes[2].omega_sq > 0.0);
    mech_modal_accuracy_t acc;
    CHECK_STATUS(mech_modal_result_accuracy(r, &acc), MECH_STATUS_OK);
    CHECK(acc.massless == 1);
    /* The condensed solve is certified too: the count of B − sA, less B₀₀'s negative
     * eigenvalues (none here), matches the computed modes below s. */
    CHECK(acc.inertia_checked == 1 && acc.inertia_consistent == 1);
    CHECK(acc.inertia_below == acc.computed_below);
    mech_modal_result_destroy(r);

    /* The massless node held by a negative ground spring (−3): B₀₀ = −1, condensed stiffness
     * [[3, 1], [1, 3]], ω² = 2 and 4; B − sA has one more negative eigenvalue than there are
     * modes below s, which the check allows for (Haynsworth inertia additivity). */
    double bn[9] = {2, -1, 0, -1, -1, -1, 0, -1, 2};
    CHECK_STATUS(mech_modal_solve(3, a, bn, &o, &r), MECH_STATUS_OK);
    CHECK_STATUS(mech_modal_result_modes(r, modes, 3), MECH_STATUS_OK);
    CHECK_NEAR(modes[0].omega_sq, 2.0, modes[0].error_bound);
    CHECK_NEAR(modes[1].omega_sq, 4.0, modes[1].error_bound);
    CHECK(modes[2].kind == MECH_MODAL_KIND_INFINITE);
    CHECK_STATUS(mech_modal_result_accuracy(r, &acc), MECH_STATUS_OK);
    CHECK(acc.inertia_checked == 1 && acc.inertia_consistent == 1);
    CHECK(acc.inertia_below == acc.computed_below);
    mech_modal_result_destroy(r);
}

static void error_paths(void) {
    double a[N * N], b[N * N];
    fixed_chain(a, b);
    mech_modal_options_t o = default_options();
    mech_modal_result_t *r;
    FILL_SENTINEL(&r, sizeof r);

    CHECK_STATUS(mech_modal_solve(N, NULL, b, &o, &r), MECH_STATUS_NULL_POINTER);
    CHECK_STATUS(mech_modal_solve(N, a, b, NULL, &r), MECH_STATUS_NULL_POINTER);
    CHECK_STATUS(mech_modal_solve(N, a, b, &o, NULL), MECH_STATUS_NULL_POINTER);
    CHECK_STATUS(mech_modal_solve(0, a, b, &o, &r), MECH_STATUS_BAD_DIMENSION);
    CHECK_STATUS(mech_modal_solve((size_t)-1, a, b, &o, &r), MECH_STATUS_BAD_DIMENSION);

    mech_modal_options_t bad = o;
    bad.selection = 7;
    CHECK_STATUS(mech_modal_solve(N, a, b, &bad, &r), MECH_STATUS_BAD_ENUM);
    bad = o;
    bad.refinement = -1;
    CHECK_STATUS(mech_modal_solve(N, a, b, &bad, &r), MECH_STATUS_BAD_ENUM);
    bad = o;
    bad.vectors = 2;
    CHECK_STATUS(mech_modal_solve(N, a, b, &bad, &r), MECH_STATUS_INVALID_ARGUMENT);
    bad = o;
    bad.selection = MECH_MODAL_SELECTION_LOWEST;
    bad.count = N + 1;
    CHECK_STATUS(mech_modal_solve(N, a, b, &bad, &r), MECH_STATUS_INVALID_ARGUMENT);
    bad = o;
    bad.selection = MECH_MODAL_SELECTION_INTERVAL;
    bad.lower = NAN;
    bad.upper = 1.0;
    CHECK_STATUS(mech_modal_solve(N, a, b, &bad, &r), MECH_STATUS_NON_FINITE);
    bad.lower = 2.0;
    CHECK_STATUS(mech_modal_solve(N, a, b, &bad, &r), MECH_STATUS_INVALID_ARGUMENT);

    double saved = b[3];
    b[3] = INFINITY;
    CHECK_STATUS(mech_modal_solve(N, a, b, &o, &r), MECH_STATUS_NON_FINITE);
    CHECK_STATUS(mech_modal_check_pencil(N, a, b), MECH_STATUS_NON_FINITE);
    b[3] = 0.5; /* b[3 + 0·N] ≠ b[0 + 3·N]: asymmetric */
    CHECK_STATUS(mech_modal_solve(N, a, b, &o, &r), MECH_STATUS_INVALID_ARGUMENT);
    CHECK_STATUS(mech_modal_check_pencil(N, a, b), MECH_STATUS_INVALID_ARGUMENT);
    b[3] = saved;
    CHECK_STATUS(mech_modal_check_pencil(N, a, b), MECH_STATUS_OK);

    a[2 + 2 * N] = -1.0; /* indefinite mass */
    CHECK_STATUS(mech_modal_solve(N, a, b, &o, &r), MECH_STATUS_NOT_POSITIVE_DEFINITE);
    {
        char msg[256];
        mech_last_error(msg, sizeof msg);
        CHECK(strstr(msg, "pivot 2") != NULL);
    }
    a[2 + 2 * N] = 1.0;

    double sa[4] = {1, 0, 0, 0}, sb[4] = {1, 0, 0, 0}; /* det(λA + B) ≡ 0 */
    CHECK_STATUS(mech_modal_solve(2, sa, sb, &o, &r), MECH_STATUS_SINGULAR);
    CHECK(mech_untouched(&r, sizeof r));

    size_t below;
    FILL_SENTINEL(&below, sizeof below);
    CHECK_STATUS(mech_modal_count_below(N, a, b, NAN, &below), MECH_STATUS_NON_FINITE);
    CHECK_STATUS(mech_modal_count_below(N, a, NULL, 1.0, &below), MECH_STATUS_NULL_POINTER);
    CHECK_STATUS(mech_modal_count_below(N, a, b, 1.0, NULL), MECH_STATUS_NULL_POINTER);
    CHECK(mech_untouched(&below, sizeof below));

    double lambda[N];
    size_t m;
    mech_modal_mode_t modes[N];
    mech_modal_accuracy_t acc;
    CHECK_STATUS(mech_modal_result_size(NULL, &m, &m), MECH_STATUS_NULL_POINTER);
    CHECK_STATUS(mech_modal_result_eigenvalues(NULL, lambda, N), MECH_STATUS_NULL_POINTER);
    CHECK_STATUS(mech_modal_result_modes(NULL, modes, N), MECH_STATUS_NULL_POINTER);
    CHECK_STATUS(mech_modal_result_vectors(NULL, lambda, N), MECH_STATUS_NULL_POINTER);
    CHECK_STATUS(mech_modal_result_accuracy(NULL, &acc), MECH_STATUS_NULL_POINTER);
    mech_modal_result_destroy(NULL);
}

static void free_response(void) {
    /* ground–m–m–ground, unit springs: ω² = 1 (x = (1, 1)/√2) and 3 (x = (1, −1)/√2). From
     * δ(0) = (1, 0), δ̇(0) = 0: δ(t) = ½(cos t + cos √3t, cos t − cos √3t). */
    double a[4] = {1, 0, 0, 1}, b[4] = {2, -1, -1, 2};
    mech_modal_options_t o = default_options();
    mech_modal_result_t *r = NULL;
    CHECK_STATUS(mech_modal_solve(2, a, b, &o, &r), MECH_STATUS_OK);
    const double d0[2] = {1.0, 0.0}, v0[2] = {0.0, 0.0};
    const double times[3] = {0.0, 0.7, -2.5};
    double d[6], v[6];
    mech_modal_response_fit_t fit;
    CHECK_STATUS(mech_modal_free_response(r, d0, v0, times, 3, d, 6, v, 6, &fit), MECH_STATUS_OK);
    const double s3 = sqrt(3.0);
    for (int j = 0; j < 3; ++j) {
        double t = times[j];
        CHECK_NEAR(d[2 * j], 0.5 * (cos(t) + cos(s3 * t)), 1e-14);
        CHECK_NEAR(d[2 * j + 1], 0.5 * (cos(t) - cos(s3 * t)), 1e-14);
        CHECK_NEAR(v[2 * j], -0.5 * (sin(t) + s3 * sin(s3 * t)), 1e-14);
        CHECK_NEAR(v[2 * j + 1], -0.5 * (sin(t) - s3 * sin(s3 * t)), 1e-14);
    }
    CHECK(fit.relative_displacement_residual <= 1e-15 && fit.velocity_residual == 0.0);
    CHECK(fit.max_error_bound >= 0.0 && fit.max_error_bound < 1e-13);
    CHECK(fit.massless == 0);
    /* Velocity and fit are optional. */
    CHECK_STATUS(mech_modal_free_response(r, d0, v0, times, 3, d, 6, NULL, 0, NULL), MECH_STATUS_OK);

    /* Errors: nothing written. */
    double sentinel[6];
    FILL_SENTINEL(sentinel, sizeof sentinel);
    mech_modal_response_fit_t fit_sentinel;
    FILL_SENTINEL(&fit_sentinel, sizeof fit_sentinel);
    CHECK_STATUS(mech_modal_free_response(NULL, d0, v0, times, 3, sentinel, 6, NULL, 0, NULL),
                 MECH_STATUS_NULL_POINTER);
    CHECK_STATUS(mech_modal_free_response(r, NULL, v0, times, 3, sentinel, 6, NULL, 0, &fit_sentinel),
                 MECH_STATUS_NULL_POINTER);
    CHECK_STATUS(mech_modal_free_response(r, d0, v0, NULL, 3, sentinel, 6, NULL, 0, NULL), MECH_STATUS_NULL_POINTER);
    CHECK_STATUS(mech_modal_free_response(r, d0, v0, times, 3, NULL, 6, NULL, 0, NULL), MECH_STATUS_NULL_POINTER);
    CHECK_STATUS(mech_modal_free_response(r, d0, v0, times, 3, sentinel, 5, NULL, 0, &fit_sentinel),
                 MECH_STATUS_BUFFER_TOO_SMALL);
    CHECK_STATUS(mech_modal_free_response(r, d0, v0, times, 3, sentinel, 6, sentinel, 4, &fit_sentinel),
                 MECH_STATUS_BUFFER_TOO_SMALL);
    const double bad_times[2] = {0.0, NAN};
    CHECK_STATUS(mech_modal_free_response(r, d0, v0, bad_times, 2, sentinel, 6, NULL, 0, &fit_sentinel),
                 MECH_STATUS_NON_FINITE);
    const double bad_d0[2] = {INFINITY, 0.0};
    CHECK_STATUS(mech_modal_free_response(r, bad_d0, v0, times, 3, sentinel, 6, NULL, 0, &fit_sentinel),
                 MECH_STATUS_NON_FINITE);
    CHECK(mech_untouched(sentinel, sizeof sentinel));
    CHECK(mech_untouched(&fit_sentinel, sizeof fit_sentinel));
    mech_modal_result_destroy(r);

    /* A values-only result cannot give a response. */
    o.vectors = 0;
    CHECK_STATUS(mech_modal_solve(2, a, b, &o, &r), MECH_STATUS_OK);
    CHECK_STATUS(mech_modal_free_response(r, d0, v0, times, 3, sentinel, 6, NULL, 0, NULL),
                 MECH_STATUS_INVALID_ARGUMENT);
    CHECK(mech_untouched(sentinel, sizeof sentinel));
    mech_modal_result_destroy(r);

    /* Free pair (rigid-body mode): from δ̇(0) = (1, 0) the centre drifts at ½ m/s and
     * δ₁(t) = t/2 + sin(√2 t)/(2√2). An inverted pair overflows at t = 1e4. */
    double bf[4] = {1, -1, -1, 1};
    o.vectors = 1;
    CHECK_STATUS(mech_modal_solve(2, a, bf, &o, &r), MECH_STATUS_OK);
    const double zero[2] = {0.0, 0.0}, push[2] = {1.0, 0.0}, t4[1] = {4.0};
    CHECK_STATUS(mech_modal_free_response(r, zero, push, t4, 1, d, 2, NULL, 0, NULL), MECH_STATUS_OK);
    const double s2 = sqrt(2.0);
    CHECK_NEAR(d[0], 2.0 + sin(s2 * 4.0) / (2.0 * s2), 1e-13);
    CHECK_NEAR(d[1], 2.0 - sin(s2 * 4.0) / (2.0 * s2), 1e-13);
    mech_modal_result_destroy(r);
    double bu[4] = {-1, 0, 0, -1};
    CHECK_STATUS(mech_modal_solve(2, a, bu, &o, &r), MECH_STATUS_OK);
    const double late[1] = {1e4};
    FILL_SENTINEL(sentinel, sizeof sentinel);
    CHECK_STATUS(mech_modal_free_response(r, push, zero, late, 1, sentinel, 2, NULL, 0, NULL),
                 MECH_STATUS_INVALID_ARGUMENT);
    CHECK(mech_untouched(sentinel, sizeof sentinel));
    mech_modal_result_destroy(r);
}

/* A 30×30 grid Laplacian (n = 900 > the dense limit): the 4 lowest
 * ω² = 4 sin²(pπ/62) + 4 sin²(qπ/62), (p, q) = (1, 1), (1, 2), (2, 1), (2, 2) (a double pair). */
#define G 30
#define GN (G * G)
static void sparse_lowest(void) {
    static size_t acp[GN + 1], arow[GN], bcp[GN + 1], brow[5 * GN];
    static double aval[GN], bval[5 * GN];
    size_t nb = 0;
    for (size_t c = 0; c < GN; ++c) {
        acp[c] = c;
        arow[c] = c;
        aval[c] = 1.0;
        size_t i = c % G, j = c / G;
        bcp[c] = nb;
        /* rows ascending within the column */
        if (j > 0) { brow[nb] = c - G; bval[nb++] = -1.0; }
        if (i > 0) { brow[nb] = c - 1; bval[nb++] = -1.0; }
        brow[nb] = c; bval[nb++] = 4.0;
        if (i + 1 < G) { brow[nb] = c + 1; bval[nb++] = -1.0; }
        if (j + 1 < G) { brow[nb] = c + G; bval[nb++] = -1.0; }
    }
    acp[GN] = GN;
    bcp[GN] = nb;
    double w[4], e[4];
    static double x[GN * 4];
    mech_modal_sparse_report_t rep;
    CHECK_STATUS(mech_modal_sparse_lowest(GN, acp, arow, aval, bcp, brow, bval, 4, w, e, x, &rep), MECH_STATUS_OK);
    const double pi = 3.14159265358979323846;
    double s1 = 4.0 * pow(sin(pi / 62.0), 2), s2 = 4.0 * pow(sin(2.0 * pi / 62.0), 2);
    double exact[4] = {2.0 * s1, s1 + s2, s1 + s2, 2.0 * s2};
    for (int k = 0; k < 4; ++k) {
        CHECK_NEAR(w[k], exact[k], e[k] + 4.0 * 2.2e-16 * exact[k]);
        CHECK(e[k] >= 0.0 && e[k] < 1e-12);
    }
    CHECK(rep.inertia_consistent == 1 && rep.inertia_below == rep.computed_below);
    /* The promised backward error (the header): η ≲ 1e-12·√κ(A)·‖K‖₂/‖B‖_F with A = I and
     * ‖K‖₂ = ‖B − σI‖₂ ≤ 8 + |σ| (Gershgorin: 4 + 4 neighbours). */
    double frobenius_b = 0.0;
    for (size_t k = 0; k < nb; ++k) frobenius_b += bval[k] * bval[k];
    frobenius_b = sqrt(frobenius_b);
    CHECK(rep.max_backward_error <= 1e-12 * (8.0 + fabs(rep.shift)) / frobenius_b);
    CHECK(rep.orthogonality_error < 1e-12);
    CHECK(rep.factor_nnz > 0 && rep.operator_applications > 0);
    CHECK_STATUS(mech_modal_sparse_lowest(GN, acp, arow, aval, bcp, brow, bval, 2, w, NULL, NULL, NULL), MECH_STATUS_OK);

    /* mech_modal_sparse_solve: the same modes with their full records. A zero-initialised
     * options struct with count set is the default solve. */
    mech_modal_sparse_options_t so;
    memset(&so, 0, sizeof so);
    so.count = 4;
    mech_modal_mode_t md[4];
    mech_modal_sparse_report_t rep2;
    mech_modal_sparse_details_t det;
    CHECK_STATUS(mech_modal_sparse_solve(GN, acp, arow, aval, bcp, brow, bval, &so, md, NULL, &rep2, &det), MECH_STATUS_OK);
    for (int k = 0; k < 4; ++k) {
        CHECK(md[k].omega_sq == w[k] && md[k].error_bound == e[k]);
        CHECK(md[k].kind == MECH_MODAL_KIND_OSCILLATORY && fabs(md[k].rate * md[k].rate - w[k]) <= 1e-15 * w[k]);
        CHECK(md[k].lambda == -w[k] && md[k].backward_error >= 0.0 && md[k].backward_error <= rep2.max_backward_error);
    }
    CHECK(md[1].group == md[2].group && md[1].multiplicity == 2 && md[0].multiplicity == 1 && md[3].group != md[2].group);
    CHECK(det.lanczos_runs >= 1 && det.kth_group_multiplicity == 1 && det.shift_attempts >= 1);
    CHECK(det.factor_seconds > 0.0 && det.lanczos_seconds > 0.0 && det.refine_seconds >= 0.0);
    CHECK(rep2.inertia_consistent == 1);
    /* count = 2 cuts the double eigenvalue: two modes come back, the details give its whole
     * multiplicity. A looser tolerance still gives bounds that hold. */
    so.count = 2;
    so.tolerance = 1e-8;
    so.block_size = 3;
    CHECK_STATUS(mech_modal_sparse_solve(GN, acp, arow, aval, bcp, brow, bval, &so, md, x, NULL, &det), MECH_STATUS_OK);
    CHECK(det.kth_group_multiplicity == 2);
    for (int k = 0; k < 2; ++k) CHECK_NEAR(md[k].omega_sq, exact[k], md[k].error_bound + 4.0 * 2.2e-16 * exact[k]);
    /* B − cA with c the double eigenvalue: the lowest mode becomes unstable (growth rate
     * √(c − 2s1)), the double one zero to the rounding of the shifted diagonal (one group of
     * two), the next oscillatory. An explicit σ below the spectrum is used as given. */
    double c = s1 + s2;
    for (size_t k = 0; k < nb; ++k) {
        if (bval[k] == 4.0) bval[k] = 4.0 - c;
    }
    so.count = 4;
    so.tolerance = 0.0;
    so.block_size = 0;
    so.shift_given = 1;
    so.shift = -1.0;
    CHECK_STATUS(mech_modal_sparse_solve(GN, acp, arow, aval, bcp, brow, bval, &so, md, NULL, &rep2, NULL), MECH_STATUS_OK);
    CHECK(rep2.shift == -1.0);
    CHECK(md[0].kind == MECH_MODAL_KIND_UNSTABLE);
    CHECK_NEAR(md[0].rate, sqrt(c - 2.0 * s1), 1e-12);
    CHECK(md[1].kind == MECH_MODAL_KIND_ZERO && md[2].kind == MECH_MODAL_KIND_ZERO);
    CHECK(md[1].group == md[2].group && md[1].multiplicity == 2 && md[1].rate == 0.0);
    CHECK(md[3].kind == MECH_MODAL_KIND_OSCILLATORY);
    for (size_t k = 0; k < nb; ++k) {
        if (bval[k] == 4.0 - c) bval[k] = 4.0;
    }
    /* Bad options: nothing written. */
    mech_modal_mode_t untouched[4];
    FILL_SENTINEL(untouched, sizeof untouched);
    so.shift_given = 0;
    so.tolerance = NAN;
    CHECK_STATUS(mech_modal_sparse_solve(GN, acp, arow, aval, bcp, brow, bval, &so, untouched, NULL, NULL, NULL),
                 MECH_STATUS_NON_FINITE);
    so.tolerance = 1.5;
    CHECK_STATUS(mech_modal_sparse_solve(GN, acp, arow, aval, bcp, brow, bval, &so, untouched, NULL, NULL, NULL),
                 MECH_STATUS_INVALID_ARGUMENT);
    so.tolerance = 0.0;
    so.shift_given = 2;
    CHECK_STATUS(mech_modal_sparse_solve(GN, acp, arow, aval, bcp, brow, bval, &so, untouched, NULL, NULL, NULL),
                 MECH_STATUS_INVALID_ARGUMENT);
    so.shift_given = 0;
    CHECK_STATUS(mech_modal_sparse_solve(GN, acp, arow, aval, bcp, brow, bval, NULL, untouched, NULL, NULL, NULL),
                 MECH_STATUS_NULL_POINTER);
    so.count = GN + 1;
    CHECK_STATUS(mech_modal_sparse_solve(GN, acp, arow, aval, bcp, brow, bval, &so, untouched, NULL, NULL, NULL),
                 MECH_STATUS_INVALID_ARGUMENT);
    CHECK(mech_untouched(untouched, sizeof untouched));

    /* Errors: nothing written. */
    double ws[4];
    FILL_SENTINEL(ws, sizeof ws);
    CHECK_STATUS(mech_modal_sparse_lowest(GN, acp, arow, aval, bcp, brow, bval, 0, ws, NULL, NULL, NULL),
                 MECH_STATUS_INVALID_ARGUMENT);
    CHECK_STATUS(mech_modal_sparse_lowest(GN, NULL, arow, aval, bcp, brow, bval, 4, ws, NULL, NULL, NULL),
                 MECH_STATUS_NULL_POINTER);
    CHECK_STATUS(mech_modal_sparse_lowest(GN, acp, arow, aval, bcp, brow, bval, 4, NULL, NULL, NULL, NULL),
                 MECH_STATUS_NULL_POINTER);
    CHECK_STATUS(mech_modal_sparse_lowest(0, acp, arow, aval, bcp, brow, bval, 4, ws, NULL, NULL, NULL),
                 MECH_STATUS_BAD_DIMENSION);
    arow[5] = GN; /* row index out of range */
    CHECK_STATUS(mech_modal_sparse_lowest(GN, acp, arow, aval, bcp, brow, bval, 4, ws, NULL, NULL, NULL),
                 MECH_STATUS_BAD_DIMENSION);
    arow[5] = 5;
    aval[5] = NAN;
    CHECK_STATUS(mech_modal_sparse_lowest(GN, acp, arow, aval, bcp, brow, bval, 4, ws, NULL, NULL, NULL),
                 MECH_STATUS_NON_FINITE);
    aval[5] = 1.0;
    bval[1] = -0.5; /* B asymmetric */
    CHECK_STATUS(mech_modal_sparse_lowest(GN, acp, arow, aval, bcp, brow, bval, 4, ws, NULL, NULL, NULL),
                 MECH_STATUS_INVALID_ARGUMENT);
    bval[1] = -1.0;
    acp[3] = acp[2] - 1; /* decreasing column pointers */
    CHECK_STATUS(mech_modal_sparse_lowest(GN, acp, arow, aval, bcp, brow, bval, 4, ws, NULL, NULL, NULL),
                 MECH_STATUS_INVALID_ARGUMENT);
    acp[3] = 3;
    CHECK(mech_untouched(ws, sizeof ws));
}

/* The sketched report (mech_modal_solve_with_residuals) bounds the exact one from above, within
 * the factor its Gaussian lower tail allows (plus the n·u rounding both carry), on a chain with
 * graded masses; the eigenvalues are the same to their bounds; an unknown kind is refused. The
 * order is past the crossover (n ≈ 200 for all pairs) below which the exact products are formed
 * even when a sketch is asked for, because they cost less. */
#define NS 300
static void sketched_report(void) {
    static double a[NS * NS], b[NS * NS];
    for (int j = 0; j < NS; ++j) {
        for (int i = 0; i < NS; ++i) {
            double mi = 1.0 + (double)i / NS, mj = 1.0 + (double)j / NS;
            double t = (i == j) ? 2.0 : ((i - j == 1 || j - i == 1) ? -1.0 : 0.0);
            a[i + NS * j] = (i == j) ? mi : 0.0;
            b[i + NS * j] = sqrt(mi * mj) * t; /* ω² = 4 sin²(kπ/(2(NS+1))) */
        }
    }
    mech_modal_options_t o = default_options();
    mech_modal_result_t *exact = NULL, *sketched = NULL;
    CHECK_STATUS(mech_modal_solve_with_residuals(NS, a, b, &o, MECH_MODAL_RESIDUALS_EXACT, &exact), MECH_STATUS_OK);
    CHECK_STATUS(mech_modal_solve_with_residuals(NS, a, b, &o, MECH_MODAL_RESIDUALS_SKETCHED, &sketched),
                 MECH_STATUS_OK);
    static mech_modal_mode_t me[NS], ms[NS];
    CHECK_STATUS(mech_modal_result_modes(exact, me, NS), MECH_STATUS_OK);
    CHECK_STATUS(mech_modal_result_modes(sketched, ms, NS), MECH_STATUS_OK);
    const double pi = 3.14159265358979323846, u = 2.220446049250313e-16, floor = NS * u;
    for (int k = 0; k < NS; ++k) {
        double s = sin((k + 1) * pi / (2.0 * (NS + 1)));
        CHECK_NEAR(ms[k].omega_sq, 4.0 * s * s, ms[k].error_bound);
        if (me[k].omega_sq == ms[k].omega_sq) {
            CHECK(ms[k].backward_error + floor >= me[k].backward_error);
            CHECK(ms[k].backward_error <= 8.0 * me[k].backward_error + floor);
        }
    }
    mech_modal_accuracy_t ae, as;
    CHECK_STATUS(mech_modal_result_accuracy(exact, &ae), MECH_STATUS_OK);
    CHECK_STATUS(mech_modal_result_accuracy(sketched, &as), MECH_STATUS_OK);
    CHECK(as.orthogonality_error >= ae.orthogonality_error);
    CHECK(as.max_backward_error <= 10.0 * NS * u);
    CHECK(as.inertia_checked == 1 && as.inertia_consistent == 1);
    mech_modal_result_destroy(exact);
    mech_modal_result_destroy(sketched);

    mech_modal_result_t *untouched = (mech_modal_result_t *)&o;
    CHECK_STATUS(mech_modal_solve_with_residuals(NS, a, b, &o, 7, &untouched), MECH_STATUS_BAD_ENUM);
    CHECK(untouched == (mech_modal_result_t *)&o);
}

/* A dense pencil large enough for every path of the blocked eigen-decomposition: several
 * 32-column panels, the two-thread symmetric matrix-vector product (trailing orders ≥ 640),
 * faer's tridiagonal divide and conquer (order ≥ 128) and the blocked Householder application.
 * The graded chain of sketched_report is turned by one Householder reflection H = I − 2uuᵀ/uᵀu
 * with a dense u, A' = HAH and B' = HBH: a congruence by an orthogonal matrix, so the closed
 * form ω²_k = 4 sin²(kπ/(2(n+1))) still holds while A' and B' are full. */
#define ND 700
/* M ← HMH for the order-n (n ≤ ND) column-major symmetric M, H = I − 2uuᵀ/uu. */
static void reflect(double *m, const double *u, double uu, int n) {
    static double mu[ND];
    double umu = 0.0;
    for (int i = 0; i < n; ++i) {
        double s = 0.0;
        for (int j = 0; j < n; ++j) s += m[i + n * j] * u[j];
        mu[i] = s;
        umu += u[i] * s;
    }
    /* HMH = M − 2(Mu)uᵀ/uu − 2u(Mu)ᵀ/uu + 4(uᵀMu) uuᵀ/uu² for symmetric M. */
    for (int j = 0; j < n; ++j) {
        for (int i = 0; i < n; ++i) {
            m[i + n * j] += -2.0 * (mu[i] * u[j] + u[i] * mu[j]) / uu + 4.0 * umu * u[i] * u[j] / (uu * uu);
        }
    }
}

static void dense_blocked_path(void) {
    static double a[ND * ND], b[ND * ND], u[ND];
    double uu = 0.0;
    for (int i = 0; i < ND; ++i) {
        u[i] = 1.0 + 0.5 * sin(0.37 * i) + (double)(i % 7) / 7.0;
        uu += u[i] * u[i];
    }
    for (int j = 0; j < ND; ++j) {
        for (int i = 0; i < ND; ++i) {
            double mi = 1.0 + (double)i / ND, mj = 1.0 + (double)j / ND;
            double t = (i == j) ? 2.0 : ((i - j == 1 || j - i == 1) ? -1.0 : 0.0);
            a[i + ND * j] = (i == j) ? mi : 0.0;
            b[i + ND * j] = sqrt(mi * mj) * t;
        }
    }
    reflect(a, u, uu, ND);
    reflect(b, u, uu, ND);
    /* Rounding of the reflection leaves the matrices symmetric to a few ulps; make them exact. */
    for (int j = 0; j < ND; ++j) {
        for (int i = j + 1; i < ND; ++i) {
            a[j + ND * i] = a[i + ND * j];
            b[j + ND * i] = b[i + ND * j];
        }
    }
    mech_modal_options_t o = default_options();
    o.refinement = MECH_MODAL_REFINEMENT_OFF;
    mech_modal_result_t *r = NULL;
    CHECK_STATUS(mech_modal_solve(ND, a, b, &o, &r), MECH_STATUS_OK);
    static mech_modal_mode_t modes[ND];
    CHECK_STATUS(mech_modal_result_modes(r, modes, ND), MECH_STATUS_OK);
    const double pi = 3.14159265358979323846, u_round = 2.220446049250313e-16;
    for (int k = 0; k < ND; ++k) {
        double s = sin((k + 1) * pi / (2.0 * (ND + 1)));
        /* The reflected pencil differs from the exact one by its own rounding, O(n·u·‖B‖). */
        CHECK_NEAR(modes[k].omega_sq, 4.0 * s * s, modes[k].error_bound + 4.0 * ND * u_round * 4.0);
        CHECK(modes[k].kind == MECH_MODAL_KIND_OSCILLATORY);
        CHECK(modes[k].backward_error >= 0.0 && modes[k].backward_error <= 10.0 * ND * u_round);
    }
    mech_modal_accuracy_t acc;
    CHECK_STATUS(mech_modal_result_accuracy(r, &acc), MECH_STATUS_OK);
    CHECK(acc.orthogonality_error >= 0.0 && acc.orthogonality_error <= 10.0 * ND * u_round);
    CHECK(acc.inertia_checked == 1 && acc.inertia_consistent == 1);
    /* Every mode computed: the Sturm check certifies the bottom of the spectrum (from n = 640
     * factored on idle core time): no mode below half the lowest computed ω², which lies below
     * the closed form's lowest. */
    double lowest = 4.0 * sin(pi / (2.0 * (ND + 1))) * sin(pi / (2.0 * (ND + 1)));
    CHECK(acc.inertia_below == 0 && acc.computed_below == 0);
    CHECK(acc.inertia_shift > 0.0 && acc.inertia_shift < lowest);
    CHECK_NEAR(acc.inertia_shift, 0.5 * modes[0].omega_sq, 1e-8 * modes[0].omega_sq);
    mech_modal_result_destroy(r);

    /* A second solve works in the n×n matrices the first one kept, a third after they were
     * released: each meets the closed form and the backward-error target, and agrees with the
     * first within the two bounds. */
    for (int pass = 0; pass < 2; ++pass) {
        if (pass == 1) {
            mech_modal_release_scratch();
        }
        mech_modal_result_t *again = NULL;
        CHECK_STATUS(mech_modal_solve(ND, a, b, &o, &again), MECH_STATUS_OK);
        static mech_modal_mode_t repeated[ND];
        CHECK_STATUS(mech_modal_result_modes(again, repeated, ND), MECH_STATUS_OK);
        for (int k = 0; k < ND; ++k) {
            double s = sin((k + 1) * pi / (2.0 * (ND + 1)));
            CHECK_NEAR(repeated[k].omega_sq, 4.0 * s * s, repeated[k].error_bound + 4.0 * ND * u_round * 4.0);
            CHECK_NEAR(repeated[k].omega_sq, modes[k].omega_sq, repeated[k].error_bound + modes[k].error_bound);
            CHECK(repeated[k].backward_error >= 0.0 && repeated[k].backward_error <= 10.0 * ND * u_round);
        }
        mech_modal_result_destroy(again);
    }

    /* Values only: without refinement every bound is the a-priori one (a backward error of n·u
     * assumed); with automatic refinement the weakly bounded lowest modes get their vectors
     * internally (inverse iteration on the tridiagonal form), so their bounds are measured and
     * far tighter, and every value still lies within its bound of the closed form. */
    o.vectors = 0;
    mech_modal_result_t *assumed = NULL, *measured = NULL;
    CHECK_STATUS(mech_modal_solve(ND, a, b, &o, &assumed), MECH_STATUS_OK);
    o.refinement = MECH_MODAL_REFINEMENT_AUTO;
    CHECK_STATUS(mech_modal_solve(ND, a, b, &o, &measured), MECH_STATUS_OK);
    static mech_modal_mode_t ma[ND], mm[ND];
    CHECK_STATUS(mech_modal_result_modes(assumed, ma, ND), MECH_STATUS_OK);
    CHECK_STATUS(mech_modal_result_modes(measured, mm, ND), MECH_STATUS_OK);
    for (int k = 0; k < ND; ++k) {
        double s = sin((k + 1) * pi / (2.0 * (ND + 1)));
        CHECK_NEAR(mm[k].omega_sq, 4.0 * s * s, mm[k].error_bound + 4.0 * ND * u_round * 4.0);
        CHECK(mm[k].backward_error == -1.0);
    }
    CHECK(mm[0].error_bound < 1e-2 * ma[0].error_bound);
    CHECK_STATUS(mech_modal_result_accuracy(measured, &acc), MECH_STATUS_OK);
    CHECK(acc.max_backward_error == -1.0 && acc.inertia_consistent == 1);
    mech_modal_result_destroy(assumed);
    mech_modal_result_destroy(measured);
}

/* Lumped masses over twelve decades with a dense stiffness, every entry exact in binary: H the
 * Sylvester–Hadamard matrix of order 64, a_ii = 4^k_i (k_i from −10 to 10), B = D^½ (HᵀTH/64) D^½
 * (integers times powers of two). D^−½ B D^−½ = (H/8)ᵀ T (H/8) is orthogonally similar to the
 * fixed chain's T, so ω² is the closed form; A is diagonal, so the solve scales instead of
 * factoring. Every ω² within its bound plus the closed form's own 4u, backward errors and the
 * A-orthogonality within 10·n·u, the Sturm check consistent, the lowest bound under 1e-8·ω². */
#define NL 64
static int lumped_power(int i) { return -10 + (20 * i) / (NL - 1); }

static void lumped_masses(void) {
    static double a[NL * NL], b[NL * NL], t[NL * NL], th[NL * NL];
    const double u_round = 2.220446049250313e-16, pi = 3.14159265358979323846;
    for (int j = 0; j < NL; ++j)
        for (int i = 0; i < NL; ++i) t[i + NL * j] = (i == j) ? 2.0 : ((i - j == 1 || j - i == 1) ? -1.0 : 0.0);
    /* th = T H, then b = Hᵀ th, all integer arithmetic. */
    for (int j = 0; j < NL; ++j)
        for (int i = 0; i < NL; ++i) {
            double sum = 0.0;
            for (int k = 0; k < NL; ++k) sum += t[i + NL * k] * ((__builtin_popcount(k & j) % 2) ? -1.0 : 1.0);
            th[i + NL * j] = sum;
        }
    for (int j = 0; j < NL; ++j)
        for (int i = 0; i < NL; ++i) {
            double sum = 0.0;
            for (int k = 0; k < NL; ++k) sum += ((__builtin_popcount(k & i) % 2) ? -1.0 : 1.0) * th[k + NL * j];
            b[i + NL * j] = ldexp(sum / NL, lumped_power(i) + lumped_power(j));
            a[i + NL * j] = (i == j) ? ldexp(1.0, 2 * lumped_power(i)) : 0.0;
        }
    mech_modal_options_t o = default_options();
    mech_modal_result_t *r = NULL;
    CHECK_STATUS(mech_modal_solve(NL, a, b, &o, &r), MECH_STATUS_OK);
    static mech_modal_mode_t modes[NL];
    CHECK_STATUS(mech_modal_result_modes(r, modes, NL), MECH_STATUS_OK);
    for (int k = 0; k < NL; ++k) {
        double s = sin((k + 1) * pi / (2.0 * (NL + 1)));
        double w2 = 4.0 * s * s;
        CHECK_NEAR(modes[k].omega_sq, w2, modes[k].error_bound + 4.0 * u_round * w2);
        CHECK(modes[k].kind == MECH_MODAL_KIND_OSCILLATORY);
        CHECK(modes[k].backward_error >= 0.0 && modes[k].backward_error <= 10.0 * NL * u_round);
    }
    CHECK(modes[0].error_bound <= 1e-8 * modes[0].omega_sq);
    mech_modal_accuracy_t acc;
    CHECK_STATUS(mech_modal_result_accuracy(r, &acc), MECH_STATUS_OK);
    CHECK(acc.orthogonality_error >= 0.0 && acc.orthogonality_error <= 10.0 * NL * u_round);
    CHECK(acc.inertia_checked == 1 && acc.inertia_consistent == 1);
    mech_modal_result_destroy(r);
}

/* Stiff series springs through massless nodes: NS unit masses, each pair of neighbours (and
 * each end and its wall) joined by k1 = 1e12 and k2 = 1 in series through a massless node, so
 * A = diag(0, 1, 0, …, 1, 0) and the condensed chain has springs k = k1 k2 / (k1 + k2):
 * ω²_j = 4 k sin²(jπ/(2(NS + 1))). The condensation cancels 12 digits; the lowest modes must
 * still be right to their bounds, and those bounds certify 13 digits (refinement measures
 * residuals of the stored A and B). With refinement off the lowest bound is honest but weak. */
#define NSERIES 40
static void stiff_massless_series(void) {
    const int n = 2 * NSERIES + 1;
    static double a[(2 * NSERIES + 1) * (2 * NSERIES + 1)], b[(2 * NSERIES + 1) * (2 * NSERIES + 1)];
    const double k1 = 1e12, k2 = 1.0, u_round = 2.220446049250313e-16, pi = 3.14159265358979323846;
    memset(a, 0, sizeof a);
    memset(b, 0, sizeof b);
    for (int s = 0; s <= NSERIES; ++s) {
        int node = 2 * s;
        b[node + n * node] += k1 + k2;
        if (s > 0) {
            b[(node - 1) + n * (node - 1)] += k1;
            b[(node - 1) + n * node] -= k1;
            b[node + n * (node - 1)] -= k1;
        }
        if (s < NSERIES) {
            b[(node + 1) + n * (node + 1)] += k2;
            b[(node + 1) + n * node] -= k2;
            b[node + n * (node + 1)] -= k2;
            a[(node + 1) + n * (node + 1)] = 1.0;
        }
    }
    const double spring = k1 * k2 / (k1 + k2);
    static mech_modal_mode_t modes[2 * NSERIES + 1];
    for (int refine = 0; refine < 2; ++refine) {
        mech_modal_options_t o = default_options();
        if (!refine) o.refinement = MECH_MODAL_REFINEMENT_OFF;
        mech_modal_result_t *r = NULL;
        CHECK_STATUS(mech_modal_solve(n, a, b, &o, &r), MECH_STATUS_OK);
        CHECK_STATUS(mech_modal_result_modes(r, modes, n), MECH_STATUS_OK);
        for (int k = 0; k < 5; ++k) {
            double s = sin((k + 1) * pi / (2.0 * (NSERIES + 1)));
            double w2 = 4.0 * spring * s * s;
            CHECK_NEAR(modes[k].omega_sq, w2, modes[k].error_bound + 8.0 * u_round * w2);
            CHECK(modes[k].kind == MECH_MODAL_KIND_OSCILLATORY);
            if (refine) CHECK(modes[k].error_bound <= 1e-13 * w2);
        }
        if (!refine) CHECK(modes[0].error_bound > 1e-6 * modes[0].omega_sq);
        CHECK(modes[n - 1].kind == MECH_MODAL_KIND_INFINITE);
        mech_modal_accuracy_t acc;
        CHECK_STATUS(mech_modal_result_accuracy(r, &acc), MECH_STATUS_OK);
        CHECK(acc.inertia_checked == 1 && acc.inertia_consistent == 1);
        mech_modal_result_destroy(r);
    }
}

/* A symmetric stiff structure: two uncoupled copies of the chain graded over 1e12 in stiffness
 * (spring i, from the ground or mass i − 1 to mass i, k_i = 10^round(12 i/23), unit masses),
 * interleaved (copy c's coordinate i is 2i + c). Every eigenvalue is double; the lowest two
 * references are the 60-digit mpmath values of tools/modal_reference.txt. The copies are refined
 * as one block: both values within their bounds, bounds that certify 8 digits or more, one group
 * of multiplicity 2; with refinement off the same pair's bound is honest but weak. */
#define NG 24
static void repeated_stiff_pair(void) {
    static double a[4 * NG * NG], b[4 * NG * NG];
    double k[NG + 1];
    for (int i = 0; i < NG; ++i) {
        k[i] = pow(10.0, round(12.0 * i / (NG - 1)));
    }
    k[NG] = 0.0;
    const int n = 2 * NG;
    for (int c = 0; c < 2; ++c) {
        for (int i = 0; i < NG; ++i) {
            int r = 2 * i + c;
            a[r + n * r] = 1.0;
            b[r + n * r] = k[i] + k[i + 1];
            if (i + 1 < NG) {
                b[r + n * (r + 2)] = -k[i + 1];
                b[(r + 2) + n * r] = -k[i + 1];
            }
        }
    }
    const double reference[2] = {3.491050226983499243542598e-2, 4.24397184079628978523204};
    for (int vectors = 0; vectors < 2; ++vectors) {
        mech_modal_options_t o = default_options();
        o.vectors = vectors;
        mech_modal_result_t *r = NULL;
        CHECK_STATUS(mech_modal_solve(n, a, b, &o, &r), MECH_STATUS_OK);
        static mech_modal_mode_t m[2 * NG];
        CHECK_STATUS(mech_modal_result_modes(r, m, n), MECH_STATUS_OK);
        for (int i = 0; i < 4; ++i) {
            double w = reference[i / 2];
            CHECK_NEAR(m[i].omega_sq, w, m[i].error_bound);
            CHECK(m[i].error_bound <= 1e-8 * w);
            CHECK(m[i].multiplicity == 2);
        }
        CHECK(m[0].group == m[1].group && m[2].group == m[3].group && m[1].group != m[2].group);
        mech_modal_accuracy_t acc;
        CHECK_STATUS(mech_modal_result_accuracy(r, &acc), MECH_STATUS_OK);
        CHECK(acc.refined_modes >= 4);
        mech_modal_result_destroy(r);
    }
    mech_modal_options_t off = default_options();
    off.refinement = MECH_MODAL_REFINEMENT_OFF;
    mech_modal_result_t *plain = NULL;
    CHECK_STATUS(mech_modal_solve(n, a, b, &off, &plain), MECH_STATUS_OK);
    mech_modal_mode_t low[2 * NG];
    CHECK_STATUS(mech_modal_result_modes(plain, low, n), MECH_STATUS_OK);
    CHECK_NEAR(low[0].omega_sq, reference[0], low[0].error_bound);
    CHECK(low[0].error_bound > 1e-8 * reference[0]);
    mech_modal_result_destroy(plain);
}

/* One chain graded over 1e12 in stiffness (k_i = 10^round(12 i/95), unit masses), long enough
 * (3n − 2 nonzeros ≤ n²/16) that the solver refines it on sparse factorizations with
 * double-double iterates: the lowest three modes, with vectors and values only, are within
 * their bounds of the 60-digit mpmath references (tools/modal_reference.txt,
 * graded_stiffness_n96), and the bounds certify 12 digits or more (before: 8.9e-7 relative for
 * the lowest with vectors, 0.47 values only). Without refinement the lowest bound is weak. The
 * same chain turned densely must be certified to 8 digits by the dense refinement paths. */
#define NS96 96
/* Entry (r, c) of the 4×4 Hadamard matrix over 2: ±1/2 by the parity of r AND c. */
static double hadamard_entry(int r, int c) {
    int bits = r & c;
    return ((bits ^ (bits >> 1)) & 1) ? -0.5 : 0.5;
}

/* The lowest three modes of (a, b) with Auto refinement, with vectors and values only: each
 * within its bound of `reference`, and the bound at most `relative` times the reference. */
static void lowest_three_certified(int n, const double *a, const double *b, const double *reference,
                                   double relative) {
    for (int vectors = 0; vectors < 2; ++vectors) {
        mech_modal_options_t o = default_options();
        o.vectors = vectors;
        o.selection = MECH_MODAL_SELECTION_LOWEST;
        o.count = 3;
        mech_modal_result_t *r = NULL;
        CHECK_STATUS(mech_modal_solve(n, a, b, &o, &r), MECH_STATUS_OK);
        mech_modal_mode_t m[3];
        CHECK_STATUS(mech_modal_result_modes(r, m, 3), MECH_STATUS_OK);
        for (int i = 0; i < 3; ++i) {
            CHECK_NEAR(m[i].omega_sq, reference[i], m[i].error_bound);
            CHECK(m[i].error_bound <= relative * reference[i]);
        }
        mech_modal_result_destroy(r);
    }
}

static void long_graded_chain(void) {
    static double a[NS96 * NS96], b[NS96 * NS96];
    double k[NS96 + 1];
    for (int i = 0; i < NS96; ++i) {
        k[i] = pow(10.0, round(12.0 * i / (NS96 - 1)));
    }
    k[NS96] = 0.0;
    const int n = NS96;
    for (int i = 0; i < n; ++i) {
        a[i + n * i] = 1.0;
        b[i + n * i] = k[i] + k[i + 1];
        if (i + 1 < n) {
            b[i + n * (i + 1)] = -k[i + 1];
            b[(i + 1) + n * i] = -k[i + 1];
        }
    }
    const double reference[3] = {2.227770545204285753598143e-3, 2.722454068087418781101334e-1,
                                 6.96648211315125092642676e-1};
    lowest_three_certified(n, a, b, reference, 1e-12);
    mech_modal_options_t off = default_options();
    off.refinement = MECH_MODAL_REFINEMENT_OFF;
    off.selection = MECH_MODAL_SELECTION_LOWEST;
    off.count = 3;
    mech_modal_result_t *plain = NULL;
    CHECK_STATUS(mech_modal_solve(n, a, b, &off, &plain), MECH_STATUS_OK);
    mech_modal_mode_t low[3];
    CHECK_STATUS(mech_modal_result_modes(plain, low, 3), MECH_STATUS_OK);
    CHECK_NEAR(low[0].omega_sq, reference[0], low[0].error_bound);
    CHECK(low[0].error_bound > 1e-8 * reference[0]);
    mech_modal_result_destroy(plain);

    /* The same chain turned by Q = diag(H, H, …), H the 4×4 Hadamard matrix over 2: exactly
     * orthogonal, and QᵀBQ is (integer sums)/4, formed exactly, so the eigenvalues are the
     * references'. Its 4×4-block tridiagonal stiffness is dense to the solver: the dense
     * refinement paths must certify Auto's 8 digits too. */
    static double ta[NS96 * NS96], tb[NS96 * NS96];
    for (int j = 0; j < n; ++j) {
        for (int i = 0; i < n; ++i) {
            double sa = 0.0, sb = 0.0;
            /* (QᵀMQ)_ij = Σ_kl Q_ki M_kl Q_lj, Q_ki nonzero only for k in i's block of four. */
            for (int k = 4 * (i / 4); k < 4 * (i / 4) + 4; ++k) {
                for (int l = 4 * (j / 4); l < 4 * (j / 4) + 4; ++l) {
                    double q = hadamard_entry(k % 4, i % 4) * hadamard_entry(l % 4, j % 4);
                    sa += q * a[k + n * l];
                    sb += q * b[k + n * l];
                }
            }
            ta[i + n * j] = sa;
            tb[i + n * j] = sb;
        }
    }
    lowest_three_certified(n, ta, tb, reference, 1e-8);
}

/* Three uncoupled free chains of unit masses and springs (each with one rigid-body mode),
 * reflected by a dense Householder matrix: the stored stiffness is singular only up to
 * rounding, so the three zero eigenvalues come out of order u·‖B‖ and of either sign. They are
 * rigid-body modes to the data's precision: MECH_MODAL_KIND_ZERO, one group of multiplicity 3,
 * with vectors and values only; every other mode is oscillatory. */
#define NF 8
static void rigid_body_modes(void) {
    const int n = 3 * NF;
    static double a[9 * NF * NF], b[9 * NF * NF], u[3 * NF];
    double uu = 0.0;
    for (int i = 0; i < n; ++i) {
        u[i] = 1.0 + 0.3 * cos(1.3 * i);
        uu += u[i] * u[i];
        a[i + n * i] = 1.0;
    }
    for (int c = 0; c < 3; ++c) {
        for (int i = 0; i + 1 < NF; ++i) {
            int r = 3 * i + c, s = r + 3; /* spring between masses i and i + 1 of copy c */
            b[r + n * r] += 1.0;
            b[s + n * s] += 1.0;
            b[r + n * s] -= 1.0;
            b[s + n * r] -= 1.0;
        }
    }
    reflect(a, u, uu, n);
    reflect(b, u, uu, n);
    for (int vectors = 0; vectors < 2; ++vectors) {
        mech_modal_options_t o = default_options();
        o.vectors = vectors;
        mech_modal_result_t *r = NULL;
        CHECK_STATUS(mech_modal_solve(n, a, b, &o, &r), MECH_STATUS_OK);
        static mech_modal_mode_t m[3 * NF];
        CHECK_STATUS(mech_modal_result_modes(r, m, n), MECH_STATUS_OK);
        for (int i = 0; i < n; ++i) {
            CHECK(m[i].kind == (i < 3 ? MECH_MODAL_KIND_ZERO : MECH_MODAL_KIND_OSCILLATORY));
        }
        CHECK(m[0].multiplicity == 3 && m[2].group == m[0].group && m[3].group != m[0].group);
        CHECK(fabs(m[0].omega_sq) <= 1e-13 && m[0].rate == 0.0);
        mech_modal_result_destroy(r);
    }
}

/* The options_default functions write what the documented defaults select: the dense defaults
 * solve as default_options() does, the sparse defaults (count set) as a zero-initialised struct,
 * bit for bit. The sparse problem is a fixed–fixed chain of NC unit springs and masses,
 * ω²_k = 4 sin²(kπ/(2(NC+1))). */
#define NC 40
static void options_defaults(void) {
    mech_modal_options_t o;
    FILL_SENTINEL(&o, sizeof o);
    CHECK_STATUS(mech_modal_options_default(&o), MECH_STATUS_OK);
    CHECK(o.selection == MECH_MODAL_SELECTION_ALL && o.count == 0 && o.lower == 0.0 && o.upper == 0.0);
    CHECK(o.vectors == 1 && o.refinement == MECH_MODAL_REFINEMENT_AUTO);
    CHECK_STATUS(mech_modal_options_default(NULL), MECH_STATUS_NULL_POINTER);
    double a[N * N], b[N * N];
    fixed_chain(a, b);
    mech_modal_options_t by_hand = default_options();
    mech_modal_result_t *r1 = NULL, *r2 = NULL;
    CHECK_STATUS(mech_modal_solve(N, a, b, &o, &r1), MECH_STATUS_OK);
    CHECK_STATUS(mech_modal_solve(N, a, b, &by_hand, &r2), MECH_STATUS_OK);
    double l1[N], l2[N];
    CHECK_STATUS(mech_modal_result_eigenvalues(r1, l1, N), MECH_STATUS_OK);
    CHECK_STATUS(mech_modal_result_eigenvalues(r2, l2, N), MECH_STATUS_OK);
    CHECK(memcmp(l1, l2, sizeof l1) == 0);
    mech_modal_result_destroy(r1);
    mech_modal_result_destroy(r2);

    mech_modal_sparse_options_t so;
    FILL_SENTINEL(&so, sizeof so);
    CHECK_STATUS(mech_modal_sparse_options_default(&so), MECH_STATUS_OK);
    CHECK(so.count == 10 && so.tolerance == 1e-12 && so.block_size == 2 && so.max_runs == 6);
    CHECK(so.shift_given == 0 && so.shift == 0.0);
    CHECK_STATUS(mech_modal_sparse_options_default(NULL), MECH_STATUS_NULL_POINTER);
    size_t acp[NC + 1], arow[NC], bcp[NC + 1], brow[3 * NC];
    double aval[NC], bval[3 * NC];
    size_t nb = 0;
    for (size_t c = 0; c < NC; ++c) {
        acp[c] = c;
        arow[c] = c;
        aval[c] = 1.0;
        bcp[c] = nb;
        if (c > 0) { brow[nb] = c - 1; bval[nb++] = -1.0; }
        brow[nb] = c; bval[nb++] = 2.0;
        if (c + 1 < NC) { brow[nb] = c + 1; bval[nb++] = -1.0; }
    }
    acp[NC] = NC;
    bcp[NC] = nb;
    so.count = 3;
    mech_modal_sparse_options_t zero;
    memset(&zero, 0, sizeof zero);
    zero.count = 3;
    mech_modal_mode_t by_default[3], by_zero[3];
    CHECK_STATUS(mech_modal_sparse_solve(NC, acp, arow, aval, bcp, brow, bval, &so, by_default, NULL, NULL, NULL),
                 MECH_STATUS_OK);
    CHECK_STATUS(mech_modal_sparse_solve(NC, acp, arow, aval, bcp, brow, bval, &zero, by_zero, NULL, NULL, NULL),
                 MECH_STATUS_OK);
    const double pi = 3.14159265358979323846;
    for (int k = 0; k < 3; ++k) {
        CHECK(by_default[k].omega_sq == by_zero[k].omega_sq && by_default[k].error_bound == by_zero[k].error_bound);
        double s = sin((k + 1) * pi / (2.0 * (NC + 1)));
        CHECK_NEAR(by_default[k].omega_sq, 4.0 * s * s, by_default[k].error_bound + 4.0 * 2.2e-16 * 4.0 * s * s);
    }
}

int main(void) {
    all_pairs();
    dense_blocked_path();
    lumped_masses();
    sparse_lowest();
    sketched_report();
    repeated_stiff_pair();
    long_graded_chain();
    rigid_body_modes();
    free_response();
    subsets_and_values_only();
    massless_coordinate();
    stiff_massless_series();
    error_paths();
    options_defaults();
    return CHECK_DONE();
}
