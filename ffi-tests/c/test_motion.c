/* Motion C ABI: a compound pendulum released from rest at θ₀ returns to θ₀ after its period
 * 4 K(sin(θ₀/2)) / ω₀ (K by the arithmetic–geometric mean, independent of the library), by
 * Dormand–Prince and by Störmer–Verlet, with the error estimate covering the true error; and
 * rejected options and arguments leaving the outputs untouched; the momentum monitors of a
 * free-floating two-body chain: P and L conserved without gravity, and under gravity the
 * momentum −m g t gained along it reported as drift while L along gravity stays conserved; a
 * step limit that stops an advance to 1e300 s after it, at the last good state, until raised. */
#include "check.h"

static const mech_vec3_t ZERO = {0.0, 0.0, 0.0};
static const mech_mat3_t IDENTITY = {{1, 0, 0, 0, 1, 0, 0, 0, 1}};
static const double PM = 1.7, PL = 0.9, PI0 = 0.05, PG = 9.81;

/* A revolute joint about y at the origin, mass m at (0, 0, −l), central Iyy = i0. */
static mech_dynamics_t *pendulum(void) {
    mech_tree_t *tree = NULL;
    CHECK_STATUS(mech_tree_create(&tree), MECH_STATUS_OK);
    const mech_vec3_t y = {0.0, 1.0, 0.0};
    size_t body = 99;
    CHECK_STATUS(mech_tree_add_body(tree, -1, MECH_JOINT_REVOLUTE, &y, &IDENTITY, &ZERO, &body), MECH_STATUS_OK);
    CHECK_STATUS(mech_tree_finalize(tree), MECH_STATUS_OK);
    mech_mass_properties_t bob;
    memset(&bob, 0, sizeof bob);
    bob.mass = PM;
    bob.center_of_mass.z = -PL;
    bob.inertia_about_com.m[0] = PI0;
    bob.inertia_about_com.m[4] = PI0;
    bob.inertia_about_com.m[8] = 0.5 * PI0;
    mech_mechanism_t *mechanism = NULL;
    CHECK_STATUS(mech_mechanism_create(tree, &bob, 1, &mechanism), MECH_STATUS_OK);
    mech_tree_destroy(tree);
    const mech_vec3_t gravity = {0.0, 0.0, -PG};
    CHECK_STATUS(mech_mechanism_set_gravity(mechanism, gravity), MECH_STATUS_OK);
    mech_dynamics_t *dynamics = NULL;
    CHECK_STATUS(mech_dynamics_create(mechanism, &dynamics), MECH_STATUS_OK);
    mech_mechanism_destroy(mechanism);
    return dynamics;
}

/* K(k) = π / (2 AGM(1, √(1 − k²))). */
static double elliptic_k(double k) {
    double a = 1.0, b = sqrt(1.0 - k * k);
    for (int i = 0; i < 40 && fabs(a - b) > 1e-16 * a; ++i) {
        const double next = 0.5 * (a + b);
        b = sqrt(a * b);
        a = next;
    }
    return acos(-1.0) / (a + b);
}

static void period(mech_dynamics_t *d, mech_motion_method_t method, double tolerance) {
    const double omega0 = sqrt(PM * PG * PL / (PM * PL * PL + PI0));
    for (int trial = 0; trial < 4; ++trial) {
        const double theta0 = 0.3 + 0.8 * trial;
        const double t_period = 4.0 * elliptic_k(sin(0.5 * theta0)) / omega0;
        mech_motion_options_t options;
        CHECK_STATUS(mech_motion_options_default(&options), MECH_STATUS_OK);
        options.method = method;
        options.rtol = 1e-12;
        options.atol = 1e-14;
        options.step = 1e-3;
        const double zero = 0.0;
        mech_simulation_t *s = NULL;
        CHECK_STATUS(mech_simulation_create(d, &options, &theta0, &zero, NULL, 1, &s), MECH_STATUS_OK);
        double q = 0.0, qd = 0.0;
        CHECK_STATUS(mech_simulation_advance(s, 0.5 * t_period, 1, &q, &qd), MECH_STATUS_OK);
        CHECK_NEAR(q, -theta0, tolerance);
        CHECK_STATUS(mech_simulation_advance(s, t_period, 1, &q, &qd), MECH_STATUS_OK);
        CHECK_NEAR(q, theta0, tolerance);
        CHECK_NEAR(qd, 0.0, tolerance * omega0);
        mech_motion_report_t report;
        CHECK_STATUS(mech_simulation_report(s, &report), MECH_STATUS_OK);
        CHECK(report.t == t_period);
        CHECK(report.invariant == MECH_MOTION_ENERGY);
        CHECK(report.error_q >= fabs(q - theta0));
        CHECK(report.error_q <= 100.0 * tolerance);
        CHECK(report.steps > 0);
        CHECK(report.max_energy_drift <= 1e-3);
        mech_simulation_destroy(s);
    }
}

