/* C11 test of the impulse-dynamics entry points: closed-form results and every error path,
 * checking with sentinels that nothing is written on failure. */
#include "check.h"

static mech_vec3_t v3(double x, double y, double z) {
    mech_vec3_t v = {x, y, z};
    return v;
}

static mech_mat3_t diag3(double a, double b, double c) {
    mech_mat3_t m;
    memset(&m, 0, sizeof m);
    m.m[0] = a;
    m.m[4] = b;
    m.m[8] = c;
    return m;
}

/* A free sphere (mass m, radius r) in inverse form. */
static mech_impulse_body_t sphere(double m, double r, mech_vec3_t c, mech_vec3_t v, mech_vec3_t w) {
    mech_impulse_body_t b;
    memset(&b, 0, sizeof b);
    double j = 0.4 * m * r * r;
    b.inverse_mass = 1.0 / m;
    b.inverse_inertia = diag3(1.0 / j, 1.0 / j, 1.0 / j);
    b.center_of_mass = c;
    b.velocity = v;
    b.angular_velocity = w;
    b.constraint = MECH_BODY_FREE;
    return b;
}

static mech_impulse_body_t ground(void) {
    mech_impulse_body_t b;
    memset(&b, 0, sizeof b);
    b.constraint = MECH_BODY_FREE;
    return b;
}

static void test_points(void) {
    mech_point_impulse_t pi;
    mech_vec3_t v = v3(1.0, -2.0, 0.5), s = v3(0.4, 1.0, -3.0);
    CHECK_STATUS(mech_impulse_on_point(2.0, &v, &s, &pi), MECH_STATUS_OK);
    CHECK_NEAR(pi.velocity_after.x, 1.2, 1e-15);
    CHECK_NEAR(pi.velocity_after.z, -1.0, 1e-15);
    /* ½ m (|V|² − |v|²) */
    double dt = 0.5 * 2.0 * ((1.2 * 1.2 + 1.5 * 1.5 + 1.0) - (1.0 + 4.0 + 0.25));
    CHECK_NEAR(pi.energy_change, dt, 1e-14);

    FILL_SENTINEL(&pi, sizeof pi);
    CHECK_STATUS(mech_impulse_on_point(-1.0, &v, &s, &pi), MECH_STATUS_INVALID_ARGUMENT);
    CHECK_STATUS(mech_impulse_on_point(NAN, &v, &s, &pi), MECH_STATUS_NON_FINITE);
    CHECK_STATUS(mech_impulse_on_point(1.0, NULL, &s, &pi), MECH_STATUS_NULL_POINTER);
    CHECK_STATUS(mech_impulse_on_point(1.0, &v, NULL, &pi), MECH_STATUS_NULL_POINTER);
    CHECK(mech_untouched(&pi, sizeof pi));
    CHECK_STATUS(mech_impulse_on_point(1.0, &v, &s, NULL), MECH_STATUS_NULL_POINTER);

    /* Oblique elastic billiard balls: they leave at right angles. */
    mech_point_impact_t pc;
    double h = sqrt(0.5);
    mech_vec3_t n = v3(h, h, 0.0), a = v3(2.0, 0.0, 0.0), zero = v3(0, 0, 0);
    CHECK_STATUS(mech_collide_points(0.17, &a, 0.17, &zero, &n, 1.0, &pc), MECH_STATUS_OK);
    CHECK_NEAR(pc.velocity_after_1.x * pc.velocity_after_2.x + pc.velocity_after_1.y * pc.velocity_after_2.y, 0.0,
               1e-15);
    CHECK_NEAR(pc.velocity_after_2.x, 1.0, 1e-15);
    CHECK_NEAR(pc.energy_change, 0.0, 1e-15);

    FILL_SENTINEL(&pc, sizeof pc);
    mech_vec3_t bad = v3(2.0, 0.0, 0.0);
    CHECK_STATUS(mech_collide_points(0.17, &a, 0.17, &zero, &bad, 1.0, &pc), MECH_STATUS_INVALID_ARGUMENT);
    CHECK_STATUS(mech_collide_points(0.17, &a, 0.17, &zero, &n, 1.5, &pc), MECH_STATUS_INVALID_ARGUMENT);
    mech_vec3_t inf = v3(INFINITY, 0.0, 0.0);
    CHECK_STATUS(mech_collide_points(0.17, &inf, 0.17, &zero, &n, 1.0, &pc), MECH_STATUS_NON_FINITE);
    CHECK_STATUS(mech_collide_points(0.17, &a, 0.17, &zero, NULL, 1.0, &pc), MECH_STATUS_NULL_POINTER);
    CHECK(mech_untouched(&pc, sizeof pc));

    mech_collinear_impact_t ci;
    CHECK_STATUS(mech_collide_collinear(1.0, 1.0, 1.0, 0.0, 1.0, &ci), MECH_STATUS_OK);
    CHECK_NEAR(ci.v2_after, 1.0, 1e-15);
}

