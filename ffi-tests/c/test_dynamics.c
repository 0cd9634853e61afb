/* Dynamics C ABI against closed forms: a pendulum (ABA, RNEA, the split of τ, the pivot
 * reaction in three frames, a joint damper, the mass matrix), a charge on three prismatic
 * joints in uniform E and B fields with point dampers, round trips RNEA(ABA(τ)) = τ on a
 * spatial chain, and every rejected argument leaving the outputs untouched. */
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

/* A mechanism made of a finalized tree and its bodies; the tree is freed here. */
static mech_dynamics_t *dynamics_of(mech_tree_t *tree, const mech_mass_properties_t *bodies, size_t count,
                                    mech_vec3_t gravity) {
    CHECK_STATUS(mech_tree_finalize(tree), MECH_STATUS_OK);
    mech_mechanism_t *mechanism = NULL;
    CHECK_STATUS(mech_mechanism_create(tree, bodies, count, &mechanism), MECH_STATUS_OK);
    mech_tree_destroy(tree);
    CHECK_STATUS(mech_mechanism_set_gravity(mechanism, gravity), MECH_STATUS_OK);
    mech_dynamics_t *dynamics = NULL;
    CHECK_STATUS(mech_dynamics_create(mechanism, &dynamics), MECH_STATUS_OK);
    mech_mechanism_destroy(mechanism); /* the dynamics holds its own copy */
    return dynamics;
}

/* Pendulum: a revolute joint about y at the origin, mass m at (0, 0, −l), central Iyy = i0. */
static const double PM = 1.7, PL = 0.9, PI0 = 0.05, PG = 9.81;

static mech_dynamics_t *pendulum(void) {
    mech_tree_t *tree = NULL;
    CHECK_STATUS(mech_tree_create(&tree), MECH_STATUS_OK);
    const mech_vec3_t y = {0.0, 1.0, 0.0};
    size_t body = 99;
    CHECK_STATUS(mech_tree_add_body(tree, -1, MECH_JOINT_REVOLUTE, &y, &IDENTITY, &ZERO, &body), MECH_STATUS_OK);
    mech_mass_properties_t bob;
    memset(&bob, 0, sizeof bob);
    bob.mass = PM;
    bob.center_of_mass.z = -PL;
    bob.inertia_about_com.m[0] = PI0;
    bob.inertia_about_com.m[4] = PI0;
    bob.inertia_about_com.m[8] = 0.5 * PI0;
    const mech_vec3_t gravity = {0.0, 0.0, -PG};
    return dynamics_of(tree, &bob, 1, gravity);
}

/* θ̈ of the pendulum: (τ − m g l sin θ − c θ̇) / (m l² + Iyy). */
static double pendulum_accel(double theta, double theta_dot, double tau, double damping) {
    return (tau - PM * PG * PL * sin(theta) - damping * theta_dot) / (PM * PL * PL + PI0);
}

