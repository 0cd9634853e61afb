/* Constrained dynamics C ABI against closed forms, on a point mass m carried by a free body
 * (its origin at the mass, a small sphere inertia) under gravity −g z:
 *  - a spherical pendulum made by a rod of length l from a ground point: tension
 *    m (g cos θ + v²/l) and acceleration g − (T/m) e (e the unit rod direction), tangential
 *    g sin θ at rest; the position drift of a stretched rod;
 *  - the mass resting on a tilted plane, pinned to a ground point, with a locked coordinate;
 *  - a redundant rod (SINGULAR naming it), and every rejected argument leaving the outputs
 *    untouched. */
#include "check.h"

static const mech_vec3_t ZERO = {0.0, 0.0, 0.0};
static const mech_mat3_t IDENTITY = {{1, 0, 0, 0, 1, 0, 0, 0, 1}};

/* A deterministic generator of doubles in [lo, hi) (xorshift64*). */
static double uniform(uint64_t *state, double lo, double hi) {
    *state ^= *state >> 12;
    *state ^= *state << 25;
    *state ^= *state >> 27;
    const uint64_t r = *state * 2685821657736338717ULL;
    return lo + (hi - lo) * (double)(r >> 11) / 9007199254740992.0;
}

/* A free body of mass m concentrated at its origin (sphere inertia 2/5 m r², r = 1 cm), gravity −g z. */
static mech_dynamics_t *point_mass(double m, double g) {
    mech_tree_t *tree = NULL;
    CHECK_STATUS(mech_tree_create(&tree), MECH_STATUS_OK);
    size_t body = 99;
    CHECK_STATUS(mech_tree_add_body(tree, -1, MECH_JOINT_FREE, NULL, &IDENTITY, &ZERO, &body), MECH_STATUS_OK);
    CHECK(body == 0);
    CHECK_STATUS(mech_tree_finalize(tree), MECH_STATUS_OK);
    mech_mass_properties_t props;
    memset(&props, 0, sizeof props);
    props.mass = m;
    const double inertia = 0.4 * m * 1e-4;
    props.inertia_about_com.m[0] = inertia;
    props.inertia_about_com.m[4] = inertia;
    props.inertia_about_com.m[8] = inertia;
    mech_mechanism_t *mechanism = NULL;
    CHECK_STATUS(mech_mechanism_create(tree, &props, 1, &mechanism), MECH_STATUS_OK);
    mech_tree_destroy(tree);
    const mech_vec3_t gravity = {0.0, 0.0, -g};
    CHECK_STATUS(mech_mechanism_set_gravity(mechanism, gravity), MECH_STATUS_OK);
    mech_dynamics_t *dynamics = NULL;
    CHECK_STATUS(mech_dynamics_create(mechanism, &dynamics), MECH_STATUS_OK);
    mech_mechanism_destroy(mechanism);
    size_t dof = 0;
    CHECK_STATUS(mech_dynamics_dof(dynamics, &dof), MECH_STATUS_OK);
    CHECK(dof == 6);
    return dynamics;
}

/* The free-joint state with the body's origin at `p`, zero rotation and origin velocity `v`. */
static void state_at(const double p[3], const double v[3], double q[6], double qd[6]) {
    for (int k = 0; k < 3; ++k) {
        q[k] = p[k];
        q[k + 3] = 0.0;
        qd[k] = v[k];
        qd[k + 3] = 0.0;
    }
}