static void test_bodies(void) {
    /* A rod (mass 2.5, length 1.6) along x through the mass-properties path: pseudo-inverse. */
    double m = 2.5, l = 1.6, v = 3.0;
    mech_mass_properties_t props;
    memset(&props, 0, sizeof props);
    props.mass = m;
    props.inertia_about_com = diag3(0.0, m * l * l / 12.0, m * l * l / 12.0);
    mech_vec3_t vel = v3(0.0, v, 0.0), zero = v3(0, 0, 0);
    mech_impulse_body_t rod;
    CHECK_STATUS(mech_impulse_body_from_mass_properties(&props, &vel, &zero, &rod), MECH_STATUS_OK);
    CHECK_NEAR(rod.inverse_mass, 1.0 / m, 1e-15);
    CHECK_NEAR(rod.inverse_inertia.m[0], 0.0, 0.0);
    CHECK_NEAR(rod.inverse_inertia.m[8], 12.0 / (m * l * l), 1e-13);

    /* Fixation of the end of the translating rod: Ω = 3v/(2L), T⁺/T⁻ = 3/4. */
    mech_fixation_t fx;
    mech_vec3_t end = v3(-l / 2.0, 0.0, 0.0);
    CHECK_STATUS(mech_impulse_fix_point(&rod, &end, &fx), MECH_STATUS_OK);
    CHECK_NEAR(fx.angular_velocity_after.z, 3.0 * v / (2.0 * l), 1e-13);
    CHECK_NEAR(fx.energy_change, -0.25 * 0.5 * m * v * v, 1e-12);
    CHECK_NEAR(fx.impulse.y, -m * v / 4.0, 1e-13);

    /* An impulse at the rod end: ΔV = S/m, ΔΩ = 6S/(mL). */
    mech_body_response_t br;
    mech_vec3_t s = v3(0.0, 1.5, 0.0), tip = v3(l / 2.0, 0.0, 0.0);
    CHECK_STATUS(mech_impulse_apply(&rod, &s, &tip, &zero, &br), MECH_STATUS_OK);
    CHECK_NEAR(br.velocity_after.y, v + 1.5 / m, 1e-14);
    CHECK_NEAR(br.angular_velocity_after.z, 6.0 * 1.5 / (m * l), 1e-13);

    /* Hinged at the end about z, at rest: the same impulse gives ΔΩ = 3S/(mL). */
    mech_impulse_body_t pendulum = rod;
    pendulum.velocity = zero;
    pendulum.constraint = MECH_BODY_HINGE_AXIS;
    pendulum.hinge_point = end;
    pendulum.hinge_axis = v3(0.0, 0.0, 1.0);
    CHECK_STATUS(mech_impulse_apply(&pendulum, &s, &tip, &zero, &br), MECH_STATUS_OK);
    CHECK_NEAR(br.angular_velocity_after.z, 3.0 * 1.5 / (m * l), 1e-13);
    pendulum.constraint = MECH_BODY_HINGE_POINT;
    CHECK_STATUS(mech_impulse_apply(&pendulum, &s, &tip, &zero, &br), MECH_STATUS_OK);
    CHECK_NEAR(br.angular_velocity_after.z, 3.0 * 1.5 / (m * l), 1e-13);

    /* Error paths. */
    FILL_SENTINEL(&br, sizeof br);
    mech_impulse_body_t bad = rod;
    bad.constraint = 7;
    CHECK_STATUS(mech_impulse_apply(&bad, &s, &tip, &zero, &br), MECH_STATUS_BAD_ENUM);
    bad = rod;
    bad.inverse_mass = -1.0;
    CHECK_STATUS(mech_impulse_apply(&bad, &s, &tip, &zero, &br), MECH_STATUS_INVALID_ARGUMENT);
    bad = rod;
    bad.inverse_inertia.m[4] = -1.0;
    CHECK_STATUS(mech_impulse_apply(&bad, &s, &tip, &zero, &br), MECH_STATUS_NOT_POSITIVE_DEFINITE);
    bad = rod;
    bad.velocity.x = NAN;
    CHECK_STATUS(mech_impulse_apply(&bad, &s, &tip, &zero, &br), MECH_STATUS_NON_FINITE);
    bad = pendulum;
    bad.constraint = MECH_BODY_HINGE_AXIS;
    bad.hinge_axis = v3(0.0, 0.0, 3.0);
    CHECK_STATUS(mech_impulse_apply(&bad, &s, &tip, &zero, &br), MECH_STATUS_INVALID_ARGUMENT);
    bad = rod; /* moving rod, hinge at a moving point */
    bad.constraint = MECH_BODY_HINGE_POINT;
    bad.hinge_point = end;
    CHECK_STATUS(mech_impulse_apply(&bad, &s, &tip, &zero, &br), MECH_STATUS_INVALID_ARGUMENT);
    CHECK_STATUS(mech_impulse_apply(NULL, &s, &tip, &zero, &br), MECH_STATUS_NULL_POINTER);
    CHECK_STATUS(mech_impulse_apply(&rod, &s, &tip, NULL, &br), MECH_STATUS_NULL_POINTER);
    CHECK(mech_untouched(&br, sizeof br));
    CHECK_STATUS(mech_impulse_apply(&rod, &s, &tip, &zero, NULL), MECH_STATUS_NULL_POINTER);

    mech_impulse_body_t out_body;
    FILL_SENTINEL(&out_body, sizeof out_body);
    props.mass = -2.0;
    CHECK_STATUS(mech_impulse_body_from_mass_properties(&props, &vel, &zero, &out_body), MECH_STATUS_INVALID_ARGUMENT);
    props.mass = m;
    props.inertia_about_com.m[3] = 5.0; /* asymmetric */
    CHECK_STATUS(mech_impulse_body_from_mass_properties(&props, &vel, &zero, &out_body),
                 MECH_STATUS_NOT_POSITIVE_DEFINITE);
    props.inertia_about_com.m[3] = NAN;
    CHECK_STATUS(mech_impulse_body_from_mass_properties(&props, &vel, &zero, &out_body), MECH_STATUS_NON_FINITE);
    CHECK_STATUS(mech_impulse_body_from_mass_properties(NULL, &vel, &zero, &out_body), MECH_STATUS_NULL_POINTER);
    CHECK(mech_untouched(&out_body, sizeof out_body));

    FILL_SENTINEL(&fx, sizeof fx);
    mech_impulse_body_t moving_wall = ground();
    moving_wall.velocity = v3(1.0, 0.0, 0.0);
    CHECK_STATUS(mech_impulse_fix_point(&moving_wall, &zero, &fx), MECH_STATUS_SINGULAR);
    mech_vec3_t nan_point = v3(NAN, 0.0, 0.0);
    CHECK_STATUS(mech_impulse_fix_point(&rod, &nan_point, &fx), MECH_STATUS_NON_FINITE);
    CHECK_STATUS(mech_impulse_fix_point(&rod, NULL, &fx), MECH_STATUS_NULL_POINTER);
    CHECK(mech_untouched(&fx, sizeof fx));
}

