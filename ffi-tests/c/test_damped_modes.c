/* Damped modes through the C ABI against the closed form of a damped oscillator: a point mass
 * m on a prismatic joint with a joint spring k and a joint damper c has
 * s = −ζω_n ± iω_n√(1−ζ²) (ζ < 1) or s = −ζω_n ± ω_n√(ζ²−1) (ζ > 1), ω_n = √(k/m),
 * ζ = c/(2√(km)); every reported value must lie within its reported bound of the closed form,
 * over random scales of m and k. Then the capacity query and the rejected arguments, which
 * leave the outputs untouched. */
#include "check.h"

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

/* The oscillator: prismatic joint along x, point mass m, spring k with rest value `rest`,
 * damper c, no gravity. */
static mech_dynamics_t *oscillator(double m, double k, double c, double rest) {
    mech_tree_t *tree = NULL;
    CHECK_STATUS(mech_tree_create(&tree), MECH_STATUS_OK);
    const mech_vec3_t x = {1.0, 0.0, 0.0};
    size_t body = 99;
    CHECK_STATUS(mech_tree_add_body(tree, -1, MECH_JOINT_PRISMATIC, &x, &IDENTITY, &ZERO, &body), MECH_STATUS_OK);
    CHECK_STATUS(mech_tree_finalize(tree), MECH_STATUS_OK);
    mech_mass_properties_t mass;
    memset(&mass, 0, sizeof mass);
    mass.mass = m;
    mech_mechanism_t *mechanism = NULL;
    CHECK_STATUS(mech_mechanism_create(tree, &mass, 1, &mechanism), MECH_STATUS_OK);
    mech_tree_destroy(tree);
    CHECK_STATUS(mech_mechanism_add_joint_spring(mechanism, 0, k, rest), MECH_STATUS_OK);
    mech_dynamics_t *d = NULL;
    CHECK_STATUS(mech_dynamics_create(mechanism, &d), MECH_STATUS_OK);
    mech_mechanism_destroy(mechanism);
    CHECK_STATUS(mech_dynamics_add_joint_damper(d, 0, c, NULL), MECH_STATUS_OK);
    return d;
}

/* |computed − exact| within the reported bound plus a few roundings of the closed form. */
static int within(double computed_re, double computed_im, double exact_re, double exact_im, double bound) {
    const double err = hypot(computed_re - exact_re, computed_im - exact_im);
    return err <= bound + 4.0 * U * hypot(exact_re, exact_im);
}

static void check_underdamped(const mech_damped_mode_t *mode, double omega_n, double zeta) {
    CHECK(mode->kind == MECH_DAMPED_KIND_UNDERDAMPED);
    const double re = -zeta * omega_n, im = omega_n * sqrt(1.0 - zeta * zeta);
    CHECK(within(mode->s_re[0], mode->s_im[0], re, im, mode->error_bound[0]));
    CHECK(within(mode->s_re[1], mode->s_im[1], re, -im, mode->error_bound[1]));
    /* ω_n = |s| and ζ = −σ/|s| inherit the eigenvalue's bound b: |Δω_n| ≤ b, |Δζ| ≤ 2b/|s|. */
    const double b = mode->error_bound[0];
    CHECK_NEAR(mode->natural_frequency, omega_n, b + 8.0 * U * omega_n);
    CHECK_NEAR(mode->damped_frequency, im, b + 8.0 * U * omega_n);
    CHECK_NEAR(mode->damping_ratio, zeta, 2.0 * b / omega_n + 8.0 * U);
}

static void check_overdamped(const mech_damped_mode_t *mode, double omega_n, double zeta) {
    CHECK(mode->kind == MECH_DAMPED_KIND_OVERDAMPED);
    /* The fast root without cancellation, the slow one from s₁s₂ = ω_n². */
    const double fast = -omega_n * (zeta + sqrt(zeta * zeta - 1.0)), slow = omega_n * omega_n / fast;
    const int fast_first = fabs(mode->s_re[0]) > fabs(mode->s_re[1]);
    const double r0 = fast_first ? fast : slow, r1 = fast_first ? slow : fast;
    CHECK(within(mode->s_re[0], mode->s_im[0], r0, 0.0, mode->error_bound[0]));
    CHECK(within(mode->s_re[1], mode->s_im[1], r1, 0.0, mode->error_bound[1]));
    CHECK(mode->damped_frequency == 0.0);
    /* ω_n = √(s₁s₂): relative error ≤ ½ Σ b_i/|s_i|; ζ = −(s₁ + s₂)/(2ω_n). */
    const double rel = 0.5 * (mode->error_bound[0] / fabs(r0) + mode->error_bound[1] / fabs(r1));
    CHECK_NEAR(mode->natural_frequency, omega_n, 1.01 * rel * omega_n + 8.0 * U * omega_n);
    const double zeta_tol = (mode->error_bound[0] + mode->error_bound[1]) / (2.0 * omega_n) + 1.01 * zeta * rel;
    CHECK_NEAR(mode->damping_ratio, zeta, zeta_tol + 8.0 * U * zeta);
}