static void pendulum_closed_forms(void) {
    mech_dynamics_t *d = pendulum();
    size_t dof = 0, bodies = 0;
    CHECK_STATUS(mech_dynamics_dof(d, &dof), MECH_STATUS_OK);
    CHECK_STATUS(mech_dynamics_body_count(d, &bodies), MECH_STATUS_OK);
    CHECK(dof == 1 && bodies == 1);
    const double inertia = PM * PL * PL + PI0;
    uint64_t seed = 0x9E3779B97F4A7C15ULL;
    for (int trial = 0; trial < 50; ++trial) {
        const double q = uniform(&seed, -3.1, 3.1), qd = uniform(&seed, -5.0, 5.0), tau = uniform(&seed, -20.0, 20.0);
        double qdd = 0.0, back = 0.0;
        CHECK_STATUS(mech_dynamics_aba(d, &q, &qd, &tau, 1, &qdd), MECH_STATUS_OK);
        const double exact = pendulum_accel(q, qd, tau, 0.0);
        CHECK_NEAR(qdd, exact, 1e-13 * (fabs(exact) + PG / PL));
        CHECK_STATUS(mech_dynamics_rnea(d, &q, &qd, &qdd, 1, &back), MECH_STATUS_OK);
        CHECK_NEAR(back, tau, 1e-12 * (fabs(tau) + PM * PG * PL));

        /* The split: c = 0 for one revolute joint, g = m g l sin θ; τ = A q̈ + c + g. */
        double tau_full = 0.0, c = 1.0, g = 0.0, err = -1.0;
        CHECK_STATUS(mech_dynamics_inverse(d, &q, &qd, &qdd, 0.0, 1, &tau_full, &c, &g, &err), MECH_STATUS_OK);
        CHECK_NEAR(c, 0.0, 1e-13 * inertia * qd * qd + 1e-300);
        CHECK_NEAR(g, PM * PG * PL * sin(q), 1e-13 * PM * PG * PL);
        CHECK_NEAR(tau_full, inertia * qdd + c + g, 1e-12 * (fabs(tau) + PM * PG * PL));
        CHECK(err > 0.0 && err < 1e-12 * (fabs(tau) + PM * PG * PL + inertia * fabs(qdd)));

        /* The pivot's reaction: F = m (ẍ_C − g), M about the pivot along y = τ, and in the
         * body frame F = m (−l θ̈ − g sin θ, 0, l θ̇² + g cos θ). */
        const double s = sin(q), co = cos(q);
        const double ax = -PL * co * qdd + PL * s * qd * qd, az = PL * s * qdd + PL * co * qd * qd;
        double w[6], wb[6], wj[6];
        CHECK_STATUS(mech_dynamics_reactions(d, &q, &qd, &qdd, 1, MECH_REACTION_FRAME_WORLD, 1, w), MECH_STATUS_OK);
        const double f_scale = PM * (PG + PL * (fabs(qdd) + qd * qd));
        CHECK_NEAR(w[0], PM * ax, 1e-13 * f_scale);
        CHECK_NEAR(w[1], 0.0, 1e-13 * f_scale);
        CHECK_NEAR(w[2], PM * (az + PG), 1e-13 * f_scale);
        CHECK_NEAR(w[3], 0.0, 1e-13 * f_scale * PL);
        CHECK_NEAR(w[4], tau, 1e-12 * f_scale * PL);
        CHECK_NEAR(w[5], 0.0, 1e-13 * f_scale * PL);
        CHECK_STATUS(mech_dynamics_reactions(d, &q, &qd, &qdd, 1, MECH_REACTION_FRAME_BODY, 1, wb), MECH_STATUS_OK);
        CHECK_NEAR(wb[0], PM * (-PL * qdd - PG * s), 1e-13 * f_scale);
        CHECK_NEAR(wb[2], PM * (PL * qd * qd + PG * co), 1e-13 * f_scale);
        CHECK_NEAR(wb[4], tau, 1e-12 * f_scale * PL);
        /* The root's joint frame is the base frame here (identity placement). */
        CHECK_STATUS(mech_dynamics_reactions(d, &q, &qd, &qdd, 1, MECH_REACTION_FRAME_JOINT, 1, wj), MECH_STATUS_OK);
        for (int k = 0; k < 6; ++k) CHECK_NEAR(wj[k], w[k], 1e-13 * f_scale * (1.0 + PL));

        /* Forward with its report: the recursion is accepted at rounding level. */
        mech_forward_report_t report;
        double qdd2 = 0.0;
        CHECK_STATUS(mech_dynamics_forward(d, &q, &qd, &tau, 0.0, 1, &qdd2, &report), MECH_STATUS_OK);
        CHECK_NEAR(qdd2, exact, 1e-13 * (fabs(exact) + PG / PL));
        CHECK(report.method == MECH_FORWARD_ARTICULATED_BODY);
        CHECK(report.backward_error >= 0.0 && report.backward_error < 1e-14);
        CHECK(report.condition == -1.0 && report.error_estimate == -1.0 && report.dissipation == 0.0);
        CHECK_STATUS(mech_dynamics_forward_crba(d, &q, &qd, &tau, 0.0, 1, &qdd2, &report), MECH_STATUS_OK);
        CHECK_NEAR(qdd2, exact, 1e-13 * (fabs(exact) + PG / PL));
        CHECK(report.method == MECH_FORWARD_MASS_MATRIX);
        CHECK_NEAR(report.condition, 1.0, 1e-15); /* a 1×1 matrix */
        CHECK(report.error_estimate >= 0.0 && report.error_estimate <= 1e-13 * (fabs(exact) + PG / PL));
        CHECK_STATUS(mech_dynamics_forward(d, &q, &qd, &tau, 0.0, 1, &qdd2, NULL), MECH_STATUS_OK);
    }
    double a = 0.0;
    const double q0 = 0.4;
    CHECK_STATUS(mech_dynamics_mass_matrix(d, &q0, 1, &a), MECH_STATUS_OK);
    CHECK_NEAR(a, inertia, 1e-15 * inertia);

    /* A joint damper adds −c θ̇; D = ½ c θ̇². */
    size_t index = 99;
    const double damping = 0.8;
    CHECK_STATUS(mech_dynamics_add_joint_damper(d, 0, damping, &index), MECH_STATUS_OK);
    CHECK(index == 0);
    const double q = 0.7, qd = -2.3, tau = 1.5;
    double qdd = 0.0, back = 0.0;
    mech_forward_report_t report;
    CHECK_STATUS(mech_dynamics_forward(d, &q, &qd, &tau, 0.0, 1, &qdd, &report), MECH_STATUS_OK);
    CHECK_NEAR(qdd, pendulum_accel(q, qd, tau, damping), 1e-13 * PG / PL);
    CHECK_NEAR(report.dissipation, 0.5 * damping * qd * qd, 1e-15);
    CHECK_STATUS(mech_dynamics_rnea(d, &q, &qd, &qdd, 1, &back), MECH_STATUS_OK);
    CHECK_NEAR(back, tau, 1e-13 * PM * PG * PL);
    mech_dynamics_destroy(d);
}

