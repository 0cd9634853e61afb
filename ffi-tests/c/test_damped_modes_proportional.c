/* Damped modes of a multi-DOF mechanism through the C ABI against the closed form of
 * proportional (Rayleigh) damping. A chain of n point masses m_i on prismatic joints along x,
 * with joint springs k_i (B = diag k), a damper c_i = α m_i from each mass to a ground point
 * (on the full relative velocity: C = α A) and a joint damper β k_i on each joint (β B) has
 * C = αA + βB, so each undamped mode ω of (A, B) (from mech_mechanism_modes on the same
 * mechanism) gives the damped pair s = −ζω ± iω√(1−ζ²) with 2ζω = α + βω², or the real roots
 * −ζω ± ω√(ζ²−1) when ζ > 1. α and β are drawn so that the lowest mode is overdamped; the
 * family over random masses, stiffnesses and damping levels must also show underdamped modes.
 * Every eigenvalue must lie within its reported bound of the closed form, up to the closed
 * form's own error propagated from the bound on ω². */
#include "check.h"

#define MAX_DOF 6

static const mech_vec3_t ZERO = {0.0, 0.0, 0.0};
static const mech_mat3_t IDENTITY = {{1, 0, 0, 0, 1, 0, 0, 0, 1}};
static const double U = 2.220446049250313e-16; /* unit roundoff ×2: one rounding of the closed form */

/* A deterministic generator of doubles in [lo, hi) (xorshift64*). */
static double uniform(uint64_t *state, double lo, double hi) {
    *state ^= *state >> 12;
    *state ^= *state << 25;
    *state ^= *state >> 27;
    const uint64_t r = *state * 2685821657736338717ULL;
    return lo + (hi - lo) * (double)(r >> 11) / 9007199254740992.0;
}

/* The chain of springs and masses, without dampers; n ≤ MAX_DOF. */
static mech_mechanism_t *chain(size_t n, const double *m, const double *k) {
    mech_tree_t *tree = NULL;
    CHECK_STATUS(mech_tree_create(&tree), MECH_STATUS_OK);
    const mech_vec3_t x = {1.0, 0.0, 0.0};
    mech_mass_properties_t bodies[MAX_DOF];
    memset(bodies, 0, sizeof bodies);
    for (size_t i = 0; i < n; ++i) {
        size_t body = 99;
        CHECK_STATUS(mech_tree_add_body(tree, (int64_t)i - 1, MECH_JOINT_PRISMATIC, &x, &IDENTITY, &x, &body),
                     MECH_STATUS_OK);
        CHECK(body == i);
        bodies[i].mass = m[i];
    }
    CHECK_STATUS(mech_tree_finalize(tree), MECH_STATUS_OK);
    mech_mechanism_t *mechanism = NULL;
    CHECK_STATUS(mech_mechanism_create(tree, bodies, n, &mechanism), MECH_STATUS_OK);
    mech_tree_destroy(tree);
    for (size_t i = 0; i < n; ++i) {
        CHECK_STATUS(mech_mechanism_add_joint_spring(mechanism, i, k[i], 0.0), MECH_STATUS_OK);
    }
    return mechanism;
}

/* ζ of the undamped mode ω under C = αA + βB. */
static double zeta_of(double omega, double alpha, double beta) {
    return 0.5 * (alpha / omega + beta * omega);
}

/* The closed-form roots of mode ω (r[0] with Im ≥ 0 or the fast real root first) and a bound
 * on their change when ω moves by δω (first order: |ds/dω| δω). */
typedef struct {
    double re[2], im[2];
    double slack[2];
} closed_form_t;

static closed_form_t closed_form(double omega, double alpha, double beta, double d_omega) {
    closed_form_t f;
    const double p = 0.5 * (alpha + beta * omega * omega), dp = beta * omega; /* p = ζω */
    const double z = zeta_of(omega, alpha, beta);
    if (z < 1.0) {
        const double q = omega * sqrt(1.0 - z * z); /* √(ω² − p²) */
        const double dq = fabs(omega - p * dp) / q;
        f.re[0] = f.re[1] = -p;
        f.im[0] = q;
        f.im[1] = -q;
        f.slack[0] = f.slack[1] = hypot(dp, dq) * d_omega;
    } else {
        const double r = omega * sqrt(z * z - 1.0); /* √(p² − ω²) */
        const double fast = -(p + r), slow = omega * omega / fast;
        const double d_fast = dp + fabs(p * dp - omega) / r;
        f.re[0] = fast;
        f.re[1] = slow;
        f.im[0] = f.im[1] = 0.0;
        f.slack[0] = d_fast * d_omega;
        f.slack[1] = (2.0 * omega / fabs(fast) + omega * omega * d_fast / (fast * fast)) * d_omega;
    }
    return f;
}

