/* Constrained motion through the C ABI: a double pendulum whose elbow is locked by a coordinate
 * constraint swings as one compound pendulum, so from rest at θ₀ it returns to θ₀ after the
 * period 4 K(sin(θ₀/2)) / ω₀ of the rigid body (K by the arithmetic–geometric mean, independent
 * of the library), by RATTLE and by Dormand–Prince with projection; the elbow stays locked to
 * rounding level and the drift report says so. A pendulum held by a rod to a point it cannot
 * reach in one step stops with MECH_STATUS_NOT_CONVERGED. */
#include "check.h"

static const mech_vec3_t ZERO = {0.0, 0.0, 0.0};
static const mech_mat3_t IDENTITY = {{1, 0, 0, 0, 1, 0, 0, 0, 1}};
static const double M0 = 1.3, L0 = 0.7, M1 = 0.6, L1 = 0.5, I0 = 0.02, G = 9.81;

/* Two revolute joints about y, the second at (0, 0, −L0) on the first body; bobs at
 * (0, 0, −L0) and (0, 0, −L1) with central Iyy = I0. */
static mech_dynamics_t *double_pendulum(void) {
    mech_tree_t *tree = NULL;
    CHECK_STATUS(mech_tree_create(&tree), MECH_STATUS_OK);
    const mech_vec3_t y = {0.0, 1.0, 0.0};
    const mech_vec3_t elbow = {0.0, 0.0, -L0};
    size_t upper = 99, lower = 99;
    CHECK_STATUS(mech_tree_add_body(tree, -1, MECH_JOINT_REVOLUTE, &y, &IDENTITY, &ZERO, &upper), MECH_STATUS_OK);
    CHECK_STATUS(mech_tree_add_body(tree, (int64_t)upper, MECH_JOINT_REVOLUTE, &y, &IDENTITY, &elbow, &lower),
                 MECH_STATUS_OK);
    CHECK_STATUS(mech_tree_finalize(tree), MECH_STATUS_OK);
    mech_mass_properties_t bobs[2];
    memset(bobs, 0, sizeof bobs);
    bobs[0].mass = M0;
    bobs[0].center_of_mass.z = -L0;
    bobs[1].mass = M1;
    bobs[1].center_of_mass.z = -L1;
    for (int i = 0; i < 2; ++i) {
        bobs[i].inertia_about_com.m[0] = I0;
        bobs[i].inertia_about_com.m[4] = I0;
        bobs[i].inertia_about_com.m[8] = 0.5 * I0;
    }
    mech_mechanism_t *mechanism = NULL;
    CHECK_STATUS(mech_mechanism_create(tree, bobs, 2, &mechanism), MECH_STATUS_OK);
    mech_tree_destroy(tree);
    const mech_vec3_t gravity = {0.0, 0.0, -G};
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

static void locked_period(mech_dynamics_t *d, mech_motion_method_t method, double tolerance) {
    /* The rigid pendulum: moment of inertia about the pivot and the moment arm of its weight. */
    const double inertia = M0 * L0 * L0 + M1 * (L0 + L1) * (L0 + L1) + 2.0 * I0;
    const double omega0 = sqrt(G * (M0 * L0 + M1 * (L0 + L1)) / inertia);
    for (int trial = 0; trial < 3; ++trial) {
        const double theta0 = 0.4 + 0.9 * trial;
        const double t_period = 4.0 * elliptic_k(sin(0.5 * theta0)) / omega0;
        mech_motion_options_t options;
        CHECK_STATUS(mech_motion_options_default(&options), MECH_STATUS_OK);
        options.method = method;
        options.rtol = 1e-12;
        options.atol = 1e-14;
        options.step = 1e-3;
        const double q0[2] = {theta0, 0.0}, v0[2] = {0.0, 0.0};
        mech_simulation_t *s = NULL;
        CHECK_STATUS(mech_simulation_create_constrained(d, &options, q0, v0, NULL, 2, &s), MECH_STATUS_OK);
        double q[2], qd[2];
        CHECK_STATUS(mech_simulation_advance(s, 0.5 * t_period, 2, q, qd), MECH_STATUS_OK);
        CHECK_NEAR(q[0], -theta0, tolerance);
        CHECK_STATUS(mech_simulation_advance(s, t_period, 2, q, qd), MECH_STATUS_OK);
        CHECK_NEAR(q[0], theta0, tolerance);
        CHECK_NEAR(qd[0], 0.0, tolerance * omega0);
        CHECK(fabs(q[1]) <= 1e-15 && fabs(qd[1]) <= 1e-14 * omega0);
        mech_motion_constraint_report_t drift;
        CHECK_STATUS(mech_simulation_constraint_report(s, &drift), MECH_STATUS_OK);
        CHECK(drift.max_position_drift <= 1e-15);
        CHECK(drift.max_velocity_drift <= 1e-14 * omega0);
        CHECK(drift.last_position_drift <= drift.max_position_drift);
        mech_motion_report_t report;
        CHECK_STATUS(mech_simulation_report(s, &report), MECH_STATUS_OK);
        CHECK(report.error_q >= fabs(q[0] - theta0));
        CHECK(report.max_energy_drift <= 1e-3);
        CHECK_STATUS(mech_simulation_constraint_report(NULL, &drift), MECH_STATUS_NULL_POINTER);
        CHECK_STATUS(mech_simulation_constraint_report(s, NULL), MECH_STATUS_NULL_POINTER);
        mech_simulation_destroy(s);
    }
}

/* The lower bob tied by a rod of length L0 + L1 to the pivot (the elbow free): a step of 5 s
 * cannot land on the rod, and the run stops with a typed status. */
static void unreachable_rod(void) {
    mech_dynamics_t *d = double_pendulum();
    const mech_vec3_t bob = {0.0, 0.0, -L1};
    size_t index = 99;
    CHECK_STATUS(mech_dynamics_add_distance_constraint(d, 1, bob, MECH_GROUND, ZERO, L0 + L1 - 0.1, &index),
                 MECH_STATUS_OK);
    CHECK(index == 0);
    mech_motion_options_t options;
    CHECK_STATUS(mech_motion_options_default(&options), MECH_STATUS_OK);
    options.method = MECH_MOTION_RATTLE;
    options.step = 5.0;
    options.estimate_error = 0;
    /* On the rod: the elbow bent so that the bob is at distance L0 + L1 − 0.1 from the pivot. */
    const double bend = acos(((L0 + L1 - 0.1) * (L0 + L1 - 0.1) - L0 * L0 - L1 * L1) / (2.0 * L0 * L1));
    const double q0[2] = {2.0, bend}, v0[2] = {3.0, 0.0};
    mech_simulation_t *s = NULL;
    CHECK_STATUS(mech_simulation_create_constrained(d, &options, q0, v0, NULL, 2, &s), MECH_STATUS_OK);
    double q[2] = {42.0, 42.0}, qd[2];
    CHECK_STATUS(mech_simulation_advance(s, 50.0, 2, q, qd), MECH_STATUS_NOT_CONVERGED);
    CHECK(q[0] == 42.0);
    mech_simulation_destroy(s);
    mech_dynamics_destroy(d);
}

int main(void) {
    mech_dynamics_t *d = double_pendulum();
    size_t index = 99;
    CHECK_STATUS(mech_dynamics_add_coordinate_constraint(d, 1, 0.0, &index), MECH_STATUS_OK);
    CHECK(index == 0);
    locked_period(d, MECH_MOTION_RATTLE, 1e-5);
    locked_period(d, MECH_MOTION_DORMAND_PRINCE, 1e-9);
    mech_dynamics_destroy(d);
    unreachable_rod();
    printf("test_motion_constrained: %d checks passed\n", mech_check_count);
    return 0;
}