/* A charge e on body 2 of three prismatic joints along x, y, z: A = diag(M0, M1, M2) with
 * M_k the mass the coordinate moves, so q̈_k = (e (E + v × B) + dampers)_k / M_k, v = q̇. */
static const double MASS[3] = {0.7, 1.1, 2.3};

static mech_dynamics_t *three_slides(void) {
    mech_tree_t *tree = NULL;
    CHECK_STATUS(mech_tree_create(&tree), MECH_STATUS_OK);
    const mech_vec3_t axes[3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
    mech_mass_properties_t bodies[3];
    memset(bodies, 0, sizeof bodies);
    for (int i = 0; i < 3; ++i) {
        size_t body = 99;
        CHECK_STATUS(mech_tree_add_body(tree, i - 1, MECH_JOINT_PRISMATIC, &axes[i], &IDENTITY, &ZERO, &body),
                     MECH_STATUS_OK);
        bodies[i].mass = MASS[i];
    }
    return dynamics_of(tree, bodies, 3, ZERO);
}

static void cross(const double a[3], const double b[3], double out[3]) {
    out[0] = a[1] * b[2] - a[2] * b[1];
    out[1] = a[2] * b[0] - a[0] * b[2];
    out[2] = a[0] * b[1] - a[1] * b[0];
}

static void charge_in_fields(void) {
    const double e = -1.6, E[3] = {0.3, -2.0, 1.2}, B[3] = {0.5, 0.8, -1.4};
    const double moved[3] = {MASS[0] + MASS[1] + MASS[2], MASS[1] + MASS[2], MASS[2]};
    const mech_vec3_t point = {0.1, -0.2, 0.3}, field_e = {E[0], E[1], E[2]}, field_b = {B[0], B[1], B[2]};
    uint64_t seed = 12345;
    for (int variant = 0; variant < 3; ++variant) {
        mech_dynamics_t *d = three_slides();
        size_t index = 99;
        CHECK_STATUS(mech_dynamics_add_charged_point(d, 2, point, e, field_e, field_b, &index), MECH_STATUS_OK);
        CHECK(index == 0);
        const double c = 0.9;
        const mech_vec3_t anchor = {0.5, 0.4, -0.6};
        if (variant > 0) {
            /* variant 1: damper on the full relative velocity; 2: along the line (dashpot). */
            CHECK_STATUS(mech_dynamics_add_point_damper(d, 2, point, MECH_GROUND, anchor, c, variant - 1, &index),
                         MECH_STATUS_OK);
            CHECK(index == 0);
        }
        for (int trial = 0; trial < 20; ++trial) {
            double q[3], v[3], tau[3], qdd[3], back[3], vxb[3];
            for (int k = 0; k < 3; ++k) {
                q[k] = uniform(&seed, -1.0, 1.0);
                v[k] = uniform(&seed, -3.0, 3.0);
                tau[k] = uniform(&seed, -2.0, 2.0);
            }
            cross(v, B, vxb);
            /* The point's position relative to the anchor, and the damper force on the point. */
            const double x[3] = {q[0] + point.x - anchor.x, q[1] + point.y - anchor.y, q[2] + point.z - anchor.z};
            const double len = sqrt(x[0] * x[0] + x[1] * x[1] + x[2] * x[2]);
            const double rate = (x[0] * v[0] + x[1] * v[1] + x[2] * v[2]) / len;
            double damper[3], dissipation = 0.0;
            for (int k = 0; k < 3; ++k) damper[k] = variant == 1 ? -c * v[k] : variant == 2 ? -c * rate * x[k] / len : 0.0;
            if (variant == 1) dissipation = 0.5 * c * (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
            if (variant == 2) dissipation = 0.5 * c * rate * rate;
            mech_forward_report_t report;
            CHECK_STATUS(mech_dynamics_forward(d, q, v, tau, 0.0, 3, qdd, &report), MECH_STATUS_OK);
            for (int k = 0; k < 3; ++k) {
                const double exact = (tau[k] + e * (E[k] + vxb[k]) + damper[k]) / moved[k];
                CHECK_NEAR(qdd[k], exact, 1e-13 * (1.0 + fabs(exact)));
            }
            CHECK_NEAR(report.dissipation, dissipation, 1e-14 * (1.0 + dissipation));
            CHECK_STATUS(mech_dynamics_rnea(d, q, v, qdd, 3, back), MECH_STATUS_OK);
            for (int k = 0; k < 3; ++k) CHECK_NEAR(back[k], tau[k], 1e-13 * 10.0);
        }
        mech_dynamics_destroy(d);
    }
}

/* A spatial chain of four bodies (revolute about x, y, z and a prismatic joint, offsets and
 * central inertias random): RNEA(ABA(τ)) = τ and A q̈ + RNEA(q, q̇, 0) = τ with A from the
 * composite-rigid-body recursion. */
static void chain_round_trips(void) {
    uint64_t seed = 777;
    const mech_vec3_t axes[4] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}, {0.6, 0.0, 0.8}};
    const mech_joint_type_t kinds[4] = {MECH_JOINT_REVOLUTE, MECH_JOINT_REVOLUTE, MECH_JOINT_REVOLUTE,
                                        MECH_JOINT_PRISMATIC};
    for (int trial = 0; trial < 10; ++trial) {
        mech_tree_t *tree = NULL;
        CHECK_STATUS(mech_tree_create(&tree), MECH_STATUS_OK);
        mech_mass_properties_t bodies[4];
        memset(bodies, 0, sizeof bodies);
        for (int i = 0; i < 4; ++i) {
            const mech_vec3_t offset = {uniform(&seed, -0.5, 0.5), uniform(&seed, -0.5, 0.5), uniform(&seed, -1.0, 0.0)};
            size_t body = 0;
            CHECK_STATUS(mech_tree_add_body(tree, i - 1, kinds[i], &axes[i], &IDENTITY, i == 0 ? &ZERO : &offset, &body),
                         MECH_STATUS_OK);
            bodies[i].mass = uniform(&seed, 0.5, 3.0);
            bodies[i].center_of_mass.x = uniform(&seed, -0.3, 0.3);
            bodies[i].center_of_mass.z = uniform(&seed, -0.6, 0.0);
            for (int k = 0; k < 3; ++k) bodies[i].inertia_about_com.m[4 * k] = uniform(&seed, 0.02, 0.04);
        }
        const mech_vec3_t gravity = {0.0, 0.0, -9.81};
        mech_dynamics_t *d = dynamics_of(tree, bodies, 4, gravity);
        double q[4], v[4], tau[4], qdd[4], back[4], bias[4], a[16];
        const double zero[4] = {0, 0, 0, 0};
        for (int k = 0; k < 4; ++k) {
            q[k] = uniform(&seed, -2.0, 2.0);
            v[k] = uniform(&seed, -3.0, 3.0);
            tau[k] = uniform(&seed, -10.0, 10.0);
        }
        CHECK_STATUS(mech_dynamics_aba(d, q, v, tau, 4, qdd), MECH_STATUS_OK);
        CHECK_STATUS(mech_dynamics_rnea(d, q, v, qdd, 4, back), MECH_STATUS_OK);
        CHECK_STATUS(mech_dynamics_rnea(d, q, v, zero, 4, bias), MECH_STATUS_OK);
        CHECK_STATUS(mech_dynamics_mass_matrix(d, q, 4, a), MECH_STATUS_OK);
        for (int i = 0; i < 4; ++i) {
            double row = bias[i];
            for (int j = 0; j < 4; ++j) {
                row += a[i + 4 * j] * qdd[j];
                CHECK_NEAR(a[i + 4 * j], a[j + 4 * i], 1e-15 * (1.0 + fabs(a[i + 4 * j])));
            }
            CHECK_NEAR(back[i], tau[i], 1e-12 * 100.0);
            CHECK_NEAR(row, tau[i], 1e-12 * 100.0);
        }
        mech_dynamics_destroy(d);
    }
}

