/* Motion C ABI with unilateral contacts: a mass dropped on the ground under gravity bounces at
 * the closed-form times t_{k+1} = t_k + 2 e^k v1 / g, losing ½ m v_k² (1 − e²) at impact k, for
 * several masses, heights and restitutions (a reproducible LCG), by Dormand–Prince and RK4;
 * the impact records, contacts, impulses and velocities agree with it; a plastic impact stops
 * the run with NOT_CONVERGED (sustained contact) after recording the impact; bad contacts and
 * indices are refused. */
#include "check.h"

static const mech_vec3_t ZERO = {0.0, 0.0, 0.0};
static const mech_mat3_t IDENTITY = {{1, 0, 0, 0, 1, 0, 0, 0, 1}};

/* A point mass m on a prismatic joint along z (q = height), gravity g along −z. */
static mech_dynamics_t *falling_mass(double m, double g) {
    mech_tree_t *tree = NULL;
    CHECK_STATUS(mech_tree_create(&tree), MECH_STATUS_OK);
    const mech_vec3_t z = {0.0, 0.0, 1.0};
    size_t body = 99;
    CHECK_STATUS(mech_tree_add_body(tree, -1, MECH_JOINT_PRISMATIC, &z, &IDENTITY, &ZERO, &body), MECH_STATUS_OK);
    CHECK_STATUS(mech_tree_finalize(tree), MECH_STATUS_OK);
    mech_mass_properties_t point;
    memset(&point, 0, sizeof point);
    point.mass = m;
    mech_mechanism_t *mechanism = NULL;
    CHECK_STATUS(mech_mechanism_create(tree, &point, 1, &mechanism), MECH_STATUS_OK);
    mech_tree_destroy(tree);
    const mech_vec3_t gravity = {0.0, 0.0, -g};
    CHECK_STATUS(mech_mechanism_set_gravity(mechanism, gravity), MECH_STATUS_OK);
    mech_dynamics_t *dynamics = NULL;
    CHECK_STATUS(mech_dynamics_create(mechanism, &dynamics), MECH_STATUS_OK);
    mech_mechanism_destroy(mechanism);
    return dynamics;
}

/* The ground z = 0 under the body's origin, frictionless, restitution e (Newton's law). */
static mech_motion_contact_t ground(double e) {
    mech_motion_contact_t c;
    memset(&c, 0, sizeof c);
    c.contact.body = 0;
    c.contact.other_body = -1;
    c.contact.normal.z = 1.0;
    c.contact.restitution = e;
    c.contact.friction = 0.0;
    c.contact.law = MECH_RESTITUTION_NEWTON;
    c.offset = 0.0;
    return c;
}

static unsigned long long lcg_state = 12345;
static double uniform(double lo, double hi) {
    lcg_state = lcg_state * 6364136223846793005ULL + 1442695040888963407ULL;
    return lo + (hi - lo) * (double)(lcg_state >> 11) / 9007199254740992.0;
}

static void check_bounces(mech_motion_method_t method) {
    for (int trial = 0; trial < 6; ++trial) {
        const double m = pow(10.0, uniform(-2.0, 2.0)), g = uniform(2.0, 15.0);
        const double h0 = pow(10.0, uniform(-1.0, 1.0)), e = uniform(0.3, 0.9);
        const double v1 = sqrt(2.0 * g * h0);
        double times[4];
        times[0] = v1 / g;
        for (int k = 1; k < 4; ++k) times[k] = times[k - 1] + 2.0 * pow(e, k) * v1 / g;
        mech_dynamics_t *d = falling_mass(m, g);
        mech_motion_options_t options;
        CHECK_STATUS(mech_motion_options_default(&options), MECH_STATUS_OK);
        options.method = method;
        options.rtol = 1e-11;
        options.atol = 1e-13 * h0;
        options.step = times[0] / 30.0;
        const mech_motion_contact_t contact = ground(e);
        const double zero = 0.0;
        mech_simulation_t *s = NULL;
        CHECK_STATUS(mech_simulation_create_with_contacts(d, &options, &contact, 1, &h0, &zero, NULL, 1, &s),
                     MECH_STATUS_OK);
        const double t_end = times[3] + pow(e, 4) * v1 / g; /* the apex after the fourth bounce */
        double q = -1.0, qd = -1.0;
        CHECK_STATUS(mech_simulation_advance(s, t_end, 1, &q, &qd), MECH_STATUS_OK);
        const double apex = pow(pow(e, 4) * v1, 2) / (2.0 * g);
        CHECK_NEAR(q, apex, 1e-7 * h0);
        CHECK_NEAR(qd, 0.0, 1e-7 * v1);
        size_t count = 0;
        CHECK_STATUS(mech_simulation_impact_count(s, &count), MECH_STATUS_OK);
        CHECK(count == 4);
        for (size_t k = 0; k < count; ++k) {
            const double v = pow(e, (double)k) * v1;
            mech_motion_impact_t impact;
            CHECK_STATUS(mech_simulation_impact(s, k, &impact), MECH_STATUS_OK);
            CHECK_NEAR(impact.t, times[k], 1e-9 * times[k]);
            CHECK(impact.contact_count == 1);
            CHECK(impact.gap <= 0.0 && impact.gap >= -1e-8 * h0);
            CHECK_NEAR(impact.approach_speed, v, 1e-8 * v);
            CHECK_NEAR(impact.energy_lost, 0.5 * m * v * v * (1.0 - e * e), 1e-7 * m * v * v);
            CHECK_NEAR(impact.energy_before - impact.energy_after, impact.energy_lost, 1e-12 * m * v * v);
            CHECK_NEAR(impact.kinetic_energy_before, 0.5 * m * v * v, 1e-8 * m * v * v);
            CHECK(fabs(impact.segment_drift) <= 1e-9 * m * g * h0);
            size_t which = 99;
            mech_vec3_t impulse = {0, 0, 0};
            mech_contact_mode_t mode = -1;
            CHECK_STATUS(mech_simulation_impact_contacts(s, k, 1, &which, &impulse, &mode), MECH_STATUS_OK);
            CHECK(which == 0);
            CHECK(mode == MECH_CONTACT_FRICTIONLESS);
            CHECK_NEAR(impulse.z, m * (1.0 + e) * v, 1e-8 * m * v);
            CHECK_NEAR(impulse.x, 0.0, 1e-12 * m * v);
            double before = 0.0, after = 0.0;
            CHECK_STATUS(mech_simulation_impact_velocities(s, k, 1, &before, &after), MECH_STATUS_OK);
            CHECK_NEAR(before, -v, 1e-8 * v);
            CHECK_NEAR(after, e * v, 1e-8 * v);
        }
        mech_motion_impact_t unused;
        CHECK_STATUS(mech_simulation_impact(s, count, &unused), MECH_STATUS_INVALID_ARGUMENT);
        size_t which[1];
        CHECK_STATUS(mech_simulation_impact_contacts(s, 0, 0, which, NULL, NULL), MECH_STATUS_BAD_DIMENSION);
        double v2[2];
        CHECK_STATUS(mech_simulation_impact_velocities(s, 0, 2, v2, v2), MECH_STATUS_BAD_DIMENSION);
        mech_simulation_destroy(s);
        mech_dynamics_destroy(d);
    }
}