static void rejected_arguments(mech_dynamics_t *d) {
    const double q0 = 0.5, zero = 0.0;
    mech_motion_options_t options;
    CHECK_STATUS(mech_motion_options_default(&options), MECH_STATUS_OK);
    mech_simulation_t *s = NULL;
    const double bad_tolerances[] = {0.0, -1e-6, 1e-16, NAN, INFINITY};
    for (size_t i = 0; i < sizeof bad_tolerances / sizeof bad_tolerances[0]; ++i) {
        options.rtol = bad_tolerances[i];
        CHECK_STATUS(mech_simulation_create(d, &options, &q0, &zero, NULL, 1, &s), MECH_STATUS_INVALID_ARGUMENT);
        CHECK(s == NULL);
    }
    CHECK_STATUS(mech_motion_options_default(&options), MECH_STATUS_OK);
    options.method = 7;
    CHECK_STATUS(mech_simulation_create(d, &options, &q0, &zero, NULL, 1, &s), MECH_STATUS_BAD_ENUM);
    options.method = MECH_MOTION_RK4;
    options.step = 0.0;
    CHECK_STATUS(mech_simulation_create(d, &options, &q0, &zero, NULL, 1, &s), MECH_STATUS_INVALID_ARGUMENT);
    CHECK_STATUS(mech_simulation_create(d, NULL, &q0, &zero, NULL, 2, &s), MECH_STATUS_BAD_DIMENSION);
    const double nan = NAN;
    CHECK_STATUS(mech_simulation_create(d, NULL, &nan, &zero, NULL, 1, &s), MECH_STATUS_NON_FINITE);
    CHECK(s == NULL);
    CHECK_STATUS(mech_simulation_create(d, NULL, &q0, &zero, NULL, 1, &s), MECH_STATUS_OK);
    double q = 42.0, qd = 42.0;
    CHECK_STATUS(mech_simulation_advance(s, 0.1, 1, &q, &qd), MECH_STATUS_OK);
    q = 42.0;
    CHECK_STATUS(mech_simulation_advance(s, 0.05, 1, &q, &qd), MECH_STATUS_INVALID_ARGUMENT);
    CHECK_STATUS(mech_simulation_advance(s, NAN, 1, &q, &qd), MECH_STATUS_NON_FINITE);
    CHECK_STATUS(mech_simulation_advance(s, 0.2, 3, &q, &qd), MECH_STATUS_BAD_DIMENSION);
    CHECK(q == 42.0);
    CHECK_STATUS(mech_simulation_advance(NULL, 0.2, 1, &q, &qd), MECH_STATUS_NULL_POINTER);
    mech_simulation_destroy(s);
    mech_simulation_destroy(NULL);
}

/* RK4 with step h reaches k·h in k steps: a limit of 40 refuses 1e300 s and 50·h (nothing
 * written, the report still at t = 0 after 40 steps), and once raised to 50 reaches 50·h. */
static void step_limit(mech_dynamics_t *d) {
    const double q0 = 0.5, zero = 0.0, h = 0.01;
    mech_motion_options_t options;
    CHECK_STATUS(mech_motion_options_default(&options), MECH_STATUS_OK);
    options.method = MECH_MOTION_RK4;
    options.step = h;
    options.estimate_error = 0;
    mech_simulation_t *s = NULL;
    CHECK_STATUS(mech_simulation_create(d, &options, &q0, &zero, NULL, 1, &s), MECH_STATUS_OK);
    CHECK_STATUS(mech_simulation_set_max_steps(s, 0), MECH_STATUS_INVALID_ARGUMENT);
    CHECK_STATUS(mech_simulation_set_max_steps(NULL, 40), MECH_STATUS_NULL_POINTER);
    CHECK_STATUS(mech_simulation_set_max_steps(s, 40), MECH_STATUS_OK);
    double q = 42.0, qd = 42.0;
    CHECK_STATUS(mech_simulation_advance(s, 1e300, 1, &q, &qd), MECH_STATUS_NOT_CONVERGED);
    CHECK_STATUS(mech_simulation_advance(s, 50 * h, 1, &q, &qd), MECH_STATUS_NOT_CONVERGED);
    char message[256];
    mech_last_error(message, sizeof message);
    CHECK(strstr(message, "more than 40 steps") != NULL);
    CHECK(q == 42.0 && qd == 42.0);
    mech_motion_report_t report;
    CHECK_STATUS(mech_simulation_report(s, &report), MECH_STATUS_OK);
    CHECK(report.t == 0.0 && report.steps == 40);
    CHECK_STATUS(mech_simulation_set_max_steps(s, 50), MECH_STATUS_OK);
    CHECK_STATUS(mech_simulation_advance(s, 50 * h, 1, &q, &qd), MECH_STATUS_OK);
    CHECK_STATUS(mech_simulation_report(s, &report), MECH_STATUS_OK);
    CHECK(report.t == 50 * h && report.steps == 50);
    CHECK(isfinite(q) && fabs(q) <= q0 && q != 42.0);
    mech_simulation_destroy(s);
}

/* A free base (2 kg) carrying a link on a revolute joint about (1, 1, 0)/√2 at (0.4, 0, 0.1);
 * gravity g along −z. */