/* |computed − exact| within the reported bound, the reference's slack and a few roundings. */
static int within(double re, double im, double exact_re, double exact_im, double bound, double slack) {
    return hypot(re - exact_re, im - exact_im) <= bound + slack + 8.0 * U * hypot(exact_re, exact_im);
}

/* One mode against its closed form; returns its kind. */
static int check_mode(const mech_damped_mode_t *mode, double omega, double d_omega, double alpha, double beta) {
    const double z = zeta_of(omega, alpha, beta);
    const closed_form_t f = closed_form(omega, alpha, beta, d_omega);
    CHECK(mode->eigenvalue_count == 2);
    for (int i = 0; i < 2; ++i) {
        /* Backward stable (≤ 64 n u for n ≤ 6) and informative bounds. */
        CHECK(mode->backward_error[i] >= 0.0 && mode->backward_error[i] < 64.0 * MAX_DOF * U);
        CHECK(mode->error_bound[i] >= 0.0 && mode->error_bound[i] < 1e-8 * omega * (1.0 + z));
    }
    /* ζ and ω_d carry the bounds of the eigenvalues and the slack of the reference. */
    const double b = fmax(mode->error_bound[0] + f.slack[0], mode->error_bound[1] + f.slack[1]);
    const double dz = 0.5 * fabs(beta - alpha / (omega * omega)) * d_omega;
    if (z < 1.0) {
        CHECK(mode->kind == MECH_DAMPED_KIND_UNDERDAMPED);
        CHECK(within(mode->s_re[0], mode->s_im[0], f.re[0], f.im[0], mode->error_bound[0], f.slack[0]));
        CHECK(within(mode->s_re[1], mode->s_im[1], f.re[1], f.im[1], mode->error_bound[1], f.slack[1]));
        CHECK_NEAR(mode->natural_frequency, omega, b + d_omega + 8.0 * U * omega);
        CHECK_NEAR(mode->damped_frequency, f.im[0], b + 8.0 * U * omega);
        CHECK_NEAR(mode->damping_ratio, z, 2.0 * b / omega + dz + 8.0 * U);
    } else {
        CHECK(mode->kind == MECH_DAMPED_KIND_OVERDAMPED);
        const int fast_first = fabs(mode->s_re[0]) > fabs(mode->s_re[1]);
        const int i0 = fast_first ? 0 : 1, i1 = 1 - i0;
        CHECK(within(mode->s_re[0], mode->s_im[0], f.re[i0], 0.0, mode->error_bound[0], f.slack[i0]));
        CHECK(within(mode->s_re[1], mode->s_im[1], f.re[i1], 0.0, mode->error_bound[1], f.slack[i1]));
        CHECK(mode->damped_frequency == 0.0);
        /* ω_n = √(s₁s₂): relative error ≤ ½ Σ Δs_i/|s_i|; ζ = −(s₁ + s₂)/(2ω_n). */
        const double e0 = mode->error_bound[0] + f.slack[i0], e1 = mode->error_bound[1] + f.slack[i1];
        const double rel = 0.5 * (e0 / fabs(f.re[i0]) + e1 / fabs(f.re[i1]));
        CHECK_NEAR(mode->natural_frequency, omega, 1.01 * rel * omega + d_omega + 8.0 * U * omega);
        CHECK_NEAR(mode->damping_ratio, z, (e0 + e1) / (2.0 * omega) + 1.01 * z * rel + dz + 8.0 * U * z);
    }
    return mode->kind;
}

/* α, β with the lowest mode overdamped (ζ₁ in [1.5, 4)) and no mode within 0.15 of critical
 * damping, where the kind is decided by the bounds alone; 0 when the draws keep failing. */