static void test_contacts(void) {
    /* A spinning sphere hits the ground and ends up rolling (sticking case):
     * p = (1 + e) m v_y, P_x = −(2m/7)(v_x + R ω_z). */
    double m = 2.0, r = 0.1, e = 0.6, vx = 1.0, vy = 3.0, wz = 25.0;
    mech_impulse_body_t ball = sphere(m, r, v3(0.0, r, 0.0), v3(vx, -vy, 0.0), v3(0.0, 0.0, wz));
    mech_impulse_body_t g = ground();
    mech_impulse_contact_t c;
    memset(&c, 0, sizeof c);
    c.point = v3(0, 0, 0);
    c.normal = v3(0.0, 1.0, 0.0);
    c.restitution = e;
    c.friction = 0.6;
    c.law = MECH_RESTITUTION_STRONGE;
    c.tolerance = 1e-10;
    mech_impact_result_t res;
    CHECK_STATUS(mech_impulse_resolve_contact(&g, &ball, &c, &res), MECH_STATUS_OK);
    CHECK_NEAR(res.normal_impulse, (1.0 + e) * m * vy, 1e-12);
    CHECK_NEAR(res.impulse.x, -2.0 * m * (vx + r * wz) / 7.0, 1e-12);
    CHECK(res.mode == MECH_CONTACT_SLIP_THEN_STICK);
    CHECK_NEAR(res.velocity_after_2.x + r * res.angular_velocity_after_2.z, 0.0, 1e-12);
    CHECK(res.energy_change < 0.0);
    /* Closed-form segments report only their rounding: a few ulps of the impulse. */
    CHECK(res.integration_error > 0.0 && res.integration_error <= 64 * 2.2e-16 * res.normal_impulse);

    /* Sliding case and the other laws (decoupled W: all laws agree). */
    c.friction = 0.1;
    int laws[3] = {MECH_RESTITUTION_NEWTON, MECH_RESTITUTION_POISSON, MECH_RESTITUTION_STRONGE};
    for (int k = 0; k < 3; ++k) {
        c.law = laws[k];
        CHECK_STATUS(mech_impulse_resolve_contact(&g, &ball, &c, &res), MECH_STATUS_OK);
        CHECK(res.mode == MECH_CONTACT_SLIP);
        CHECK_NEAR(res.impulse.x, -0.1 * (1.0 + e) * m * vy, 1e-12);
    }
    /* Infinite friction: no slip after the impact. */
    c.friction = INFINITY;
    CHECK_STATUS(mech_impulse_resolve_contact(&g, &ball, &c, &res), MECH_STATUS_OK);
    CHECK(res.mode == MECH_CONTACT_STICK);
    CHECK_NEAR(res.relative_velocity_after.x, 0.0, 1e-12);
    /* Separating: no impulse. */
    c.friction = 0.5;
    mech_impulse_body_t up = ball;
    up.velocity.y = 1.0;
    CHECK_STATUS(mech_impulse_resolve_contact(&g, &up, &c, &res), MECH_STATUS_OK);
    CHECK(res.mode == MECH_CONTACT_NO_IMPACT);
    CHECK(res.normal_impulse == 0.0);

    /* Error paths: nothing written. */
    FILL_SENTINEL(&res, sizeof res);
    mech_impulse_contact_t bad = c;
    bad.law = 3;
    CHECK_STATUS(mech_impulse_resolve_contact(&g, &ball, &bad, &res), MECH_STATUS_BAD_ENUM);
    bad = c;
    bad.law = -1;
    CHECK_STATUS(mech_impulse_resolve_contact(&g, &ball, &bad, &res), MECH_STATUS_BAD_ENUM);
    bad = c;
    bad.restitution = 1.5;
    CHECK_STATUS(mech_impulse_resolve_contact(&g, &ball, &bad, &res), MECH_STATUS_INVALID_ARGUMENT);
    bad = c;
    bad.friction = -0.1;
    CHECK_STATUS(mech_impulse_resolve_contact(&g, &ball, &bad, &res), MECH_STATUS_INVALID_ARGUMENT);
    bad = c;
    bad.friction = NAN;
    CHECK_STATUS(mech_impulse_resolve_contact(&g, &ball, &bad, &res), MECH_STATUS_NON_FINITE);
    bad = c;
    bad.normal = v3(0.0, 0.0, 0.0);
    CHECK_STATUS(mech_impulse_resolve_contact(&g, &ball, &bad, &res), MECH_STATUS_INVALID_ARGUMENT);
    bad = c;
    bad.normal = v3(0.0, 1.01, 0.0);
    CHECK_STATUS(mech_impulse_resolve_contact(&g, &ball, &bad, &res), MECH_STATUS_INVALID_ARGUMENT);
    bad = c;
    bad.point.x = INFINITY;
    CHECK_STATUS(mech_impulse_resolve_contact(&g, &ball, &bad, &res), MECH_STATUS_NON_FINITE);
    bad = c;
    bad.tolerance = 0.0;
    CHECK_STATUS(mech_impulse_resolve_contact(&g, &ball, &bad, &res), MECH_STATUS_INVALID_ARGUMENT);
    bad.tolerance = 0.5; /* would count a slip at half the approach speed as halted */
    CHECK_STATUS(mech_impulse_resolve_contact(&g, &ball, &bad, &res), MECH_STATUS_INVALID_ARGUMENT);
    /* Two immovable bodies approaching. */
    mech_impulse_body_t wall = ground();
    wall.velocity = v3(0.0, -1.0, 0.0);
    CHECK_STATUS(mech_impulse_resolve_contact(&g, &wall, &c, &res), MECH_STATUS_SINGULAR);
    CHECK_STATUS(mech_impulse_resolve_contact(NULL, &ball, &c, &res), MECH_STATUS_NULL_POINTER);
    CHECK_STATUS(mech_impulse_resolve_contact(&g, NULL, &c, &res), MECH_STATUS_NULL_POINTER);
    CHECK_STATUS(mech_impulse_resolve_contact(&g, &ball, NULL, &res), MECH_STATUS_NULL_POINTER);
    CHECK(mech_untouched(&res, sizeof res));
    CHECK_STATUS(mech_impulse_resolve_contact(&g, &ball, &c, NULL), MECH_STATUS_NULL_POINTER);
}

