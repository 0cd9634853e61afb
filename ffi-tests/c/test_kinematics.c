/* C test of the kinematics entry points: rotations, Euler angles, rigid-motion fields,
 * relative motion and the kinematic tree handle, with every error path. */
#include "check.h"

static const double PI = 3.14159265358979323846;
static const double TOL = 1e-14;

static mech_mat3_t identity3(void) {
    mech_mat3_t m;
    memset(&m, 0, sizeof m);
    m.m[0] = m.m[4] = m.m[8] = 1.0;
    return m;
}

/* Rz(t), column-major. */
static mech_mat3_t rot_z(double t) {
    mech_mat3_t m = identity3();
    m.m[0] = cos(t);
    m.m[1] = sin(t);
    m.m[3] = -sin(t);
    m.m[4] = cos(t);
    return m;
}

static void test_existing_and_exp_log(void) {
    mech_mat3_t r;
    mech_vec3_t phi = {0.0, 0.0, PI / 2.0};
    CHECK_STATUS(mech_rotation_exp(&phi, &r), MECH_STATUS_OK);
    mech_mat3_t rz = rot_z(PI / 2.0);
    for (int i = 0; i < 9; ++i) CHECK_NEAR(r.m[i], rz.m[i], TOL);
    mech_vec3_t back;
    CHECK_STATUS(mech_rotation_log(&r, &back), MECH_STATUS_OK);
    CHECK_NEAR(back.z, PI / 2.0, TOL);
    /* Half turn about x: |log| = π. */
    mech_vec3_t half = {PI, 0.0, 0.0};
    CHECK_STATUS(mech_rotation_exp(&half, &r), MECH_STATUS_OK);
    CHECK_STATUS(mech_rotation_log(&r, &back), MECH_STATUS_OK);
    CHECK_NEAR(fabs(back.x), PI, 4e-15);
    mech_quat_t q;
    CHECK_STATUS(mech_quat_from_rotation_matrix(&rz, &q), MECH_STATUS_OK);
    CHECK_NEAR(q.w, sqrt(0.5), TOL);
    CHECK_NEAR(q.z, sqrt(0.5), TOL);
    mech_mat3_t r2;
    CHECK_STATUS(mech_rotation_matrix_from_quat(&q, MECH_QUAT_REQUIRE_UNIT, &r2), MECH_STATUS_OK);
    for (int i = 0; i < 9; ++i) CHECK_NEAR(r2.m[i], rz.m[i], TOL);
    mech_vec3_t w;
    mech_mat3_t rdot;
    memset(&rdot, 0, sizeof rdot);
    CHECK_STATUS(mech_angular_velocity_from_rate(&rz, &rdot, &w), MECH_STATUS_OK);
    CHECK(w.x == 0.0 && w.y == 0.0 && w.z == 0.0);

    /* Error paths: nothing written. */
    FILL_SENTINEL(&r, sizeof r);
    CHECK_STATUS(mech_rotation_exp(NULL, &r), MECH_STATUS_NULL_POINTER);
    CHECK_STATUS(mech_rotation_exp(&phi, NULL), MECH_STATUS_NULL_POINTER);
    mech_vec3_t bad = {NAN, 0.0, 0.0};
    CHECK_STATUS(mech_rotation_exp(&bad, &r), MECH_STATUS_NON_FINITE);
    CHECK(mech_untouched(&r, sizeof r));
    FILL_SENTINEL(&back, sizeof back);
    mech_mat3_t refl = identity3();
    refl.m[8] = -1.0;
    CHECK_STATUS(mech_rotation_log(&refl, &back), MECH_STATUS_INVALID_ARGUMENT);
    CHECK_STATUS(mech_rotation_log(NULL, &back), MECH_STATUS_NULL_POINTER);
    CHECK_STATUS(mech_rotation_log(&rz, NULL), MECH_STATUS_NULL_POINTER);
    mech_mat3_t nanm = identity3();
    nanm.m[3] = INFINITY;
    CHECK_STATUS(mech_rotation_log(&nanm, &back), MECH_STATUS_NON_FINITE);
    CHECK(mech_untouched(&back, sizeof back));
    FILL_SENTINEL(&q, sizeof q);
    CHECK_STATUS(mech_quat_from_rotation_matrix(&refl, &q), MECH_STATUS_INVALID_ARGUMENT);
    CHECK_STATUS(mech_quat_from_rotation_matrix(NULL, &q), MECH_STATUS_NULL_POINTER);
    CHECK(mech_untouched(&q, sizeof q));
    mech_quat_t q2 = {2.0, 0.0, 0.0, 0.0};
    FILL_SENTINEL(&r2, sizeof r2);
    CHECK_STATUS(mech_rotation_matrix_from_quat(&q2, MECH_QUAT_REQUIRE_UNIT, &r2), MECH_STATUS_INVALID_ARGUMENT);
    CHECK_STATUS(mech_rotation_matrix_from_quat(&q2, 7, &r2), MECH_STATUS_BAD_ENUM);
    CHECK(mech_untouched(&r2, sizeof r2));
    CHECK_STATUS(mech_rotation_matrix_from_quat(&q2, MECH_QUAT_NORMALIZE, &r2), MECH_STATUS_OK);
    FILL_SENTINEL(&w, sizeof w);
    CHECK_STATUS(mech_angular_velocity_from_rate(&rz, &nanm, &w), MECH_STATUS_NON_FINITE);
    CHECK_STATUS(mech_angular_velocity_from_rate(&refl, &rdot, &w), MECH_STATUS_INVALID_ARGUMENT);
    CHECK(mech_untouched(&w, sizeof w));
}