static void rejected_arguments(void) {
    mech_dynamics_t *d = pendulum();
    const double q = 0.3, qd = 0.1, x = 0.2, nan = NAN;
    double out[6];
    mech_forward_report_t report;
    FILL_SENTINEL(out, sizeof out);
    FILL_SENTINEL(&report, sizeof report);
    CHECK_STATUS(mech_dynamics_aba(NULL, &q, &qd, &x, 1, out), MECH_STATUS_NULL_POINTER);
    CHECK_STATUS(mech_dynamics_rnea(d, &q, &qd, &x, 2, out), MECH_STATUS_BAD_DIMENSION);
    CHECK_STATUS(mech_dynamics_aba(d, &q, &qd, &x, 0, out), MECH_STATUS_BAD_DIMENSION);
    CHECK_STATUS(mech_dynamics_aba(d, &nan, &qd, &x, 1, out), MECH_STATUS_NON_FINITE);
    CHECK_STATUS(mech_dynamics_rnea(d, &q, &nan, &x, 1, out), MECH_STATUS_NON_FINITE);
    CHECK_STATUS(mech_dynamics_inverse(d, &q, &qd, &x, nan, 1, out, NULL, NULL, NULL), MECH_STATUS_NON_FINITE);
    CHECK_STATUS(mech_dynamics_forward(d, &q, &qd, &nan, 0.0, 1, out, &report), MECH_STATUS_NON_FINITE);
    CHECK_STATUS(mech_dynamics_forward_crba(d, &q, &qd, &x, 0.0, 3, out, &report), MECH_STATUS_BAD_DIMENSION);
    CHECK_STATUS(mech_dynamics_reactions(d, &q, &qd, &x, 1, 3, 1, out), MECH_STATUS_BAD_ENUM);
    CHECK_STATUS(mech_dynamics_reactions(d, &q, &qd, &x, 1, -1, 1, out), MECH_STATUS_BAD_ENUM);
    CHECK_STATUS(mech_dynamics_reactions(d, &q, &qd, &x, 1, MECH_REACTION_FRAME_WORLD, 2, out),
                 MECH_STATUS_BAD_DIMENSION);
    CHECK_STATUS(mech_dynamics_reactions(d, &q, &qd, &x, 1, MECH_REACTION_FRAME_WORLD, 1, NULL),
                 MECH_STATUS_NULL_POINTER);
    CHECK_STATUS(mech_dynamics_mass_matrix(d, &nan, 1, out), MECH_STATUS_NON_FINITE);
    CHECK_STATUS(mech_dynamics_mass_matrix(d, &q, 1, NULL), MECH_STATUS_NULL_POINTER);
    CHECK(mech_untouched(out, sizeof out) && mech_untouched(&report, sizeof report));

    size_t index = 42;
    CHECK_STATUS(mech_dynamics_add_joint_damper(d, 0, -0.5, &index), MECH_STATUS_INVALID_ARGUMENT);
    CHECK_STATUS(mech_dynamics_add_joint_damper(d, 0, nan, &index), MECH_STATUS_NON_FINITE);
    CHECK_STATUS(mech_dynamics_add_joint_damper(d, 1, 0.5, &index), MECH_STATUS_INVALID_ARGUMENT);
    CHECK_STATUS(mech_dynamics_add_joint_damper(NULL, 0, 0.5, &index), MECH_STATUS_NULL_POINTER);
    CHECK_STATUS(mech_dynamics_add_point_damper(d, 0, ZERO, MECH_GROUND, ZERO, -1.0, 0, &index),
                 MECH_STATUS_INVALID_ARGUMENT);
    CHECK_STATUS(mech_dynamics_add_point_damper(d, 0, ZERO, MECH_GROUND, ZERO, 1.0, 2, &index),
                 MECH_STATUS_INVALID_ARGUMENT);
    CHECK_STATUS(mech_dynamics_add_point_damper(d, 1, ZERO, MECH_GROUND, ZERO, 1.0, 0, &index),
                 MECH_STATUS_INVALID_ARGUMENT);
    CHECK_STATUS(mech_dynamics_add_point_damper(d, -2, ZERO, MECH_GROUND, ZERO, 1.0, 0, &index),
                 MECH_STATUS_INVALID_ARGUMENT);
    const mech_vec3_t bad_point = {0.0, NAN, 0.0};
    CHECK_STATUS(mech_dynamics_add_point_damper(d, 0, bad_point, MECH_GROUND, ZERO, 1.0, 1, &index),
                 MECH_STATUS_NON_FINITE);
    CHECK_STATUS(mech_dynamics_add_charged_point(d, 3, ZERO, 1.0, ZERO, ZERO, &index), MECH_STATUS_INVALID_ARGUMENT);
    CHECK_STATUS(mech_dynamics_add_charged_point(d, 0, ZERO, 1.0, bad_point, ZERO, &index), MECH_STATUS_NON_FINITE);
    CHECK(index == 42);
    size_t dof = 7;
    CHECK_STATUS(mech_dynamics_dof(NULL, &dof), MECH_STATUS_NULL_POINTER);
    CHECK_STATUS(mech_dynamics_body_count(d, NULL), MECH_STATUS_NULL_POINTER);
    CHECK(dof == 7);
    mech_dynamics_t *none = NULL;
    CHECK_STATUS(mech_dynamics_create(NULL, &none), MECH_STATUS_NULL_POINTER);
    CHECK(none == NULL);

    /* A dashpot whose points coincide has no direction: evaluations fail, nothing written. */
    const mech_vec3_t bob = {0.0, 0.0, -PL}, below = {0.0, 0.0, -PL};
    CHECK_STATUS(mech_dynamics_add_point_damper(d, 0, bob, MECH_GROUND, below, 1.0, 1, NULL), MECH_STATUS_OK);
    const double hanging = 0.0;
    CHECK_STATUS(mech_dynamics_aba(d, &hanging, &qd, &x, 1, out), MECH_STATUS_SINGULAR);
    CHECK(mech_untouched(out, sizeof out));
    mech_dynamics_destroy(d);

    /* A joint that moves no inertia: a point mass on its own revolute axis. */
    mech_tree_t *tree = NULL;
    CHECK_STATUS(mech_tree_create(&tree), MECH_STATUS_OK);
    const mech_vec3_t y = {0.0, 1.0, 0.0};
    size_t body = 0;
    CHECK_STATUS(mech_tree_add_body(tree, -1, MECH_JOINT_REVOLUTE, &y, &IDENTITY, &ZERO, &body), MECH_STATUS_OK);
    mech_mass_properties_t point_mass;
    memset(&point_mass, 0, sizeof point_mass);
    point_mass.mass = 1.0;
    mech_dynamics_t *singular = dynamics_of(tree, &point_mass, 1, ZERO);
    CHECK_STATUS(mech_dynamics_aba(singular, &q, &qd, &x, 1, out), MECH_STATUS_SINGULAR);
    CHECK_STATUS(mech_dynamics_forward(singular, &q, &qd, &x, 0.0, 1, out, &report), MECH_STATUS_SINGULAR);
    CHECK(mech_untouched(out, sizeof out) && mech_untouched(&report, sizeof report));
    mech_dynamics_destroy(singular);
    mech_dynamics_destroy(NULL);
}