static mech_dynamics_t *floating_pair(double g) {
    mech_tree_t *tree = NULL;
    CHECK_STATUS(mech_tree_create(&tree), MECH_STATUS_OK);
    const mech_vec3_t unused = {0.0, 0.0, 1.0};
    const mech_vec3_t axis = {sqrt(0.5), sqrt(0.5), 0.0};
    const mech_vec3_t offset = {0.4, 0.0, 0.1};
    size_t base = 99, link = 99;
    CHECK_STATUS(mech_tree_add_body(tree, -1, MECH_JOINT_FREE, &unused, &IDENTITY, &ZERO, &base), MECH_STATUS_OK);
    CHECK_STATUS(mech_tree_add_body(tree, (int64_t)base, MECH_JOINT_REVOLUTE, &axis, &IDENTITY, &offset, &link),
                 MECH_STATUS_OK);
    CHECK_STATUS(mech_tree_finalize(tree), MECH_STATUS_OK);
    mech_mass_properties_t bodies[2];
    memset(bodies, 0, sizeof bodies);
    bodies[0].mass = 2.0;
    bodies[0].inertia_about_com.m[0] = 0.1;
    bodies[0].inertia_about_com.m[4] = 0.2;
    bodies[0].inertia_about_com.m[8] = 0.3;
    bodies[1].mass = 0.8;
    bodies[1].center_of_mass.x = 0.3;
    bodies[1].center_of_mass.z = -0.1;
    bodies[1].inertia_about_com.m[0] = 0.01;
    bodies[1].inertia_about_com.m[4] = 0.02;
    bodies[1].inertia_about_com.m[8] = 0.02;
    mech_mechanism_t *mechanism = NULL;
    CHECK_STATUS(mech_mechanism_create(tree, bodies, 2, &mechanism), MECH_STATUS_OK);
    mech_tree_destroy(tree);
    const mech_vec3_t gravity = {0.0, 0.0, -g};
    CHECK_STATUS(mech_mechanism_set_gravity(mechanism, gravity), MECH_STATUS_OK);
    mech_dynamics_t *dynamics = NULL;
    CHECK_STATUS(mech_dynamics_create(mechanism, &dynamics), MECH_STATUS_OK);
    mech_mechanism_destroy(mechanism);
    return dynamics;
}

static double largest(mech_vec3_t v) { return fmax(fabs(v.x), fmax(fabs(v.y), fabs(v.z))); }

static void momentum_monitors(double g) {
    mech_dynamics_t *d = floating_pair(g);
    mech_motion_options_t options;
    CHECK_STATUS(mech_motion_options_default(&options), MECH_STATUS_OK);
    options.rtol = 1e-11;
    options.atol = 1e-12;
    options.estimate_error = 0;
    const double q0[7] = {0.1, -0.2, 0.3, 0.2, -0.4, 0.1, 0.5};
    const double v0[7] = {0.5, 0.3, -0.2, 1.0, -0.5, 2.0, -1.5};
    mech_simulation_t *s = NULL;
    CHECK_STATUS(mech_simulation_create(d, &options, q0, v0, NULL, 7, &s), MECH_STATUS_OK);
    double q[7], qd[7];
    const double t_end = 2.0;
    for (int i = 1; i <= 20; ++i) {
        CHECK_STATUS(mech_simulation_advance(s, 0.05 * i * t_end, 7, q, qd), MECH_STATUS_OK);
    }
    mech_motion_momentum_report_t m;
    CHECK_STATUS(mech_simulation_momentum_report(s, &m), MECH_STATUS_OK);
    CHECK(m.linear.scale > 0.1 && m.angular.scale > 0.1);
    CHECK(fabs(m.angular.max_drift.z) <= 1e-8 * m.angular.scale);
    CHECK(fabs(m.linear.max_drift.x) <= 1e-8 * m.linear.scale);
    CHECK(fabs(m.linear.max_drift.y) <= 1e-8 * m.linear.scale);
    if (g == 0.0) {
        CHECK(largest(m.linear.max_drift) <= 1e-8 * m.linear.scale);
        CHECK(largest(m.angular.max_drift) <= 1e-8 * m.angular.scale);
    } else {
        const double gained = -2.8 * g * t_end;
        CHECK_NEAR(m.linear.last.z - m.linear.initial.z, gained, 1e-8 * fabs(gained));
        CHECK(m.linear.max_drift.z >= 0.99 * fabs(gained));
    }
    CHECK_STATUS(mech_simulation_momentum_report(NULL, &m), MECH_STATUS_NULL_POINTER);
    CHECK_STATUS(mech_simulation_momentum_report(s, NULL), MECH_STATUS_NULL_POINTER);
    mech_simulation_destroy(s);
    mech_dynamics_destroy(d);
}

int main(void) {
    mech_dynamics_t *d = pendulum();
    period(d, MECH_MOTION_DORMAND_PRINCE, 1e-9);
    period(d, MECH_MOTION_STORMER_VERLET, 1e-5);
    rejected_arguments(d);
    step_limit(d);
    momentum_monitors(0.0);
    momentum_monitors(9.81);
    mech_dynamics_destroy(d);
    printf("test_motion: %d checks passed\n", mech_check_count);
    return 0;
}