static void test_axis_angle_and_orthonormalize(void) {
    mech_vec3_t z = {0.0, 0.0, 1.0};
    mech_mat3_t r;
    CHECK_STATUS(mech_rotation_from_axis_angle(&z, 0.3, &r), MECH_STATUS_OK);
    mech_mat3_t rz = rot_z(0.3);
    for (int i = 0; i < 9; ++i) CHECK_NEAR(r.m[i], rz.m[i], TOL);
    FILL_SENTINEL(&r, sizeof r);
    mech_vec3_t zero = {0.0, 0.0, 0.0};
    CHECK_STATUS(mech_rotation_from_axis_angle(&zero, 0.3, &r), MECH_STATUS_INVALID_ARGUMENT);
    mech_vec3_t two = {0.0, 2.0, 0.0};
    CHECK_STATUS(mech_rotation_from_axis_angle(&two, 0.3, &r), MECH_STATUS_INVALID_ARGUMENT);
    CHECK_STATUS(mech_rotation_from_axis_angle(&z, NAN, &r), MECH_STATUS_NON_FINITE);
    CHECK_STATUS(mech_rotation_from_axis_angle(NULL, 0.3, &r), MECH_STATUS_NULL_POINTER);
    CHECK_STATUS(mech_rotation_from_axis_angle(&z, 0.3, NULL), MECH_STATUS_NULL_POINTER);
    CHECK(mech_untouched(&r, sizeof r));

    mech_mat3_t drift = rot_z(0.3);
    drift.m[0] += 1e-7;
    drift.m[4] -= 2e-7;
    double corr;
    CHECK_STATUS(mech_rotation_orthonormalize(&drift, &r, &corr), MECH_STATUS_OK);
    CHECK(corr > 0.0 && corr < 3e-7);
    /* RᵀR = I */
    for (int i = 0; i < 3; ++i) {
        for (int j = 0; j < 3; ++j) {
            double s = 0.0;
            for (int k = 0; k < 3; ++k) s += r.m[k + 3 * i] * r.m[k + 3 * j];
            CHECK_NEAR(s, i == j ? 1.0 : 0.0, 1e-15);
        }
    }
    FILL_SENTINEL(&r, sizeof r);
    FILL_SENTINEL(&corr, sizeof corr);
    mech_mat3_t refl = identity3();
    refl.m[0] = -1.0;
    CHECK_STATUS(mech_rotation_orthonormalize(&refl, &r, &corr), MECH_STATUS_INVALID_ARGUMENT);
    drift.m[2] = NAN;
    CHECK_STATUS(mech_rotation_orthonormalize(&drift, &r, &corr), MECH_STATUS_NON_FINITE);
    CHECK_STATUS(mech_rotation_orthonormalize(NULL, &r, &corr), MECH_STATUS_NULL_POINTER);
    CHECK_STATUS(mech_rotation_orthonormalize(&refl, NULL, &corr), MECH_STATUS_NULL_POINTER);
    CHECK_STATUS(mech_rotation_orthonormalize(&refl, &r, NULL), MECH_STATUS_NULL_POINTER);
    CHECK(mech_untouched(&r, sizeof r));
    CHECK(mech_untouched(&corr, sizeof corr));
}