/* A point mass d = 1e-6 … 1e-9 m from the second joint's axis, behind a 1 kg link: A is
 * ill-conditioned up to singular to working precision. Every answer of the mass-matrix route
 * has κ∞ ≥ 1 and an estimate that is finite, or +∞ (HUGE_VAL) exactly where n·κ∞·u ≥ 1/2; a
 * refusal is MECH_STATUS_SINGULAR; and some d gives the +∞ answer through the boundary. */
static mech_dynamics_t *near_axis_mass(double d) {
    mech_tree_t *tree = NULL;
    CHECK_STATUS(mech_tree_create(&tree), MECH_STATUS_OK);
    const mech_vec3_t z = {0.0, 0.0, 1.0}, x = {1.0, 0.0, 0.0}, offset = {0.5, 0.0, 0.0};
    size_t root = 99, tip = 99;
    CHECK_STATUS(mech_tree_add_body(tree, -1, MECH_JOINT_REVOLUTE, &z, &IDENTITY, &ZERO, &root), MECH_STATUS_OK);
    CHECK_STATUS(mech_tree_add_body(tree, (int64_t)root, MECH_JOINT_REVOLUTE, &x, &IDENTITY, &offset, &tip),
                 MECH_STATUS_OK);
    mech_mass_properties_t bodies[2];
    memset(bodies, 0, sizeof bodies);
    bodies[0].mass = 1.0;
    bodies[0].center_of_mass.x = 0.25;
    bodies[0].inertia_about_com.m[0] = bodies[0].inertia_about_com.m[4] = bodies[0].inertia_about_com.m[8] = 0.01;
    bodies[1].mass = 0.5;
    bodies[1].center_of_mass.x = 0.3;
    bodies[1].center_of_mass.y = d;
    const mech_vec3_t gravity = {0.0, 0.0, -9.81};
    return dynamics_of(tree, bodies, 2, gravity);
}