/* e = 0: the mass stays on the ground, pressed by gravity: not modelled, so the advance stops
 * with NOT_CONVERGED after the impact, which is recorded with the whole energy of approach lost. */
static void plastic_impact_stops_the_run(void) {
    mech_dynamics_t *d = falling_mass(2.0, 9.81);
    const mech_motion_contact_t contact = ground(0.0);
    const double h0 = 0.5, zero = 0.0;
    mech_simulation_t *s = NULL;
    CHECK_STATUS(mech_simulation_create_with_contacts(d, NULL, &contact, 1, &h0, &zero, NULL, 1, &s), MECH_STATUS_OK);
    double q = 0.0, qd = 0.0;
    CHECK_STATUS(mech_simulation_advance(s, 2.0, 1, &q, &qd), MECH_STATUS_NOT_CONVERGED);
    char message[512];
    mech_last_error(message, sizeof message);
    CHECK(strstr(message, "stays closed") != NULL);
    size_t count = 0;
    CHECK_STATUS(mech_simulation_impact_count(s, &count), MECH_STATUS_OK);
    CHECK(count == 1);
    mech_motion_impact_t impact;
    CHECK_STATUS(mech_simulation_impact(s, 0, &impact), MECH_STATUS_OK);
    CHECK_NEAR(impact.energy_lost, 2.0 * 9.81 * h0, 1e-7);
    CHECK_NEAR(impact.t, sqrt(2.0 * h0 / 9.81), 1e-8);
    mech_simulation_destroy(s);
    mech_dynamics_destroy(d);
}

static void bad_contacts_are_refused(void) {
    mech_dynamics_t *d = falling_mass(1.0, 9.81);
    const double h0 = 1.0, zero = 0.0;
    mech_simulation_t *s = (mech_simulation_t *)0x1;
    mech_motion_contact_t contact = ground(0.5);
    contact.contact.normal.z = 2.0;
    CHECK_STATUS(mech_simulation_create_with_contacts(d, NULL, &contact, 1, &h0, &zero, NULL, 1, &s),
                 MECH_STATUS_INVALID_ARGUMENT);
    CHECK(s == (mech_simulation_t *)0x1);
    contact = ground(0.5);
    contact.contact.body = 7;
    CHECK_STATUS(mech_simulation_create_with_contacts(d, NULL, &contact, 1, &h0, &zero, NULL, 1, &s),
                 MECH_STATUS_INVALID_ARGUMENT);
    contact = ground(1.5);
    CHECK_STATUS(mech_simulation_create_with_contacts(d, NULL, &contact, 1, &h0, &zero, NULL, 1, &s),
                 MECH_STATUS_INVALID_ARGUMENT);
    contact = ground(0.5);
    contact.offset = NAN;
    CHECK(mech_simulation_create_with_contacts(d, NULL, &contact, 1, &h0, &zero, NULL, 1, &s) != MECH_STATUS_OK);
    CHECK_STATUS(mech_simulation_create_with_contacts(d, NULL, NULL, 1, &h0, &zero, NULL, 1, &s),
                 MECH_STATUS_NULL_POINTER);
    /* No contacts: an ordinary simulation with no impacts. */
    CHECK_STATUS(mech_simulation_create_with_contacts(d, NULL, NULL, 0, &h0, &zero, NULL, 1, &s), MECH_STATUS_OK);
    double q = 0.0, qd = 0.0;
    CHECK_STATUS(mech_simulation_advance(s, 1.0, 1, &q, &qd), MECH_STATUS_OK);
    CHECK_NEAR(q, h0 - 0.5 * 9.81, 1e-8);
    size_t count = 99;
    CHECK_STATUS(mech_simulation_impact_count(s, &count), MECH_STATUS_OK);
    CHECK(count == 0);
    mech_simulation_destroy(s);
    mech_dynamics_destroy(d);
}

int main(void) {
    check_bounces(MECH_MOTION_DORMAND_PRINCE);
    check_bounces(MECH_MOTION_RK4);
    plastic_impact_stops_the_run();
    bad_contacts_are_refused();
    printf("test_motion_impacts: %d checks passed\n", mech_check_count);
    return 0;
}