static void test_euler(void) {
    /* Aerospace ZYX: yaw, pitch, roll round trip. */
    double angles[3] = {0.3, -0.4, 1.2};
    mech_mat3_t r;
    CHECK_STATUS(mech_rotation_from_euler(MECH_EULER_ZYX, angles, &r), MECH_STATUS_OK);
    CHECK_NEAR(r.m[2], -sin(-0.4), TOL); /* entry (2,0) = −sin(pitch) */
    double back[3];
    int32_t lock;
    double dist;
    CHECK_STATUS(mech_euler_from_rotation(&r, MECH_EULER_ZYX, back, &lock, &dist), MECH_STATUS_OK);
    for (int i = 0; i < 3; ++i) CHECK_NEAR(back[i], angles[i], 4e-15);
    CHECK(lock == 0);
    CHECK_NEAR(dist, cos(-0.4), TOL);
    /* Gimbal lock of ZYZ at θ = 0: reported, and the angles reproduce R. */
    double locked[3] = {0.5, 0.0, 0.7};
    CHECK_STATUS(mech_rotation_from_euler(MECH_EULER_ZYZ, locked, &r), MECH_STATUS_OK);
    CHECK_STATUS(mech_euler_from_rotation(&r, MECH_EULER_ZYZ, back, &lock, &dist), MECH_STATUS_OK);
    CHECK(lock == 1);
    CHECK_NEAR(back[0] + back[2], 1.2, 4e-15);
    /* EB1911 (13), body frame, for ZYZ {ψ, θ, φ}: r = φ̇ + cos θ ψ̇. */
    double eb[3] = {0.2, 0.9, -0.4}; /* ψ, θ, φ */
    double rates[3] = {1.0, 0.5, 2.0}; /* ψ̇, θ̇, φ̇ */
    mech_vec3_t w;
    CHECK_STATUS(mech_angular_velocity_from_euler_rates(MECH_EULER_ZYZ, eb, rates, MECH_FRAME_BODY, &w),
                 MECH_STATUS_OK);
    CHECK_NEAR(w.x, 0.5 * sin(-0.4) - sin(0.9) * cos(-0.4) * 1.0, TOL);
    CHECK_NEAR(w.y, 0.5 * cos(-0.4) + sin(0.9) * sin(-0.4) * 1.0, TOL);
    CHECK_NEAR(w.z, 2.0 + cos(0.9) * 1.0, TOL);
    double rb[3];
    CHECK_STATUS(mech_euler_rates_from_angular_velocity(MECH_EULER_ZYZ, eb, &w, MECH_FRAME_BODY, rb), MECH_STATUS_OK);
    for (int i = 0; i < 3; ++i) CHECK_NEAR(rb[i], rates[i], 1e-14);

    /* Errors. */
    FILL_SENTINEL(rb, sizeof rb);
    double lock_angles[3] = {0.1, 0.0, 0.2};
    CHECK_STATUS(mech_euler_rates_from_angular_velocity(MECH_EULER_ZYZ, lock_angles, &w, MECH_FRAME_BODY, rb),
                 MECH_STATUS_SINGULAR);
    CHECK_STATUS(mech_euler_rates_from_angular_velocity(12, eb, &w, MECH_FRAME_BODY, rb), MECH_STATUS_BAD_ENUM);
    CHECK_STATUS(mech_euler_rates_from_angular_velocity(MECH_EULER_ZYZ, eb, &w, 2, rb), MECH_STATUS_BAD_ENUM);
    CHECK_STATUS(mech_euler_rates_from_angular_velocity(MECH_EULER_ZYZ, NULL, &w, MECH_FRAME_BODY, rb),
                 MECH_STATUS_NULL_POINTER);
    CHECK_STATUS(mech_euler_rates_from_angular_velocity(MECH_EULER_ZYZ, eb, NULL, MECH_FRAME_BODY, rb),
                 MECH_STATUS_NULL_POINTER);
    CHECK_STATUS(mech_euler_rates_from_angular_velocity(MECH_EULER_ZYZ, eb, &w, MECH_FRAME_BODY, NULL),
                 MECH_STATUS_NULL_POINTER);
    mech_vec3_t wnan = {NAN, 0.0, 0.0};
    CHECK_STATUS(mech_euler_rates_from_angular_velocity(MECH_EULER_ZYZ, eb, &wnan, MECH_FRAME_BODY, rb),
                 MECH_STATUS_NON_FINITE);
    CHECK(mech_untouched(rb, sizeof rb));
    mech_vec3_t w2;
    FILL_SENTINEL(&w2, sizeof w2);
    double nan_angles[3] = {0.0, NAN, 0.0};
    CHECK_STATUS(mech_angular_velocity_from_euler_rates(MECH_EULER_XYZ, nan_angles, rates, MECH_FRAME_FIXED, &w2),
                 MECH_STATUS_NON_FINITE);
    CHECK_STATUS(mech_angular_velocity_from_euler_rates(-1, eb, rates, MECH_FRAME_FIXED, &w2), MECH_STATUS_BAD_ENUM);
    CHECK_STATUS(mech_angular_velocity_from_euler_rates(MECH_EULER_XYZ, eb, rates, 9, &w2), MECH_STATUS_BAD_ENUM);
    CHECK_STATUS(mech_angular_velocity_from_euler_rates(MECH_EULER_XYZ, eb, NULL, MECH_FRAME_FIXED, &w2),
                 MECH_STATUS_NULL_POINTER);
    CHECK_STATUS(mech_angular_velocity_from_euler_rates(MECH_EULER_XYZ, eb, rates, MECH_FRAME_FIXED, NULL),
                 MECH_STATUS_NULL_POINTER);
    CHECK(mech_untouched(&w2, sizeof w2));
    mech_mat3_t r3;
    FILL_SENTINEL(&r3, sizeof r3);
    CHECK_STATUS(mech_rotation_from_euler(99, angles, &r3), MECH_STATUS_BAD_ENUM);
    CHECK_STATUS(mech_rotation_from_euler(MECH_EULER_XYZ, NULL, &r3), MECH_STATUS_NULL_POINTER);
    CHECK_STATUS(mech_rotation_from_euler(MECH_EULER_XYZ, nan_angles, &r3), MECH_STATUS_NON_FINITE);
    CHECK_STATUS(mech_rotation_from_euler(MECH_EULER_XYZ, angles, NULL), MECH_STATUS_NULL_POINTER);
    CHECK(mech_untouched(&r3, sizeof r3));
    FILL_SENTINEL(back, sizeof back);
    FILL_SENTINEL(&lock, sizeof lock);
    FILL_SENTINEL(&dist, sizeof dist);
    mech_mat3_t refl = identity3();
    refl.m[4] = -1.0;
    CHECK_STATUS(mech_euler_from_rotation(&refl, MECH_EULER_XYZ, back, &lock, &dist), MECH_STATUS_INVALID_ARGUMENT);
    CHECK_STATUS(mech_euler_from_rotation(&r, 12, back, &lock, &dist), MECH_STATUS_BAD_ENUM);
    CHECK_STATUS(mech_euler_from_rotation(NULL, MECH_EULER_XYZ, back, &lock, &dist), MECH_STATUS_NULL_POINTER);
    CHECK_STATUS(mech_euler_from_rotation(&r, MECH_EULER_XYZ, NULL, &lock, &dist), MECH_STATUS_NULL_POINTER);
    CHECK_STATUS(mech_euler_from_rotation(&r, MECH_EULER_XYZ, back, NULL, &dist), MECH_STATUS_NULL_POINTER);
    CHECK_STATUS(mech_euler_from_rotation(&r, MECH_EULER_XYZ, back, &lock, NULL), MECH_STATUS_NULL_POINTER);
    CHECK(mech_untouched(back, sizeof back));
    CHECK(mech_untouched(&lock, sizeof lock));
    CHECK(mech_untouched(&dist, sizeof dist));
}