static void pendulum_family(void) {
    uint64_t seed = 0x2545F4914F6CDD1DULL;
    for (int trial = 0; trial < 40; ++trial) {
        const double m = uniform(&seed, 0.2, 5.0), g = uniform(&seed, 1.0, 20.0), l = uniform(&seed, 0.1, 3.0);
        const double theta = uniform(&seed, -1.5, 1.5), phi = uniform(&seed, -3.1, 3.1);
        const double pivot[3] = {uniform(&seed, -1, 1), uniform(&seed, -1, 1), uniform(&seed, -1, 1)};
        mech_dynamics_t *d = point_mass(m, g);
        const mech_vec3_t ground = {pivot[0], pivot[1], pivot[2]};
        size_t index = 99, equations = 99;
        CHECK_STATUS(mech_dynamics_add_distance_constraint(d, MECH_GROUND, ground, 0, ZERO, l, &index), MECH_STATUS_OK);
        CHECK(index == 0);
        CHECK_STATUS(mech_dynamics_constraint_equations(d, &equations), MECH_STATUS_OK);
        CHECK(equations == 1);

        /* e: unit vector from the pivot to the mass; t: a unit vector perpendicular to it. */
        const double e[3] = {sin(theta) * cos(phi), sin(theta) * sin(phi), -cos(theta)};
        const double t[3] = {-sin(phi), cos(phi), 0.0};
        const double speed = (trial % 2 == 0) ? 0.0 : uniform(&seed, -3.0, 3.0);
        double p[3], v[3], q[6], qd[6], tau[6] = {0}, qdd[6], lambda[1];
        for (int k = 0; k < 3; ++k) {
            p[k] = pivot[k] + l * e[k];
            v[k] = speed * t[k];
        }
        state_at(p, v, q, qd);
        mech_constrained_report_t report;
        CHECK_STATUS(mech_dynamics_forward_constrained(d, q, qd, tau, 0.0, 6, 1, qdd, lambda, &report), MECH_STATUS_OK);
        const double tension = m * (g * cos(theta) + speed * speed / l);
        const double scale = g + speed * speed / l;
        CHECK_NEAR(lambda[0], tension, 1e-13 * m * scale);
        const double gravity[3] = {0.0, 0.0, -g};
        double radial = 0.0, tangential2 = 0.0;
        for (int k = 0; k < 3; ++k) {
            CHECK_NEAR(qdd[k], gravity[k] - tension / m * e[k], 1e-13 * scale);
            CHECK_NEAR(qdd[k + 3], 0.0, 1e-12 * scale / l);
            radial += qdd[k] * e[k];
        }
        for (int k = 0; k < 3; ++k) tangential2 += (qdd[k] - radial * e[k]) * (qdd[k] - radial * e[k]);
        /* Along the rod: the centripetal −v²/l; across it, g sin θ. */
        CHECK_NEAR(radial, -speed * speed / l, 1e-13 * scale);
        CHECK_NEAR(sqrt(tangential2), g * fabs(sin(theta)), 1e-13 * scale);
        CHECK(report.position_drift <= 1e-15 * (l + 3.0));
        CHECK(report.velocity_drift <= 1e-15 * (fabs(speed) + 1.0));
        CHECK(report.backward_error >= 0.0 && report.backward_error < 1e-14);

        /* A rod stretched by δ: the drift is |δ|; the report may be left out. */
        const double delta = uniform(&seed, -0.1, 0.1) * l;
        for (int k = 0; k < 3; ++k) p[k] = pivot[k] + (l + delta) * e[k];
        state_at(p, v, q, qd);
        CHECK_STATUS(mech_dynamics_forward_constrained(d, q, qd, tau, 0.0, 6, 1, qdd, lambda, &report), MECH_STATUS_OK);
        CHECK_NEAR(report.position_drift, fabs(delta), 1e-14 * (l + 3.0));
        CHECK_STATUS(mech_dynamics_forward_constrained(d, q, qd, tau, 0.0, 6, 1, qdd, lambda, NULL), MECH_STATUS_OK);
        mech_dynamics_destroy(d);
    }
}

/* The mass at rest on the plane n·x = n·p (n random, given unscaled): a = g − (g·n) n, λ = m g·n.
 * Then pinned at p (three scaled axes): q̈ = 0, λ = m g. Then with z locked: λ = −m g. */