/* A pendulum: one body on a revolute joint about z at the origin, bob of mass m at (0, −L, 0)
 * with central inertia ic about z. I_z = ic + m L². At θ = 0, rate ω, the bob moves along +x. */
static mech_tree_t *pendulum_tree(double omega) {
    mech_tree_t *tree = NULL;
    CHECK_STATUS(mech_tree_create(&tree), MECH_STATUS_OK);
    mech_vec3_t z = v3(0.0, 0.0, 1.0), origin = v3(0.0, 0.0, 0.0);
    mech_mat3_t id = diag3(1.0, 1.0, 1.0);
    size_t b0 = 99;
    CHECK_STATUS(mech_tree_add_body(tree, -1, MECH_JOINT_REVOLUTE, &z, &id, &origin, &b0), MECH_STATUS_OK);
    CHECK(b0 == 0);
    CHECK_STATUS(mech_tree_finalize(tree), MECH_STATUS_OK);
    double q = 0.0;
    CHECK_STATUS(mech_tree_set_state(tree, &q, &omega, 1), MECH_STATUS_OK);
    return tree;
}

static void test_mechanisms(void) {
    const double m = 2.0, l = 0.8, ic = 0.05, omega = 1.5, e = 0.5;
    const double iz = ic + m * l * l;
    mech_mass_properties_t bob;
    memset(&bob, 0, sizeof bob);
    bob.mass = m;
    bob.center_of_mass = v3(0.0, -l, 0.0);
    bob.inertia_about_com = diag3(ic, ic, ic);
    mech_tree_t *tree = pendulum_tree(omega);

    /* Lagrange's impulse equation: a horizontal impulse s at the bob gives Δθ̇ = L s / I_z. */
    mech_mechanism_impulse_t hit;
    memset(&hit, 0, sizeof hit);
    hit.body = 0;
    hit.point = v3(0.0, -l, 0.0);
    hit.impulse = v3(0.3, 0.0, 0.0);
    double dq = 0.0;
    mech_mechanism_response_t resp;
    CHECK_STATUS(mech_impulse_mechanism_apply(tree, &bob, 1, &hit, 1, &dq, 1, &resp), MECH_STATUS_OK);
    CHECK_NEAR(dq, l * 0.3 / iz, 1e-14);
    CHECK_NEAR(resp.energy_before, 0.5 * iz * omega * omega, 1e-14);
    CHECK_NEAR(resp.energy_change, 0.5 * iz * ((omega + dq) * (omega + dq) - omega * omega), 1e-13);
    CHECK(resp.backward_error <= 1e-15);

    /* The bob hits a smooth wall (normal −x): θ̇⁺ = −e ω, P = (1 + e) ω I_z / L, ΔT = −½(1 − e²) I_z ω². */
    mech_mechanism_contact_t wall;
    memset(&wall, 0, sizeof wall);
    wall.body = 0;
    wall.point = v3(0.0, -l, 0.0);
    wall.other_body = -1;
    wall.normal = v3(-1.0, 0.0, 0.0);
    wall.restitution = e;
    wall.friction = 0.0;
    wall.law = MECH_RESTITUTION_STRONGE;
    mech_mechanism_contact_result_t res[2];
    mech_mechanism_impact_t imp;
    CHECK_STATUS(mech_impulse_mechanism_contacts(tree, &bob, 1, &wall, 1, NULL, res, &dq, 1, &imp), MECH_STATUS_OK);
    CHECK_NEAR(dq, -(1.0 + e) * omega, 1e-13);
    CHECK_NEAR(res[0].normal_impulse, (1.0 + e) * omega * iz / l, 1e-12);
    CHECK_NEAR(res[0].impulse.x, -(1.0 + e) * omega * iz / l, 1e-12);
    CHECK_NEAR(res[0].relative_velocity_before.x, omega * l, 1e-14);
    CHECK_NEAR(res[0].relative_velocity_after.x, -e * omega * l, 1e-13);
    CHECK(res[0].mode == MECH_CONTACT_FRICTIONLESS);
    CHECK_NEAR(imp.energy_change, -0.5 * (1.0 - e * e) * iz * omega * omega, 1e-12);
    CHECK(imp.simultaneous == 0 && imp.converged == 1 && imp.delassus_rank == 1);

    /* The same contact twice, rough: the simultaneous model, rank 1 of 6, the same Δθ̇. */
    mech_mechanism_contact_t two[2] = {wall, wall};
    two[0].friction = 0.4;
    two[1].friction = 0.4;
    mech_multi_contact_options_t opts = {1e-12, 1000, 1e-10};
    CHECK_STATUS(mech_impulse_mechanism_contacts(tree, &bob, 1, two, 2, &opts, res, &dq, 1, &imp), MECH_STATUS_OK);
    CHECK(imp.simultaneous == 1 && imp.converged == 1 && imp.delassus_rank == 1);
    CHECK_NEAR(dq, -(1.0 + e) * omega, 1e-10);
    CHECK_NEAR(res[0].normal_impulse + res[1].normal_impulse, (1.0 + e) * omega * iz / l, 1e-10);
    CHECK(imp.energy_change <= 0.0);
    CHECK(imp.complementarity_residual <= 1e-12 * omega * l);

    /* The Delassus matrix: W_nn = L² / I_z, the frame's third column is the normal. */
    double w[36];
    mech_mat3_t frames[2];
    size_t rank = 0;
    CHECK_STATUS(mech_impulse_mechanism_delassus(tree, &bob, 1, two, 2, w, 6, frames, &rank), MECH_STATUS_OK);
    CHECK_NEAR(w[2 + 6 * 2], l * l / iz, 1e-14);
    CHECK_NEAR(w[5 + 6 * 2], l * l / iz, 1e-14);
    CHECK_NEAR(frames[1].m[6], -1.0, 0.0);
    CHECK(rank == 1);

    /* Error paths: nothing written. */
    FILL_SENTINEL(res, sizeof res);
    FILL_SENTINEL(&imp, sizeof imp);
    FILL_SENTINEL(&dq, sizeof dq);
    FILL_SENTINEL(&resp, sizeof resp);
    FILL_SENTINEL(w, sizeof w);
    CHECK_STATUS(mech_impulse_mechanism_contacts(NULL, &bob, 1, &wall, 1, NULL, res, &dq, 1, &imp),
                 MECH_STATUS_NULL_POINTER);
    CHECK_STATUS(mech_impulse_mechanism_contacts(tree, NULL, 1, &wall, 1, NULL, res, &dq, 1, &imp),
                 MECH_STATUS_NULL_POINTER);
    CHECK_STATUS(mech_impulse_mechanism_contacts(tree, &bob, 1, NULL, 1, NULL, res, &dq, 1, &imp),
                 MECH_STATUS_NULL_POINTER);
    CHECK_STATUS(mech_impulse_mechanism_contacts(tree, &bob, 1, &wall, 1, NULL, NULL, &dq, 1, &imp),
                 MECH_STATUS_NULL_POINTER);
    CHECK_STATUS(mech_impulse_mechanism_contacts(tree, &bob, 1, &wall, 1, NULL, res, NULL, 1, &imp),
                 MECH_STATUS_NULL_POINTER);
    CHECK_STATUS(mech_impulse_mechanism_contacts(tree, &bob, 2, &wall, 1, NULL, res, &dq, 1, &imp),
                 MECH_STATUS_BAD_DIMENSION);
    CHECK_STATUS(mech_impulse_mechanism_contacts(tree, &bob, 1, &wall, 1, NULL, res, &dq, 2, &imp),
                 MECH_STATUS_BAD_DIMENSION);
    mech_mass_properties_t bad_bob = bob;
    bad_bob.mass = NAN;
    CHECK_STATUS(mech_impulse_mechanism_contacts(tree, &bad_bob, 1, &wall, 1, NULL, res, &dq, 1, &imp),
                 MECH_STATUS_NON_FINITE);
    /* A point mass on the joint axis: A = 0, not positive definite. */
    bad_bob = bob;
    bad_bob.center_of_mass = v3(0.0, 0.0, 0.0);
    bad_bob.inertia_about_com = diag3(0.0, 0.0, 0.0);
    CHECK_STATUS(mech_impulse_mechanism_contacts(tree, &bad_bob, 1, &wall, 1, NULL, res, &dq, 1, &imp),
                 MECH_STATUS_NOT_POSITIVE_DEFINITE);
    CHECK_STATUS(mech_impulse_mechanism_apply(tree, &bad_bob, 1, &hit, 1, &dq, 1, &resp),
                 MECH_STATUS_NOT_POSITIVE_DEFINITE);
    mech_mechanism_contact_t bad = wall;
    bad.body = 3;
    CHECK_STATUS(mech_impulse_mechanism_contacts(tree, &bob, 1, &bad, 1, NULL, res, &dq, 1, &imp),
                 MECH_STATUS_INVALID_ARGUMENT);
    bad = wall;
    bad.normal = v3(-2.0, 0.0, 0.0);
    CHECK_STATUS(mech_impulse_mechanism_contacts(tree, &bob, 1, &bad, 1, NULL, res, &dq, 1, &imp),
                 MECH_STATUS_INVALID_ARGUMENT);
    bad = wall;
    bad.normal.y = NAN;
    CHECK_STATUS(mech_impulse_mechanism_contacts(tree, &bob, 1, &bad, 1, NULL, res, &dq, 1, &imp),
                 MECH_STATUS_NON_FINITE);
    bad = wall;
    bad.law = 9;
    CHECK_STATUS(mech_impulse_mechanism_contacts(tree, &bob, 1, &bad, 1, NULL, res, &dq, 1, &imp),
                 MECH_STATUS_BAD_ENUM);
    bad = wall;
    bad.restitution = 1.5;
    CHECK_STATUS(mech_impulse_mechanism_contacts(tree, &bob, 1, &bad, 1, NULL, res, &dq, 1, &imp),
                 MECH_STATUS_INVALID_ARGUMENT);
    bad = wall;
    bad.friction = -1.0;
    CHECK_STATUS(mech_impulse_mechanism_contacts(tree, &bob, 1, &bad, 1, NULL, res, &dq, 1, &imp),
                 MECH_STATUS_INVALID_ARGUMENT);
    bad = wall;
    bad.other_body = -2;
    CHECK_STATUS(mech_impulse_mechanism_contacts(tree, &bob, 1, &bad, 1, NULL, res, &dq, 1, &imp),
                 MECH_STATUS_INVALID_ARGUMENT);
    mech_multi_contact_options_t bad_opts = {0.0, 10, 1e-10};
    CHECK_STATUS(mech_impulse_mechanism_contacts(tree, &bob, 1, two, 2, &bad_opts, res, &dq, 1, &imp),
                 MECH_STATUS_INVALID_ARGUMENT);
    bad_opts.tolerance = NAN;
    CHECK_STATUS(mech_impulse_mechanism_contacts(tree, &bob, 1, two, 2, &bad_opts, res, &dq, 1, &imp),
                 MECH_STATUS_NON_FINITE);
    CHECK(mech_untouched(res, sizeof res));
    CHECK(mech_untouched(&imp, sizeof imp));
    CHECK_STATUS(mech_impulse_mechanism_contacts(tree, &bob, 1, &wall, 1, NULL, res, &dq, 1, NULL),
                 MECH_STATUS_NULL_POINTER);

    mech_mechanism_impulse_t bad_hit = hit;
    bad_hit.impulse.x = INFINITY;
    CHECK_STATUS(mech_impulse_mechanism_apply(tree, &bob, 1, &bad_hit, 1, &dq, 1, &resp), MECH_STATUS_NON_FINITE);
    bad_hit = hit;
    bad_hit.body = 1;
    CHECK_STATUS(mech_impulse_mechanism_apply(tree, &bob, 1, &bad_hit, 1, &dq, 1, &resp),
                 MECH_STATUS_INVALID_ARGUMENT);
    CHECK_STATUS(mech_impulse_mechanism_apply(tree, &bob, 1, &hit, 1, &dq, 0, &resp), MECH_STATUS_BAD_DIMENSION);
    CHECK_STATUS(mech_impulse_mechanism_apply(tree, &bob, 1, NULL, 1, &dq, 1, &resp), MECH_STATUS_NULL_POINTER);
    CHECK_STATUS(mech_impulse_mechanism_apply(NULL, &bob, 1, &hit, 1, &dq, 1, &resp), MECH_STATUS_NULL_POINTER);
    /* A state whose velocities were refused is no state: the impulses must not use the old q̇. */
    double q0 = 0.0, nan_rate = NAN;
    CHECK_STATUS(mech_tree_set_state(tree, &q0, &nan_rate, 1), MECH_STATUS_NON_FINITE);
    CHECK_STATUS(mech_impulse_mechanism_apply(tree, &bob, 1, &hit, 1, &dq, 1, &resp), MECH_STATUS_INVALID_ARGUMENT);
    CHECK_STATUS(mech_impulse_mechanism_contacts(tree, &bob, 1, &wall, 1, NULL, res, &dq, 1, &imp),
                 MECH_STATUS_INVALID_ARGUMENT);
    CHECK(mech_untouched(&dq, sizeof dq));
    CHECK(mech_untouched(&resp, sizeof resp));
    CHECK(mech_untouched(res, sizeof res));
    CHECK_STATUS(mech_impulse_mechanism_apply(tree, &bob, 1, &hit, 1, &dq, 1, NULL), MECH_STATUS_NULL_POINTER);

    CHECK_STATUS(mech_impulse_mechanism_delassus(tree, &bob, 1, two, 2, w, 5, frames, &rank),
                 MECH_STATUS_BAD_DIMENSION);
    CHECK_STATUS(mech_impulse_mechanism_delassus(tree, &bob, 1, two, 2, NULL, 6, frames, &rank),
                 MECH_STATUS_NULL_POINTER);
    CHECK_STATUS(mech_impulse_mechanism_delassus(tree, &bob, 1, two, 2, w, 6, NULL, &rank),
                 MECH_STATUS_NULL_POINTER);
    CHECK_STATUS(mech_impulse_mechanism_delassus(tree, &bob, 1, two, 2, w, 6, frames, NULL),
                 MECH_STATUS_NULL_POINTER);
    CHECK(mech_untouched(w, sizeof w));
    mech_tree_destroy(tree);

    /* A tree that is not finalized. */
    mech_tree_t *open = NULL;
    CHECK_STATUS(mech_tree_create(&open), MECH_STATUS_OK);
    CHECK_STATUS(mech_impulse_mechanism_contacts(open, &bob, 1, &wall, 1, NULL, res, &dq, 1, &imp),
                 MECH_STATUS_INVALID_ARGUMENT);
    mech_tree_destroy(open);
}