static void test_fields_and_relative_motion(void) {
    /* Rotating disc: Ω about z, point running outward at u along the rotating x axis. */
    const double omega = 2.5, r0 = 0.4, u = 0.7, t = 0.3;
    const double phi = omega * t, rr = r0 + u * t;
    mech_rigid_motion_t frame;
    memset(&frame, 0, sizeof frame);
    frame.rotation = rot_z(phi);
    frame.omega.z = omega;
    mech_vec3_t xi = {rr, 0.0, 0.0}, xi_dot = {u, 0.0, 0.0}, xi_ddot = {0.0, 0.0, 0.0};
    mech_relative_decomposition_t d;
    CHECK_STATUS(mech_relative_motion_decompose(&frame, &xi, &xi_dot, &xi_ddot, &d), MECH_STATUS_OK);
    /* Coriolis 2 Ω u e_φ, drag −Ω² r e_r. */
    CHECK_NEAR(d.a_coriolis.x, -2.0 * omega * u * sin(phi), 1e-14);
    CHECK_NEAR(d.a_coriolis.y, 2.0 * omega * u * cos(phi), 1e-14);
    CHECK_NEAR(d.a_drag.x, -omega * omega * rr * cos(phi), 1e-14);
    CHECK_NEAR(d.a_drag.y, -omega * omega * rr * sin(phi), 1e-14);
    CHECK_NEAR(d.v_rel.x, u * cos(phi), 1e-15);
    CHECK_NEAR(d.v_drag.y, omega * rr * cos(phi), 1e-14);

    mech_vec3_t v, a;
    CHECK_STATUS(mech_velocity_field(&frame, &d.position, &v), MECH_STATUS_OK);
    CHECK_NEAR(v.x, d.v_drag.x, 1e-15);
    CHECK_STATUS(mech_acceleration_field(&frame, &d.position, &a), MECH_STATUS_OK);
    CHECK_NEAR(a.y, d.a_drag.y, 1e-15);

    FILL_SENTINEL(&v, sizeof v);
    FILL_SENTINEL(&a, sizeof a);
    FILL_SENTINEL(&d, sizeof d);
    mech_rigid_motion_t bad = frame;
    bad.c_dot.y = NAN;
    CHECK_STATUS(mech_velocity_field(&bad, &xi, &v), MECH_STATUS_NON_FINITE);
    CHECK_STATUS(mech_acceleration_field(&bad, &xi, &a), MECH_STATUS_NON_FINITE);
    CHECK_STATUS(mech_relative_motion_decompose(&bad, &xi, &xi_dot, &xi_ddot, &d), MECH_STATUS_NON_FINITE);
    bad = frame;
    bad.rotation.m[0] = 2.0;
    CHECK_STATUS(mech_velocity_field(&bad, &xi, &v), MECH_STATUS_INVALID_ARGUMENT);
    CHECK_STATUS(mech_acceleration_field(&bad, &xi, &a), MECH_STATUS_INVALID_ARGUMENT);
    CHECK_STATUS(mech_relative_motion_decompose(&bad, &xi, &xi_dot, &xi_ddot, &d), MECH_STATUS_INVALID_ARGUMENT);
    CHECK_STATUS(mech_velocity_field(NULL, &xi, &v), MECH_STATUS_NULL_POINTER);
    CHECK_STATUS(mech_velocity_field(&frame, NULL, &v), MECH_STATUS_NULL_POINTER);
    CHECK_STATUS(mech_velocity_field(&frame, &xi, NULL), MECH_STATUS_NULL_POINTER);
    CHECK_STATUS(mech_acceleration_field(NULL, &xi, &a), MECH_STATUS_NULL_POINTER);
    CHECK_STATUS(mech_acceleration_field(&frame, NULL, &a), MECH_STATUS_NULL_POINTER);
    CHECK_STATUS(mech_acceleration_field(&frame, &xi, NULL), MECH_STATUS_NULL_POINTER);
    mech_vec3_t nanv = {0.0, 0.0, INFINITY};
    CHECK_STATUS(mech_velocity_field(&frame, &nanv, &v), MECH_STATUS_NON_FINITE);
    CHECK_STATUS(mech_relative_motion_decompose(&frame, &xi, &nanv, &xi_ddot, &d), MECH_STATUS_NON_FINITE);
    CHECK_STATUS(mech_relative_motion_decompose(NULL, &xi, &xi_dot, &xi_ddot, &d), MECH_STATUS_NULL_POINTER);
    CHECK_STATUS(mech_relative_motion_decompose(&frame, NULL, &xi_dot, &xi_ddot, &d), MECH_STATUS_NULL_POINTER);
    CHECK_STATUS(mech_relative_motion_decompose(&frame, &xi, NULL, &xi_ddot, &d), MECH_STATUS_NULL_POINTER);
    CHECK_STATUS(mech_relative_motion_decompose(&frame, &xi, &xi_dot, NULL, &d), MECH_STATUS_NULL_POINTER);
    CHECK_STATUS(mech_relative_motion_decompose(&frame, &xi, &xi_dot, &xi_ddot, NULL), MECH_STATUS_NULL_POINTER);
    CHECK(mech_untouched(&v, sizeof v));
    CHECK(mech_untouched(&a, sizeof a));
    CHECK(mech_untouched(&d, sizeof d));
}