static void plane_pin_and_lock(void) {
    uint64_t seed = 0x9E3779B97F4A7C15ULL;
    for (int trial = 0; trial < 20; ++trial) {
        const double m = uniform(&seed, 0.2, 5.0), g = uniform(&seed, 1.0, 20.0), s = uniform(&seed, 0.5, 4.0);
        double n[3] = {uniform(&seed, -1, 1), uniform(&seed, -1, 1), uniform(&seed, 0.2, 1)};
        const double norm = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
        for (int k = 0; k < 3; ++k) n[k] /= norm;
        const double p[3] = {uniform(&seed, -2, 2), uniform(&seed, -2, 2), uniform(&seed, -2, 2)};
        const double rest[3] = {0.0, 0.0, 0.0};
        double q[6], qd[6], tau[6] = {0}, qdd[6], lambda[3];
        state_at(p, rest, q, qd);

        mech_dynamics_t *d = point_mass(m, g);
        const mech_vec3_t normal = {s * n[0], s * n[1], s * n[2]};
        const double offset = s * (n[0] * p[0] + n[1] * p[1] + n[2] * p[2]);
        CHECK_STATUS(mech_dynamics_add_plane_constraint(d, 0, ZERO, normal, offset, NULL), MECH_STATUS_OK);
        CHECK_STATUS(mech_dynamics_forward_constrained(d, q, qd, tau, 0.0, 6, 1, qdd, lambda, NULL), MECH_STATUS_OK);
        const double gn = -g * n[2];
        CHECK_NEAR(lambda[0], m * gn, 1e-13 * m * g);
        const double gravity[3] = {0.0, 0.0, -g};
        for (int k = 0; k < 3; ++k) CHECK_NEAR(qdd[k], gravity[k] - gn * n[k], 1e-13 * g);
        mech_dynamics_destroy(d);

        d = point_mass(m, g);
        const mech_vec3_t at = {p[0], p[1], p[2]};
        const mech_vec3_t axes[3] = {{s, 0, 0}, {0, 2.0 * s, 0}, {0, 0, 0.5 * s}};
        size_t index = 99, equations = 0;
        CHECK_STATUS(mech_dynamics_add_point_constraint(d, 0, ZERO, MECH_GROUND, at, axes, 3, &index), MECH_STATUS_OK);
        CHECK(index == 0);
        CHECK_STATUS(mech_dynamics_constraint_equations(d, &equations), MECH_STATUS_OK);
        CHECK(equations == 3);
        CHECK_STATUS(mech_dynamics_forward_constrained(d, q, qd, tau, 0.0, 6, 3, qdd, lambda, NULL), MECH_STATUS_OK);
        for (int k = 0; k < 6; ++k) CHECK_NEAR(qdd[k], 0.0, 1e-13 * g);
        /* The force on the body is −Σ λ_r d_r = m g z: λ = (0, 0, −m g). */
        CHECK_NEAR(lambda[0], 0.0, 1e-13 * m * g);
        CHECK_NEAR(lambda[1], 0.0, 1e-13 * m * g);
        CHECK_NEAR(lambda[2], -m * g, 1e-13 * m * g);
        mech_dynamics_destroy(d);

        d = point_mass(m, g);
        CHECK_STATUS(mech_dynamics_add_coordinate_constraint(d, 2, p[2], &index), MECH_STATUS_OK);
        CHECK(index == 0);
        CHECK_STATUS(mech_dynamics_forward_constrained(d, q, qd, tau, 0.0, 6, 1, qdd, lambda, NULL), MECH_STATUS_OK);
        for (int k = 0; k < 6; ++k) CHECK_NEAR(qdd[k], 0.0, 1e-13 * g);
        CHECK_NEAR(lambda[0], -m * g, 1e-13 * m * g);
        mech_dynamics_destroy(d);
    }
}