/* mech_multi_contact_options_default writes the options a NULL pointer selects: a rough double
 * contact (the simultaneous model) gives the same impact, bit for bit, with either. */
static void test_multi_contact_options_default(void) {
    mech_multi_contact_options_t o;
    FILL_SENTINEL(&o, sizeof o);
    CHECK_STATUS(mech_multi_contact_options_default(&o), MECH_STATUS_OK);
    CHECK(o.tolerance == 1e-10 && o.max_iterations == 10000 && o.process_tolerance == 1e-10);
    CHECK_STATUS(mech_multi_contact_options_default(NULL), MECH_STATUS_NULL_POINTER);

    const double m = 2.0, l = 0.8, ic = 0.05, omega = 1.5;
    mech_mass_properties_t bob;
    memset(&bob, 0, sizeof bob);
    bob.mass = m;
    bob.center_of_mass = v3(0.0, -l, 0.0);
    bob.inertia_about_com = diag3(ic, ic, ic);
    mech_tree_t *tree = pendulum_tree(omega);
    mech_mechanism_contact_t two[2];
    memset(two, 0, sizeof two);
    for (int k = 0; k < 2; ++k) {
        two[k].body = 0;
        two[k].point = v3(0.0, -l, 0.0);
        two[k].other_body = -1;
        two[k].normal = v3(-1.0, 0.0, 0.0);
        two[k].restitution = 0.5;
        two[k].friction = 0.4;
        two[k].law = MECH_RESTITUTION_POISSON;
    }
    mech_mechanism_contact_result_t by_null[2], by_default[2];
    mech_mechanism_impact_t imp_null, imp_default;
    double dq_null = 0.0, dq_default = 1.0;
    CHECK_STATUS(mech_impulse_mechanism_contacts(tree, &bob, 1, two, 2, NULL, by_null, &dq_null, 1, &imp_null),
                 MECH_STATUS_OK);
    CHECK_STATUS(mech_impulse_mechanism_contacts(tree, &bob, 1, two, 2, &o, by_default, &dq_default, 1, &imp_default),
                 MECH_STATUS_OK);
    CHECK(imp_null.simultaneous == 1 && imp_null.converged == 1);
    CHECK(dq_null == dq_default);
    CHECK(imp_null.energy_change == imp_default.energy_change && imp_null.iterations == imp_default.iterations);
    CHECK(imp_null.complementarity_residual == imp_default.complementarity_residual);
    for (int k = 0; k < 2; ++k) {
        CHECK(by_null[k].normal_impulse == by_default[k].normal_impulse);
        CHECK(by_null[k].impulse.x == by_default[k].impulse.x && by_null[k].impulse.y == by_default[k].impulse.y);
        CHECK(by_null[k].mode == by_default[k].mode);
    }
    mech_tree_destroy(tree);
}