static void test_tree(void) {
    /* Planar two-link arm: revolute z joints, links l1 = 0.7 and l2 = 0.4. */
    const double l1 = 0.7, l2 = 0.4;
    mech_tree_t *tree = NULL;
    CHECK_STATUS(mech_tree_create(&tree), MECH_STATUS_OK);
    CHECK(tree != NULL);
    mech_mat3_t id = identity3();
    mech_vec3_t origin = {0.0, 0.0, 0.0}, link = {l1, 0.0, 0.0}, z = {0.0, 0.0, 1.0};
    size_t b0 = 99, b1 = 99, tmp;
    CHECK_STATUS(mech_tree_add_body(tree, -1, MECH_JOINT_REVOLUTE, &z, &id, &origin, &b0), MECH_STATUS_OK);
    CHECK_STATUS(mech_tree_add_body(tree, (int64_t)b0, MECH_JOINT_REVOLUTE, &z, &id, &link, &b1), MECH_STATUS_OK);
    CHECK(b0 == 0 && b1 == 1);

    /* add_body errors: nothing written to body_out. */
    FILL_SENTINEL(&tmp, sizeof tmp);
    mech_vec3_t zero = {0.0, 0.0, 0.0}, nanv = {NAN, 0.0, 0.0};
    mech_mat3_t refl = identity3();
    refl.m[8] = -1.0;
    CHECK_STATUS(mech_tree_add_body(tree, 0, MECH_JOINT_REVOLUTE, &zero, &id, &origin, &tmp),
                 MECH_STATUS_INVALID_ARGUMENT);
    CHECK_STATUS(mech_tree_add_body(tree, 0, MECH_JOINT_REVOLUTE, NULL, &id, &origin, &tmp), MECH_STATUS_NULL_POINTER);
    CHECK_STATUS(mech_tree_add_body(tree, 0, MECH_JOINT_PRISMATIC, &nanv, &id, &origin, &tmp), MECH_STATUS_NON_FINITE);
    CHECK_STATUS(mech_tree_add_body(tree, 0, 6, &z, &id, &origin, &tmp), MECH_STATUS_BAD_ENUM);
    CHECK_STATUS(mech_tree_add_body(tree, -2, MECH_JOINT_FIXED, NULL, &id, &origin, &tmp),
                 MECH_STATUS_INVALID_ARGUMENT);
    CHECK_STATUS(mech_tree_add_body(tree, 0, MECH_JOINT_FIXED, NULL, &refl, &origin, &tmp),
                 MECH_STATUS_INVALID_ARGUMENT);
    CHECK_STATUS(mech_tree_add_body(tree, 0, MECH_JOINT_FIXED, NULL, &id, &nanv, &tmp), MECH_STATUS_NON_FINITE);
    CHECK_STATUS(mech_tree_add_body(tree, 0, MECH_JOINT_FIXED, NULL, NULL, &origin, &tmp), MECH_STATUS_NULL_POINTER);
    CHECK_STATUS(mech_tree_add_body(tree, 0, MECH_JOINT_FIXED, NULL, &id, NULL, &tmp), MECH_STATUS_NULL_POINTER);
    CHECK_STATUS(mech_tree_add_body(tree, 0, MECH_JOINT_FIXED, NULL, &id, &origin, NULL), MECH_STATUS_NULL_POINTER);
    CHECK_STATUS(mech_tree_add_body(NULL, 0, MECH_JOINT_FIXED, NULL, &id, &origin, &tmp), MECH_STATUS_NULL_POINTER);
    CHECK(mech_untouched(&tmp, sizeof tmp));

    /* Queries before finalize fail. */
    size_t nb, dof;
    FILL_SENTINEL(&nb, sizeof nb);
    CHECK_STATUS(mech_tree_size(tree, &nb, &dof), MECH_STATUS_INVALID_ARGUMENT);
    CHECK(mech_untouched(&nb, sizeof nb));
    CHECK_STATUS(mech_tree_finalize(tree), MECH_STATUS_OK);
    CHECK_STATUS(mech_tree_finalize(tree), MECH_STATUS_INVALID_ARGUMENT);
    CHECK_STATUS(mech_tree_add_body(tree, 0, MECH_JOINT_FIXED, NULL, &id, &origin, &tmp),
                 MECH_STATUS_INVALID_ARGUMENT);
    CHECK_STATUS(mech_tree_size(tree, &nb, &dof), MECH_STATUS_OK);
    CHECK(nb == 2 && dof == 2);
    CHECK_STATUS(mech_tree_size(NULL, &nb, &dof), MECH_STATUS_NULL_POINTER);
    CHECK_STATUS(mech_tree_size(tree, NULL, &dof), MECH_STATUS_NULL_POINTER);
    CHECK_STATUS(mech_tree_size(tree, &nb, NULL), MECH_STATUS_NULL_POINTER);

    /* Pose before any state: not ready. */
    mech_mat3_t r;
    mech_vec3_t p;
    FILL_SENTINEL(&r, sizeof r);
    FILL_SENTINEL(&p, sizeof p);
    CHECK_STATUS(mech_tree_body_pose(tree, 1, &r, &p), MECH_STATUS_INVALID_ARGUMENT);
    CHECK(mech_untouched(&r, sizeof r) && mech_untouched(&p, sizeof p));

    const double t1 = 0.3, t2 = -1.1, w1 = 0.8, w2 = 1.7, a1 = -0.4, a2 = 0.9;
    double q[2] = {t1, t2}, qd[2] = {w1, w2}, qdd[2] = {a1, a2};
    /* set_state errors. */
    CHECK_STATUS(mech_tree_set_state(tree, q, qd, 3), MECH_STATUS_BAD_DIMENSION);
    CHECK_STATUS(mech_tree_set_state(tree, NULL, qd, 2), MECH_STATUS_NULL_POINTER);
    CHECK_STATUS(mech_tree_set_state(tree, q, NULL, 2), MECH_STATUS_NULL_POINTER);
    CHECK_STATUS(mech_tree_set_state(NULL, q, qd, 2), MECH_STATUS_NULL_POINTER);
    double qnan[2] = {0.0, NAN};
    CHECK_STATUS(mech_tree_set_state(tree, qnan, qd, 2), MECH_STATUS_NON_FINITE);
    CHECK_STATUS(mech_tree_set_accelerations(tree, qdd, 2), MECH_STATUS_INVALID_ARGUMENT); /* no state yet */
    CHECK_STATUS(mech_tree_set_state(tree, q, qd, 2), MECH_STATUS_OK);

    CHECK_STATUS(mech_tree_body_pose(tree, 1, &r, &p), MECH_STATUS_OK);
    CHECK_NEAR(p.x, l1 * cos(t1), TOL);
    CHECK_NEAR(p.y, l1 * sin(t1), TOL);
    CHECK_NEAR(r.m[0], cos(t1 + t2), TOL);
    CHECK_NEAR(r.m[1], sin(t1 + t2), TOL);
    FILL_SENTINEL(&r, sizeof r);
    FILL_SENTINEL(&p, sizeof p);
    CHECK_STATUS(mech_tree_body_pose(tree, 2, &r, &p), MECH_STATUS_INVALID_ARGUMENT);
    CHECK_STATUS(mech_tree_body_pose(tree, 1, NULL, &p), MECH_STATUS_NULL_POINTER);
    CHECK_STATUS(mech_tree_body_pose(tree, 1, &r, NULL), MECH_STATUS_NULL_POINTER);
    CHECK_STATUS(mech_tree_body_pose(NULL, 1, &r, &p), MECH_STATUS_NULL_POINTER);
    CHECK(mech_untouched(&r, sizeof r) && mech_untouched(&p, sizeof p));

    mech_vec3_t tip = {l2, 0.0, 0.0}, w, v;
    const double s1 = sin(t1), c1 = cos(t1), s12 = sin(t1 + t2), c12 = cos(t1 + t2);
    CHECK_STATUS(mech_tree_body_velocity(tree, 1, &tip, &w, &v), MECH_STATUS_OK);
    CHECK_NEAR(w.z, w1 + w2, TOL);
    CHECK_NEAR(v.x, -l1 * s1 * w1 - l2 * s12 * (w1 + w2), TOL);
    CHECK_NEAR(v.y, l1 * c1 * w1 + l2 * c12 * (w1 + w2), TOL);
    FILL_SENTINEL(&w, sizeof w);
    FILL_SENTINEL(&v, sizeof v);
    CHECK_STATUS(mech_tree_body_velocity(tree, 5, &tip, &w, &v), MECH_STATUS_INVALID_ARGUMENT);
    CHECK_STATUS(mech_tree_body_velocity(tree, 1, &nanv, &w, &v), MECH_STATUS_NON_FINITE);
    CHECK_STATUS(mech_tree_body_velocity(tree, 1, NULL, &w, &v), MECH_STATUS_NULL_POINTER);
    CHECK_STATUS(mech_tree_body_velocity(tree, 1, &tip, NULL, &v), MECH_STATUS_NULL_POINTER);
    CHECK_STATUS(mech_tree_body_velocity(tree, 1, &tip, &w, NULL), MECH_STATUS_NULL_POINTER);
    CHECK_STATUS(mech_tree_body_velocity(NULL, 1, &tip, &w, &v), MECH_STATUS_NULL_POINTER);
    CHECK(mech_untouched(&w, sizeof w) && mech_untouched(&v, sizeof v));

    /* Accelerations. */
    mech_vec3_t wd, acc;
    FILL_SENTINEL(&wd, sizeof wd);
    FILL_SENTINEL(&acc, sizeof acc);
    CHECK_STATUS(mech_tree_body_acceleration(tree, 1, &tip, &wd, &acc), MECH_STATUS_INVALID_ARGUMENT);
    CHECK(mech_untouched(&wd, sizeof wd) && mech_untouched(&acc, sizeof acc));
    CHECK_STATUS(mech_tree_set_accelerations(tree, qdd, 1), MECH_STATUS_BAD_DIMENSION);
    CHECK_STATUS(mech_tree_set_accelerations(tree, NULL, 2), MECH_STATUS_NULL_POINTER);
    CHECK_STATUS(mech_tree_set_accelerations(NULL, qdd, 2), MECH_STATUS_NULL_POINTER);
    CHECK_STATUS(mech_tree_set_accelerations(tree, qnan, 2), MECH_STATUS_NON_FINITE);
    CHECK_STATUS(mech_tree_set_accelerations(tree, qdd, 2), MECH_STATUS_OK);
    CHECK_STATUS(mech_tree_body_acceleration(tree, 1, &tip, &wd, &acc), MECH_STATUS_OK);
    const double w12 = w1 + w2;
    CHECK_NEAR(wd.z, a1 + a2, TOL);
    CHECK_NEAR(acc.x, -l1 * (c1 * w1 * w1 + s1 * a1) - l2 * (c12 * w12 * w12 + s12 * (a1 + a2)), 1e-14);
    CHECK_NEAR(acc.y, l1 * (-s1 * w1 * w1 + c1 * a1) + l2 * (-s12 * w12 * w12 + c12 * (a1 + a2)), 1e-14);
    FILL_SENTINEL(&wd, sizeof wd);
    FILL_SENTINEL(&acc, sizeof acc);
    CHECK_STATUS(mech_tree_body_acceleration(tree, 9, &tip, &wd, &acc), MECH_STATUS_INVALID_ARGUMENT);
    CHECK_STATUS(mech_tree_body_acceleration(tree, 1, NULL, &wd, &acc), MECH_STATUS_NULL_POINTER);
    CHECK_STATUS(mech_tree_body_acceleration(tree, 1, &tip, NULL, &acc), MECH_STATUS_NULL_POINTER);
    CHECK_STATUS(mech_tree_body_acceleration(tree, 1, &tip, &wd, NULL), MECH_STATUS_NULL_POINTER);
    CHECK_STATUS(mech_tree_body_acceleration(NULL, 1, &tip, &wd, &acc), MECH_STATUS_NULL_POINTER);
    CHECK(mech_untouched(&wd, sizeof wd) && mech_untouched(&acc, sizeof acc));

    /* Jacobians: closed forms. */
    double j[6], big[8];
    CHECK_STATUS(mech_tree_jacobian(tree, 1, MECH_JACOBIAN_POINT, &tip, j, 6), MECH_STATUS_OK);
    CHECK_NEAR(j[0], -l1 * s1 - l2 * s12, TOL);
    CHECK_NEAR(j[1], l1 * c1 + l2 * c12, TOL);
    CHECK_NEAR(j[3], -l2 * s12, TOL);
    CHECK_NEAR(j[4], l2 * c12, TOL);
    CHECK_STATUS(mech_tree_jacobian(tree, 0, MECH_JACOBIAN_ANGULAR, NULL, j, 6), MECH_STATUS_OK);
    CHECK(j[2] == 1.0 && j[5] == 0.0);
    /* J̇: d/dt of column 2 of the tip = −l2 (c12, s12) (w1 + w2). */
    FILL_SENTINEL(big, sizeof big);
    CHECK_STATUS(mech_tree_jacobian(tree, 1, MECH_JACOBIAN_POINT_RATE, &tip, big, 8), MECH_STATUS_OK);
    CHECK_NEAR(big[3], -l2 * c12 * w12, TOL);
    CHECK_NEAR(big[4], -l2 * s12 * w12, TOL);
    CHECK(mech_untouched(big + 6, 2 * sizeof(double))); /* only 3·dof written */
    CHECK_STATUS(mech_tree_jacobian(tree, 1, MECH_JACOBIAN_ANGULAR_RATE, NULL, j, 6), MECH_STATUS_OK);
    CHECK(j[2] == 0.0 && j[5] == 0.0); /* planar: axes do not turn */
    FILL_SENTINEL(j, sizeof j);
    CHECK_STATUS(mech_tree_jacobian(tree, 1, MECH_JACOBIAN_POINT, &tip, j, 5), MECH_STATUS_BUFFER_TOO_SMALL);
    CHECK_STATUS(mech_tree_jacobian(tree, 1, 4, &tip, j, 6), MECH_STATUS_BAD_ENUM);
    CHECK_STATUS(mech_tree_jacobian(tree, 1, MECH_JACOBIAN_POINT, NULL, j, 6), MECH_STATUS_NULL_POINTER);
    CHECK_STATUS(mech_tree_jacobian(tree, 1, MECH_JACOBIAN_POINT, &nanv, j, 6), MECH_STATUS_NON_FINITE);
    CHECK_STATUS(mech_tree_jacobian(tree, 1, MECH_JACOBIAN_POINT, &tip, NULL, 6), MECH_STATUS_NULL_POINTER);
    CHECK_STATUS(mech_tree_jacobian(tree, 7, MECH_JACOBIAN_POINT, &tip, j, 6), MECH_STATUS_INVALID_ARGUMENT);
    CHECK_STATUS(mech_tree_jacobian(NULL, 1, MECH_JACOBIAN_POINT, &tip, j, 6), MECH_STATUS_NULL_POINTER);
    CHECK(mech_untouched(j, sizeof j));
    mech_tree_destroy(tree);
    mech_tree_destroy(NULL);

    /* Structural errors at finalize: cycle, two roots, no bodies, non-unit axis. */
    CHECK_STATUS(mech_tree_create(&tree), MECH_STATUS_OK);
    CHECK_STATUS(mech_tree_finalize(tree), MECH_STATUS_INVALID_ARGUMENT); /* empty */
    mech_tree_destroy(tree);
    CHECK_STATUS(mech_tree_create(&tree), MECH_STATUS_OK);
    CHECK_STATUS(mech_tree_add_body(tree, -1, MECH_JOINT_FREE, NULL, &id, &origin, &tmp), MECH_STATUS_OK);
    CHECK_STATUS(mech_tree_add_body(tree, 2, MECH_JOINT_SPHERICAL, NULL, &id, &origin, &tmp), MECH_STATUS_OK);
    CHECK_STATUS(mech_tree_add_body(tree, 1, MECH_JOINT_PLANAR, NULL, &id, &origin, &tmp), MECH_STATUS_OK);
    CHECK_STATUS(mech_tree_finalize(tree), MECH_STATUS_INVALID_ARGUMENT); /* 1 ↔ 2 cycle */
    char msg[256];
    mech_last_error(msg, sizeof msg);
    CHECK(strstr(msg, "cycle") != NULL);
    mech_tree_destroy(tree);
    CHECK_STATUS(mech_tree_create(&tree), MECH_STATUS_OK);
    CHECK_STATUS(mech_tree_add_body(tree, -1, MECH_JOINT_FIXED, NULL, &id, &origin, &tmp), MECH_STATUS_OK);
    CHECK_STATUS(mech_tree_add_body(tree, -1, MECH_JOINT_FIXED, NULL, &id, &origin, &tmp), MECH_STATUS_OK);
    CHECK_STATUS(mech_tree_finalize(tree), MECH_STATUS_INVALID_ARGUMENT); /* two roots */
    mech_tree_destroy(tree);
    CHECK_STATUS(mech_tree_create(&tree), MECH_STATUS_OK);
    CHECK_STATUS(mech_tree_add_body(tree, 4, MECH_JOINT_FIXED, NULL, &id, &origin, &tmp), MECH_STATUS_OK);
    CHECK_STATUS(mech_tree_finalize(tree), MECH_STATUS_INVALID_ARGUMENT); /* no root / parent out of range */
    mech_tree_destroy(tree);
    /* A tree without coordinates accepts n = 0 and NULL arrays. */
    CHECK_STATUS(mech_tree_create(&tree), MECH_STATUS_OK);
    CHECK_STATUS(mech_tree_add_body(tree, -1, MECH_JOINT_FIXED, NULL, &id, &link, &tmp), MECH_STATUS_OK);
    CHECK_STATUS(mech_tree_finalize(tree), MECH_STATUS_OK);
    CHECK_STATUS(mech_tree_set_state(tree, NULL, NULL, 0), MECH_STATUS_OK);
    CHECK_STATUS(mech_tree_body_pose(tree, 0, &r, &p), MECH_STATUS_OK);
    CHECK(p.x == l1);
    mech_tree_destroy(tree);
    FILL_SENTINEL(&tree, sizeof tree);
    CHECK_STATUS(mech_tree_create(NULL), MECH_STATUS_NULL_POINTER);
}

