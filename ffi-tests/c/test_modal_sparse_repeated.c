/* C test of mech_modal_sparse_lowest on repeated eigenvalues: COPIES uncoupled identical chains
 * of LEN linear finite elements (consistent mass A = tridiag(1, 4, 1), stiffness
 * B = 6·tridiag(−1, 2, −1), exact in binary). Each chain has
 * ω²_j = 12 sin²(θ_j/2)/(2 + cos θ_j), θ_j = jπ/(LEN + 1), so the pencil has every ω²_j with
 * multiplicity COPIES = 4, larger than the solver's default Lanczos block size 2: the inertia
 * count and the deflated reruns must recover the copies a block Krylov space cannot see. */
#include "check.h"

#define COPIES 4
#define LEN 150
#define NN (COPIES * LEN)
#define NNZ (3 * NN)
#define U 2.220446049250313e-16

static size_t acp[NN + 1], arow[NNZ], bcp[NN + 1], brow[NNZ];
static double aval[NNZ], bval[NNZ];

static void assemble(void) {
    size_t nz = 0;
    for (size_t c = 0; c < NN; ++c) {
        size_t i = c % LEN;
        acp[c] = nz;
        bcp[c] = nz;
        /* rows ascending within the column; no coupling between copies */
        if (i > 0) { arow[nz] = brow[nz] = c - 1; aval[nz] = 1.0; bval[nz++] = -6.0; }
        arow[nz] = brow[nz] = c; aval[nz] = 4.0; bval[nz++] = 12.0;
        if (i + 1 < LEN) { arow[nz] = brow[nz] = c + 1; aval[nz] = 1.0; bval[nz++] = -6.0; }
    }
    acp[NN] = nz;
    bcp[NN] = nz;
}

static double chain_omega_sq(int j) {
    const double pi = 3.14159265358979323846;
    double theta = j * pi / (LEN + 1.0), s = sin(0.5 * theta);
    return 12.0 * s * s / (2.0 + cos(theta));
}

/* max |(XᵀMX − D)_ij| for the CSC matrix M and the NN × k column-major X. */
static double gram_error(const size_t *cp, const size_t *row, const double *val, const double *x, int k,
                         const double *d) {
    static double mx[NN];
    double worst = 0.0;
    for (int q = 0; q < k; ++q) {
        memset(mx, 0, sizeof mx);
        for (size_t c = 0; c < NN; ++c) {
            for (size_t p = cp[c]; p < cp[c + 1]; ++p) mx[row[p]] += val[p] * x[c + NN * (size_t)q];
        }
        for (int r = 0; r < k; ++r) {
            double g = 0.0;
            for (size_t i = 0; i < NN; ++i) g += x[i + NN * (size_t)r] * mx[i];
            double target = (r == q) ? d[q] : 0.0;
            if (fabs(g - target) > worst) worst = fabs(g - target);
        }
    }
    return worst;
}

/* The 8 lowest modes: two eigenvalues of multiplicity 4 each. */
static void two_full_groups(void) {
    enum { K = 8 };
    double w[K], e[K], ones[K];
    static double x[NN * K];
    mech_modal_sparse_report_t rep;
    CHECK_STATUS(mech_modal_sparse_lowest(NN, acp, arow, aval, bcp, brow, bval, K, w, e, x, &rep), MECH_STATUS_OK);
    for (int k = 0; k < K; ++k) {
        double exact = chain_omega_sq(1 + k / COPIES);
        /* bound of the solver + rounding of the closed form (< 8u relative) */
        CHECK_NEAR(w[k], exact, e[k] + 8.0 * U * exact);
        CHECK(e[k] >= 0.0 && e[k] <= 1e-10 * exact);
        ones[k] = 1.0;
    }
    /* Multiplicities: neighbours within the sum of their bounds form a group; expect [4, 4]. */
    int groups = 1, size = 1, sizes[K] = {0};
    for (int k = 1; k < K; ++k) {
        if (fabs(w[k] - w[k - 1]) <= e[k] + e[k - 1]) {
            ++size;
        } else {
            sizes[groups - 1] = size;
            ++groups;
            size = 1;
        }
    }
    sizes[groups - 1] = size;
    CHECK(groups == 2 && sizes[0] == COPIES && sizes[1] == COPIES);
    /* The shapes of each repeated group are A-orthonormal and B-orthogonal. */
    CHECK(gram_error(acp, arow, aval, x, K, ones) <= 1e3 * U);
    CHECK(gram_error(bcp, brow, bval, x, K, w) <= 24.0 * 1e3 * U);
    CHECK(rep.orthogonality_error <= 1e3 * U);
    /* Certificate: the inertia count at τ equals the computed count and the closed form's. */
    CHECK(rep.inertia_consistent == 1 && rep.inertia_below == rep.computed_below);
    CHECK(rep.inertia_shift > w[K - 1]);
    size_t closed_form = 0;
    for (int j = 1; j <= LEN; ++j) closed_form += (chain_omega_sq(j) < rep.inertia_shift) ? COPIES : 0;
    CHECK(rep.inertia_below == closed_form);
}

/* count = 2 cuts through the lowest eigenvalue (multiplicity 4): two copies come back, and the
 * report certifies that all four lie below τ and were computed. */
static void count_cutting_a_group(void) {
    double w[2], e[2];
    mech_modal_sparse_report_t rep;
    CHECK_STATUS(mech_modal_sparse_lowest(NN, acp, arow, aval, bcp, brow, bval, 2, w, e, NULL, &rep), MECH_STATUS_OK);
    double exact = chain_omega_sq(1);
    CHECK_NEAR(w[0], exact, e[0] + 8.0 * U * exact);
    CHECK_NEAR(w[1], exact, e[1] + 8.0 * U * exact);
    CHECK(rep.inertia_consistent == 1 && rep.inertia_shift > exact);
    CHECK(rep.inertia_below >= COPIES && rep.inertia_below % COPIES == 0);
}

int main(void) {
    assemble();
    two_full_groups();
    count_cutting_a_group();
    return CHECK_DONE();
}