/* Without constraints, m = 0 and free fall; a redundant rod fails with SINGULAR naming it. */
static void redundant_and_rejected(void) {
    const double m = 1.3, g = 9.81, l = 0.7;
    mech_dynamics_t *d = point_mass(m, g);
    const double p[3] = {l * sin(0.3), 0.0, -l * cos(0.3)}, rest[3] = {0, 0, 0};
    double q[6], qd[6], tau[6] = {0}, qdd[6], lambda[2];
    state_at(p, rest, q, qd);
    CHECK_STATUS(mech_dynamics_forward_constrained(d, q, qd, tau, 0.0, 6, 0, qdd, NULL, NULL), MECH_STATUS_OK);
    for (int k = 0; k < 6; ++k) CHECK_NEAR(qdd[k], k == 2 ? -g : 0.0, 1e-14 * g);

    size_t index = 99;
    CHECK_STATUS(mech_dynamics_add_distance_constraint(d, MECH_GROUND, ZERO, 0, ZERO, l, &index), MECH_STATUS_OK);
    CHECK(index == 0);

    /* Rejected arguments: the outputs stay untouched. */
    mech_constrained_report_t report;
    FILL_SENTINEL(qdd, sizeof qdd);
    FILL_SENTINEL(lambda, sizeof lambda);
    FILL_SENTINEL(&report, sizeof report);
    CHECK_STATUS(mech_dynamics_forward_constrained(d, q, qd, tau, 0.0, 6, 2, qdd, lambda, &report),
                 MECH_STATUS_BAD_DIMENSION);
    CHECK_STATUS(mech_dynamics_forward_constrained(d, q, qd, tau, 0.0, 6, 0, qdd, lambda, &report),
                 MECH_STATUS_BAD_DIMENSION);
    CHECK_STATUS(mech_dynamics_forward_constrained(d, q, qd, tau, 0.0, 5, 1, qdd, lambda, &report),
                 MECH_STATUS_BAD_DIMENSION);
    CHECK_STATUS(mech_dynamics_forward_constrained(d, q, qd, tau, NAN, 6, 1, qdd, lambda, &report),
                 MECH_STATUS_NON_FINITE);
    double bad[6];
    memcpy(bad, qd, sizeof bad);
    bad[4] = NAN;
    CHECK_STATUS(mech_dynamics_forward_constrained(d, q, bad, tau, 0.0, 6, 1, qdd, lambda, &report),
                 MECH_STATUS_NON_FINITE);
    CHECK_STATUS(mech_dynamics_forward_constrained(d, q, qd, tau, 0.0, 6, 1, qdd, NULL, &report),
                 MECH_STATUS_NULL_POINTER);
    CHECK_STATUS(mech_dynamics_forward_constrained(NULL, q, qd, tau, 0.0, 6, 1, qdd, lambda, &report),
                 MECH_STATUS_NULL_POINTER);
    CHECK(mech_untouched(qdd, sizeof qdd) && mech_untouched(lambda, sizeof lambda));
    CHECK(mech_untouched(&report, sizeof report));

    /* Rejected constraints leave the count and index_out unchanged. */
    const mech_vec3_t nan_point = {0.0, NAN, 0.0}, zero_axis[1] = {{0, 0, 0}};
    const mech_vec3_t four_axes[4] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}, {1, 1, 0}};
    index = 77;
    CHECK_STATUS(mech_dynamics_add_distance_constraint(d, MECH_GROUND, ZERO, 0, ZERO, NAN, &index),
                 MECH_STATUS_NON_FINITE);
    CHECK_STATUS(mech_dynamics_add_distance_constraint(d, MECH_GROUND, nan_point, 0, ZERO, l, &index),
                 MECH_STATUS_NON_FINITE);
    CHECK_STATUS(mech_dynamics_add_distance_constraint(d, MECH_GROUND, ZERO, 0, ZERO, 0.0, &index),
                 MECH_STATUS_INVALID_ARGUMENT);
    CHECK_STATUS(mech_dynamics_add_distance_constraint(d, MECH_GROUND, ZERO, 1, ZERO, l, &index),
                 MECH_STATUS_INVALID_ARGUMENT);
    CHECK_STATUS(mech_dynamics_add_distance_constraint(d, -2, ZERO, 0, ZERO, l, &index),
                 MECH_STATUS_INVALID_ARGUMENT);
    CHECK_STATUS(mech_dynamics_add_point_constraint(d, 0, ZERO, MECH_GROUND, ZERO, four_axes, 4, &index),
                 MECH_STATUS_INVALID_ARGUMENT);
    CHECK_STATUS(mech_dynamics_add_point_constraint(d, 0, ZERO, MECH_GROUND, ZERO, four_axes, 0, &index),
                 MECH_STATUS_INVALID_ARGUMENT);
    CHECK_STATUS(mech_dynamics_add_point_constraint(d, 0, ZERO, MECH_GROUND, ZERO, zero_axis, 1, &index),
                 MECH_STATUS_INVALID_ARGUMENT);
    CHECK_STATUS(mech_dynamics_add_point_constraint(d, 0, ZERO, MECH_GROUND, ZERO, NULL, 1, &index),
                 MECH_STATUS_NULL_POINTER);
    CHECK_STATUS(mech_dynamics_add_plane_constraint(d, 0, ZERO, ZERO, 1.0, &index), MECH_STATUS_INVALID_ARGUMENT);
    CHECK_STATUS(mech_dynamics_add_plane_constraint(d, 0, ZERO, four_axes[2], INFINITY, &index),
                 MECH_STATUS_NON_FINITE);
    CHECK_STATUS(mech_dynamics_add_coordinate_constraint(d, 6, 0.0, &index), MECH_STATUS_INVALID_ARGUMENT);
    CHECK_STATUS(mech_dynamics_add_coordinate_constraint(d, 0, NAN, &index), MECH_STATUS_NON_FINITE);
    CHECK(index == 77);
    size_t equations = 0;
    CHECK_STATUS(mech_dynamics_constraint_equations(d, &equations), MECH_STATUS_OK);
    CHECK(equations == 1);
    CHECK_STATUS(mech_dynamics_constraint_equations(d, NULL), MECH_STATUS_NULL_POINTER);

    /* The same rod again: the second equation depends on the first. */
    CHECK_STATUS(mech_dynamics_add_distance_constraint(d, MECH_GROUND, ZERO, 0, ZERO, l, &index), MECH_STATUS_OK);
    CHECK(index == 1);
    CHECK_STATUS(mech_dynamics_forward_constrained(d, q, qd, tau, 0.0, 6, 2, qdd, lambda, &report),
                 MECH_STATUS_SINGULAR);
    char message[512];
    mech_last_error(message, sizeof message);
    CHECK(strstr(message, "redundant") != NULL);
    CHECK(strstr(message, "constraint 1") != NULL);
    CHECK(strstr(message, "distance") != NULL);
    CHECK(mech_untouched(qdd, sizeof qdd) && mech_untouched(lambda, sizeof lambda));
    CHECK(mech_untouched(&report, sizeof report));

    /* The unconstrained functions ignore the constraints: free fall. */
    CHECK_STATUS(mech_dynamics_forward(d, q, qd, tau, 0.0, 6, qdd, NULL), MECH_STATUS_OK);
    for (int k = 0; k < 6; ++k) CHECK_NEAR(qdd[k], k == 2 ? -g : 0.0, 1e-14 * g);
    mech_dynamics_destroy(d);
}

int main(void) {
    pendulum_family();
    plane_pin_and_lock();
    redundant_and_rejected();
    return CHECK_DONE();
}