static int draw_damping(uint64_t *seed, const double *omega, size_t n, double *alpha, double *beta) {
    for (int attempt = 0; attempt < 100; ++attempt) {
        const double zeta_1 = uniform(seed, 1.5, 4.0);
        *beta = pow(10.0, uniform(seed, -3.0, -0.5)) / omega[n - 1];
        *alpha = 2.0 * zeta_1 * omega[0] - *beta * omega[0] * omega[0];
        int clear = *alpha > 0.0;
        for (size_t j = 0; j < n; ++j) clear = clear && fabs(zeta_of(omega[j], *alpha, *beta) - 1.0) > 0.15;
        if (clear) return 1;
    }
    return 0;
}

static void proportional_family(void) {
    uint64_t seed = 0x8C3D5A1F2B7E9604ULL;
    int underdamped = 0, overdamped = 0;
    for (int trial = 0; trial < 40; ++trial) {
        const size_t n = 2 + (size_t)uniform(&seed, 0.0, MAX_DOF - 1.0); /* 2 … 6 */
        double m[MAX_DOF], k[MAX_DOF], q0[MAX_DOF] = {0};
        for (size_t i = 0; i < n; ++i) {
            m[i] = pow(10.0, uniform(&seed, -1.5, 1.5));
            k[i] = pow(10.0, uniform(&seed, 0.0, 3.5));
        }
        mech_mechanism_t *mechanism = chain(n, m, k);
        double omega_sq[MAX_DOF], bounds[MAX_DOF], omega[MAX_DOF], d_omega[MAX_DOF];
        mech_modal_kind_t kinds[MAX_DOF];
        size_t found = 0;
        mech_stability_t stability;
        CHECK_STATUS(mech_mechanism_modes(mechanism, q0, n, 0, omega_sq, bounds, kinds, NULL, &found, &stability),
                     MECH_STATUS_OK);
        CHECK(found == n);
        for (size_t j = 0; j < n; ++j) {
            CHECK(omega_sq[j] > bounds[j]);
            omega[j] = sqrt(omega_sq[j]);
            d_omega[j] = bounds[j] / (2.0 * omega[j]) + U * omega[j]; /* δ√x ≈ δx/(2√x), plus the sqrt's rounding */
            /* Distinct undamped modes, so that mode j of the damped list is mode j here. */
            if (j > 0) CHECK(omega[j] - omega[j - 1] > 1e-6 * omega[j]);
        }
        double alpha = 0.0, beta = 0.0;
        if (!draw_damping(&seed, omega, n, &alpha, &beta)) {
            mech_mechanism_destroy(mechanism);
            continue;
        }
        mech_dynamics_t *d = NULL;
        CHECK_STATUS(mech_dynamics_create(mechanism, &d), MECH_STATUS_OK);
        mech_mechanism_destroy(mechanism);
        const mech_vec3_t ground_point = {-10.0, 3.0, 0.0};
        for (size_t i = 0; i < n; ++i) {
            CHECK_STATUS(mech_dynamics_add_point_damper(d, (int64_t)i, ZERO, MECH_GROUND, ground_point, alpha * m[i], 0,
                                                        NULL),
                         MECH_STATUS_OK);
            CHECK_STATUS(mech_dynamics_add_joint_damper(d, i, beta * k[i], NULL), MECH_STATUS_OK);
        }
        size_t count = 0;
        CHECK_STATUS(mech_dynamics_damped_modes(d, q0, n, 0, NULL, &count, NULL), MECH_STATUS_BUFFER_TOO_SMALL);
        CHECK(count == n); /* one mode per undamped mode: overdamped roots share their shape */
        mech_damped_mode_t modes[2 * MAX_DOF];
        double gradient = -1.0;
        CHECK_STATUS(mech_dynamics_damped_modes(d, q0, n, 2 * n, modes, &count, &gradient), MECH_STATUS_OK);
        CHECK(count == n && gradient == 0.0);
        for (size_t j = 0; j < n; ++j) {
            const int kind = check_mode(&modes[j], omega[j], d_omega[j], alpha, beta);
            underdamped += kind == MECH_DAMPED_KIND_UNDERDAMPED;
            overdamped += kind == MECH_DAMPED_KIND_OVERDAMPED;
        }
        CHECK(modes[0].kind == MECH_DAMPED_KIND_OVERDAMPED);
        mech_dynamics_destroy(d);
    }
    /* The family is not vacuous: both kinds occur, most trials ran. */
    CHECK(overdamped >= 30 && underdamped >= 30);
}

int main(void) {
    proportional_family();
    return CHECK_DONE();
}