/* A rod-like body hinged about z at (0, L, 0), its tip at the origin moving along x at omega L,
 * strikes a wall whose normal makes 1 rad with the tip's path. With friction 0.8 the contact
 * self-locks (f gamma > |g_n|): Newton and Stronge report the jam, Poisson ends at (1 + e) p_c
 * with the tip at rest, p_c = |omega| I_h / (|g_n| + f gamma), g = (L, 0, 0). */
static void test_self_locking(void) {
    double m = 1.2, l = 0.9, omega = 2.0, e = 0.5, f = 0.8;
    double j = m * l * l / 12.0; /* transverse moments; the axial one 1% of it */
    mech_impulse_body_t rod;
    memset(&rod, 0, sizeof rod);
    rod.inverse_mass = 1.0 / m;
    rod.inverse_inertia = diag3(1.0 / j, 100.0 / j, 1.0 / j);
    rod.center_of_mass = v3(0.0, l / 2.0, 0.0);
    rod.velocity = v3(omega * l / 2.0, 0.0, 0.0);
    rod.angular_velocity = v3(0.0, 0.0, omega);
    rod.constraint = MECH_BODY_HINGE_AXIS;
    rod.hinge_point = v3(0.0, l, 0.0);
    rod.hinge_axis = v3(0.0, 0.0, 1.0);
    mech_impulse_body_t wall = ground();
    mech_impulse_contact_t c;
    memset(&c, 0, sizeof c);
    c.point = v3(0, 0, 0);
    c.normal = v3(-cos(1.0), -sin(1.0), 0.0);
    c.restitution = e;
    c.friction = f;
    c.tolerance = 1e-10;
    double i_h = j + m * (l / 2.0) * (l / 2.0);
    double g_n = l * cos(1.0), gamma = l * sin(1.0);
    CHECK(f * gamma > g_n);
    double p_c = omega * i_h / (g_n + f * gamma);
    mech_impact_result_t res;
    c.law = MECH_RESTITUTION_NEWTON;
    FILL_SENTINEL(&res, sizeof res);
    CHECK_STATUS(mech_impulse_resolve_contact(&wall, &rod, &c, &res), MECH_STATUS_NOT_CONVERGED);
    CHECK(mech_untouched(&res, sizeof res));
    c.law = MECH_RESTITUTION_STRONGE;
    CHECK_STATUS(mech_impulse_resolve_contact(&wall, &rod, &c, &res), MECH_STATUS_NOT_CONVERGED);
    c.law = MECH_RESTITUTION_POISSON;
    CHECK_STATUS(mech_impulse_resolve_contact(&wall, &rod, &c, &res), MECH_STATUS_OK);
    CHECK_NEAR(res.compression_impulse, p_c, 1e-12 * p_c);
    CHECK_NEAR(res.normal_impulse, (1.0 + e) * p_c, 1e-12 * p_c);
    CHECK_NEAR(res.angular_velocity_after_2.z, 0.0, 1e-12 * omega);
    CHECK(res.mode == MECH_CONTACT_SLIP_THEN_STICK);
    /* Out of the regime (friction 0.5) Newton's law holds: u_n+ = -e u_n-. */
    c.friction = 0.5;
    c.law = MECH_RESTITUTION_NEWTON;
    CHECK_STATUS(mech_impulse_resolve_contact(&wall, &rod, &c, &res), MECH_STATUS_OK);
    double un_after = res.relative_velocity_after.x * c.normal.x + res.relative_velocity_after.y * c.normal.y;
    CHECK_NEAR(un_after, e * omega * g_n, 1e-12 * omega * l);
}