static void singular_to_working_precision(void) {
    const double q[2] = {0.3, 0.7}, qd[2] = {0.2, -0.1}, tau[2] = {0.4, 0.1};
    const double u = 2.220446049250313e-16;
    int infinite = 0;
    for (int step = 0; step <= 60; ++step) {
        mech_dynamics_t *d = near_axis_mass(pow(10.0, -6.0 - 0.05 * step));
        double qdd[2] = {0.0, 0.0};
        mech_forward_report_t report;
        const mech_status_t status = mech_dynamics_forward_crba(d, q, qd, tau, 0.0, 2, qdd, &report);
        CHECK(status == MECH_STATUS_OK || status == MECH_STATUS_SINGULAR);
        if (status == MECH_STATUS_OK) {
            CHECK(report.method == MECH_FORWARD_MASS_MATRIX && report.condition >= 1.0);
            CHECK(isfinite(qdd[0]) && isfinite(qdd[1]));
            if (report.error_estimate == HUGE_VAL) {
                CHECK(2.0 * report.condition * u >= 0.5);
                ++infinite;
            } else {
                CHECK(isfinite(report.error_estimate) && report.error_estimate >= 0.0);
                CHECK(2.0 * report.condition * u < 0.5);
            }
        }
        mech_dynamics_destroy(d);
    }
    CHECK(infinite > 0);
}

int main(void) {
    singular_to_working_precision();
    pendulum_closed_forms();
    charge_in_fields();
    chain_round_trips();
    rejected_arguments();
    return CHECK_DONE();
}