static void oscillator_family(void) {
    const double zetas[3] = {0.01, 0.5, 2.0};
    uint64_t seed = 0xD1B54A32D192ED03ULL;
    for (int trial = 0; trial < 30; ++trial) {
        const double m = pow(10.0, uniform(&seed, -2.0, 2.0)), k = pow(10.0, uniform(&seed, -1.0, 4.0));
        const double zeta = zetas[trial % 3], omega_n = sqrt(k / m), c = 2.0 * zeta * sqrt(k * m);
        const double rest = uniform(&seed, -1.0, 1.0);
        mech_dynamics_t *d = oscillator(m, k, c, rest);
        mech_damped_mode_t modes[2];
        size_t count = 99;
        double gradient = -1.0;
        const double q0 = 0.0; /* away from the rest value: grad U = k (q0 − rest) */
        CHECK_STATUS(mech_dynamics_damped_modes(d, &q0, 1, 2, modes, &count, &gradient), MECH_STATUS_OK);
        CHECK(count == 1);
        CHECK_NEAR(gradient, k * fabs(rest), 4.0 * U * k * fabs(rest));
        const mech_damped_mode_t *mode = &modes[0];
        CHECK(mode->eigenvalue_count == 2);
        for (int i = 0; i < 2; ++i) {
            /* The bounds are informative, not vacuous. */
            CHECK(mode->error_bound[i] >= 0.0 && mode->error_bound[i] < 1e-10 * omega_n * (1.0 + zeta));
            CHECK(mode->backward_error[i] >= 0.0 && mode->backward_error[i] < 1e-14);
        }
        if (zeta < 1.0)
            check_underdamped(mode, omega_n, zeta);
        else
            check_overdamped(mode, omega_n, zeta);
        /* Without the gradient output. */
        CHECK_STATUS(mech_dynamics_damped_modes(d, &q0, 1, 2, modes, &count, NULL), MECH_STATUS_OK);
        mech_dynamics_destroy(d);
    }
}

static void capacity_and_rejected_arguments(void) {
    mech_dynamics_t *d = oscillator(2.0, 50.0, 1.0, 0.0);
    mech_damped_mode_t modes[2];
    size_t count = 42;
    double gradient = 7.0;
    const double q0 = 0.1;

    /* The count query: capacity 0 with no buffer, and capacity 0 with one left untouched. */
    CHECK_STATUS(mech_dynamics_damped_modes(d, &q0, 1, 0, NULL, &count, &gradient), MECH_STATUS_BUFFER_TOO_SMALL);
    CHECK(count == 1 && gradient == 7.0);
    FILL_SENTINEL(modes, sizeof modes);
    count = 42;
    CHECK_STATUS(mech_dynamics_damped_modes(d, &q0, 1, 0, modes, &count, &gradient), MECH_STATUS_BUFFER_TOO_SMALL);
    CHECK(count == 1 && gradient == 7.0 && mech_untouched(modes, sizeof modes));

    /* Rejected inputs write nothing at all. */
    count = 42;
    const double bad[2] = {NAN, INFINITY};
    for (int i = 0; i < 2; ++i) {
        CHECK_STATUS(mech_dynamics_damped_modes(d, &bad[i], 1, 2, modes, &count, &gradient), MECH_STATUS_NON_FINITE);
    }
    const double two[2] = {0.0, 0.0};
    CHECK_STATUS(mech_dynamics_damped_modes(d, two, 2, 2, modes, &count, &gradient), MECH_STATUS_BAD_DIMENSION);
    CHECK_STATUS(mech_dynamics_damped_modes(d, NULL, 1, 2, modes, &count, &gradient), MECH_STATUS_NULL_POINTER);
    CHECK_STATUS(mech_dynamics_damped_modes(d, &q0, 1, 2, modes, NULL, &gradient), MECH_STATUS_NULL_POINTER);
    CHECK_STATUS(mech_dynamics_damped_modes(d, &q0, 1, 2, NULL, &count, &gradient), MECH_STATUS_NULL_POINTER);
    CHECK_STATUS(mech_dynamics_damped_modes(NULL, &q0, 1, 2, modes, &count, &gradient), MECH_STATUS_NULL_POINTER);
    CHECK(count == 42 && gradient == 7.0 && mech_untouched(modes, sizeof modes));

    /* The same call with room succeeds: gradient k·|q0|. */
    CHECK_STATUS(mech_dynamics_damped_modes(d, &q0, 1, 1, modes, &count, &gradient), MECH_STATUS_OK);
    CHECK(count == 1);
    CHECK_NEAR(gradient, 50.0 * 0.1, 1e-15 * 5.0);
    mech_dynamics_destroy(d);
}

int main(void) {
    oscillator_family();
    capacity_and_rejected_arguments();
    return CHECK_DONE();
}