/* A needle (axial moment 2e-7 of the others) struck from rest and sticking: the impulse against
 * the solution of W P = (1 + e) |u_n| n for the stored data computed with mpmath at 200 bits
 * (W = I - [d]x G [d]x has condition 3e6 here, so a plain double solve is off by ~1e-10), and a
 * reported error bound at the level of rounding. */
static void test_needle(void) {
    /* Axis a = (2, 3, 6)/7; inverse inertia I + (1/2e-7 - 1) a a^T (unit transverse moments). */
    double a[3] = {2.0 / 7.0, 3.0 / 7.0, 6.0 / 7.0};
    mech_impulse_body_t needle;
    memset(&needle, 0, sizeof needle);
    needle.inverse_mass = 1.0;
    for (int i = 0; i < 3; ++i)
        for (int k = 0; k < 3; ++k) needle.inverse_inertia.m[i + 3 * k] = (i == k) + (1.0 / 2e-7 - 1.0) * a[i] * a[k];
    double n[3] = {0.6, 0.0, -0.8};
    needle.velocity = v3(-n[0], -n[1], -n[2]);
    needle.constraint = MECH_BODY_FREE;
    double d[3] = {0.3, -0.5, 0.2};
    mech_impulse_body_t g = ground();
    mech_impulse_contact_t c;
    memset(&c, 0, sizeof c);
    c.point = v3(d[0], d[1], d[2]);
    c.normal = v3(n[0], n[1], n[2]);
    c.restitution = 0.5;
    c.friction = 100.0;
    c.law = MECH_RESTITUTION_STRONGE;
    c.tolerance = 1e-10;
    mech_impact_result_t res;
    CHECK_STATUS(mech_impulse_resolve_contact(&g, &needle, &c, &res), MECH_STATUS_OK);
    CHECK(res.mode == MECH_CONTACT_STICK);
    double p_ref[3] = {-0.11842196737596349, -0.313081972820121, -0.45507198098635754};
    double size = sqrt(p_ref[0] * p_ref[0] + p_ref[1] * p_ref[1] + p_ref[2] * p_ref[2]);
    double error = sqrt(pow(res.impulse.x - p_ref[0], 2) + pow(res.impulse.y - p_ref[1], 2) + pow(res.impulse.z - p_ref[2], 2));
    CHECK(error <= 8 * 2.2e-16 * size);
    CHECK(error <= res.integration_error + 2.2e-16 * size); /* the reference is itself rounded */
    CHECK(res.integration_error > 0.0 && res.integration_error <= 256 * 2.2e-16 * size);
}

int main(void) {
    test_points();
    test_self_locking();
    test_needle();
    test_bodies();
    test_contacts();
    test_mechanisms();
    test_multi_contact_options_default();
    return CHECK_DONE();
}