/* Extreme inputs: huge angles reduced exactly, rotation vectors beyond 2^53 refused, results
 * that overflow reported as MECH_STATUS_OUT_OF_RANGE. */
static void test_extreme_inputs(void) {
    mech_mat3_t r;
    /* sin and cos of the double 1e308, computed with mpmath at 1200 bits. */
    mech_vec3_t z = {0, 0, 1};
    CHECK_STATUS(mech_rotation_from_axis_angle(&z, 1e308, &r), MECH_STATUS_OK);
    CHECK_NEAR(r.m[0], -0.8913089376870335, 4 * 2.2e-16);
    CHECK_NEAR(r.m[1], 0.4533964905016491, 4 * 2.2e-16);
    CHECK_NEAR(r.m[3], -0.4533964905016491, 4 * 2.2e-16);
    CHECK(r.m[8] == 1.0);
    /* A rotation vector of 1e308 components: |phi| = 1.7e308, refused, nothing written. */
    mech_vec3_t phi = {1e308, 1e308, 1e308};
    FILL_SENTINEL(&r, sizeof r);
    CHECK_STATUS(mech_rotation_exp(&phi, &r), MECH_STATUS_INVALID_ARGUMENT);
    CHECK(mech_untouched(&r, sizeof r));
    /* Tiny rotation vectors: the identity plus [phi]x to rounding. */
    mech_vec3_t small = {3e-300, -4e-300, 0};
    CHECK_STATUS(mech_rotation_exp(&small, &r), MECH_STATUS_OK);
    CHECK(r.m[0] == 1.0 && r.m[4] == 1.0 && r.m[8] == 1.0);
    CHECK_NEAR(r.m[2], 4e-300, 1e-315); /* R(2,0) = -phi_y */
    /* A velocity field whose value overflows: omega x (x - c) = 1e308 * 1e308. */
    mech_rigid_motion_t m;
    memset(&m, 0, sizeof m);
    m.rotation = identity3();
    m.omega.z = 1e308;
    mech_vec3_t x = {1e308, 0, 0};
    mech_vec3_t v;
    FILL_SENTINEL(&v, sizeof v);
    CHECK_STATUS(mech_velocity_field(&m, &x, &v), MECH_STATUS_OUT_OF_RANGE);
    CHECK(mech_untouched(&v, sizeof v));
}

int main(void) {
    test_existing_and_exp_log();
    test_extreme_inputs();
    test_axis_angle_and_orthonormalize();
    test_euler();
    test_fields_and_relative_motion();
    test_tree();
    return CHECK_DONE();
}
