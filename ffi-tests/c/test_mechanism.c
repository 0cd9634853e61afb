/* Mechanism C ABI: potentials with exact derivatives, equilibrium, stability and modes of a
 * double pendulum of point masses against closed forms, and the error paths. */
#include "check.h"

static const double G = 9.81, L = 0.8, M = 1.5;

static mech_tree_t *double_pendulum_tree(void) {
    mech_tree_t *tree = NULL;
    CHECK_STATUS(mech_tree_create(&tree), MECH_STATUS_OK);
    const mech_vec3_t axis = {0.0, 1.0, 0.0};
    const mech_mat3_t identity = {{1, 0, 0, 0, 1, 0, 0, 0, 1}};
    const mech_vec3_t origin = {0.0, 0.0, 0.0}, elbow = {0.0, 0.0, -L};
    size_t body = 99;
    CHECK_STATUS(mech_tree_add_body(tree, -1, MECH_JOINT_REVOLUTE, &axis, &identity, &origin, &body), MECH_STATUS_OK);
    CHECK(body == 0);
    CHECK_STATUS(mech_tree_add_body(tree, 0, MECH_JOINT_REVOLUTE, &axis, &identity, &elbow, &body), MECH_STATUS_OK);
    CHECK(body == 1);
    CHECK_STATUS(mech_tree_finalize(tree), MECH_STATUS_OK);
    return tree;
}

static mech_mechanism_t *double_pendulum(void) {
    mech_tree_t *tree = double_pendulum_tree();
    mech_mass_properties_t bodies[2];
    memset(bodies, 0, sizeof bodies);
    for (int i = 0; i < 2; ++i) {
        bodies[i].mass = M;
        bodies[i].center_of_mass.z = -L;
    }
    mech_mechanism_t *mechanism = NULL;
    CHECK_STATUS(mech_mechanism_create(tree, bodies, 2, &mechanism), MECH_STATUS_OK);
    mech_tree_destroy(tree); /* the mechanism holds its own copy */
    const mech_vec3_t gravity = {0.0, 0.0, -G};
    CHECK_STATUS(mech_mechanism_set_gravity(mechanism, gravity), MECH_STATUS_OK);
    return mechanism;
}

int main(void) {
    mech_mechanism_t *m = double_pendulum();
    size_t dof = 0;
    CHECK_STATUS(mech_mechanism_dof(m, &dof), MECH_STATUS_OK);
    CHECK(dof == 2);

    /* U = −mgl cos q1 − mgl (cos q1 + cos(q1 + q2)) and its exact derivatives. */
    const double q[2] = {0.3, -0.2};
    const double c1 = cos(q[0]), c12 = cos(q[0] + q[1]), s1 = sin(q[0]), s12 = sin(q[0] + q[1]);
    const double mgl = M * G * L;
    double u = 0.0, grad[2], hess[4];
    CHECK_STATUS(mech_mechanism_potential(m, q, 2, &u, grad, hess), MECH_STATUS_OK);
    CHECK_NEAR(u, -mgl * (2.0 * c1 + c12), 1e-13);
    CHECK_NEAR(grad[0], mgl * (2.0 * s1 + s12), 1e-13);
    CHECK_NEAR(grad[1], mgl * s12, 1e-13);
    CHECK_NEAR(hess[0], mgl * (2.0 * c1 + c12), 1e-12);
    CHECK_NEAR(hess[1], mgl * c12, 1e-12);
    CHECK_NEAR(hess[2], mgl * c12, 1e-12);
    CHECK_NEAR(hess[3], mgl * c12, 1e-12);
    CHECK_STATUS(mech_mechanism_potential(m, q, 2, &u, grad, NULL), MECH_STATUS_OK); /* no Hessian */

    /* The hanging equilibrium and its modes: ω² l / g = 2 ∓ √2. */
    double q_eq[2];
    mech_equilibrium_report_t report;
    CHECK_STATUS(mech_mechanism_equilibrium(m, q, 2, MECH_SEEK_MINIMUM, 0, 0.0, q_eq, &report), MECH_STATUS_OK);
    CHECK_NEAR(q_eq[0], 0.0, 1e-12);
    CHECK_NEAR(q_eq[1], 0.0, 1e-12);
    CHECK(report.gradient_norm <= report.tolerance);
    CHECK(report.iterations > 0 && report.at_limit == 0);
    double w2[2], bounds[2], shapes[4];
    mech_modal_kind_t kinds[2];
    size_t found = 0;
    mech_stability_t stability;
    CHECK_STATUS(mech_mechanism_modes(m, q_eq, 2, 0, w2, bounds, kinds, shapes, &found, &stability), MECH_STATUS_OK);
    CHECK(found == 2);
    CHECK_NEAR(w2[0], (2.0 - sqrt(2.0)) * G / L, 1e-12);
    CHECK_NEAR(w2[1], (2.0 + sqrt(2.0)) * G / L, 1e-12);
    CHECK(fabs(w2[0] - (2.0 - sqrt(2.0)) * G / L) <= bounds[0] + 1e-15 * w2[0]);
    CHECK(kinds[0] == MECH_MODAL_KIND_OSCILLATORY && kinds[1] == MECH_MODAL_KIND_OSCILLATORY);
    CHECK(stability.unstable_directions == 0 && stability.zero_modes == 0 && stability.gyroscopic_stable == -1);
    /* Lowest mode: absolute angles θ2/θ1 = √2, so the relative joint angle q2/q1 = √2 − 1. */
    CHECK_NEAR(shapes[1] / shapes[0], sqrt(2.0) - 1.0, 1e-10);

    /* Upright: a stationary point with two unstable directions. */
    const double near_up[2] = {3.0, 0.1};
    CHECK_STATUS(mech_mechanism_equilibrium(m, near_up, 2, MECH_SEEK_STATIONARY, 0, 0.0, q_eq, &report), MECH_STATUS_OK);
    CHECK_NEAR(q_eq[0], 3.14159265358979323846, 1e-10);
    CHECK_NEAR(q_eq[1], 0.0, 1e-10);
    CHECK_STATUS(mech_mechanism_modes(m, q_eq, 2, 1, w2, bounds, kinds, NULL, &found, &stability), MECH_STATUS_OK);
    CHECK(found == 1 && kinds[0] == MECH_MODAL_KIND_UNSTABLE);
    CHECK(stability.unstable_directions == 1); /* only the lowest mode was asked for */
    CHECK_NEAR(stability.max_growth_rate * stability.max_growth_rate, (2.0 + sqrt(2.0)) * G / L, 1e-10);

    /* Loads: springs, a force, limits, a rotating frame. */
    const mech_vec3_t zero = {0, 0, 0}, tip = {0.0, 0.0, -L}, wall = {1.0, 0.0, -2.0 * L};
    const mech_vec3_t push = {2.0, 0.0, 0.0}, up = {0.0, 0.0, 1.0};
    CHECK_STATUS(mech_mechanism_add_joint_spring(m, 1, 5.0, 0.0), MECH_STATUS_OK);
    CHECK_STATUS(mech_mechanism_add_point_spring(m, 1, tip, MECH_GROUND, wall, 10.0, 0.5), MECH_STATUS_OK);
    CHECK_STATUS(mech_mechanism_add_force(m, 0, tip, push), MECH_STATUS_OK);
    CHECK_STATUS(mech_mechanism_set_limits(m, 0, -1.0, 1.0), MECH_STATUS_OK);
    CHECK_STATUS(mech_mechanism_set_rotating_frame(m, up, 1.0), MECH_STATUS_OK);
    CHECK_STATUS(mech_mechanism_equilibrium(m, q, 2, MECH_SEEK_MINIMUM, 0, 0.0, q_eq, &report), MECH_STATUS_OK);
    CHECK_STATUS(mech_mechanism_potential(m, q_eq, 2, &u, grad, NULL), MECH_STATUS_OK);
    CHECK(fabs(grad[0]) <= report.tolerance && fabs(grad[1]) <= report.tolerance);

    /* Errors: nothing is written. */
    double sentinel[4];
    FILL_SENTINEL(sentinel, sizeof sentinel);
    CHECK_STATUS(mech_mechanism_potential(NULL, q, 2, &u, sentinel, NULL), MECH_STATUS_NULL_POINTER);
    CHECK_STATUS(mech_mechanism_potential(m, q, 3, &u, sentinel, NULL), MECH_STATUS_BAD_DIMENSION);
    const double bad[2] = {NAN, 0.0};
    CHECK_STATUS(mech_mechanism_potential(m, bad, 2, &u, sentinel, NULL), MECH_STATUS_NON_FINITE);
    CHECK_STATUS(mech_mechanism_equilibrium(m, q, 2, 7, 0, 0.0, sentinel, &report), MECH_STATUS_BAD_ENUM);
    CHECK_STATUS(mech_mechanism_modes(m, q, 2, 3, sentinel, bounds, kinds, NULL, &found, &stability),
                 MECH_STATUS_BAD_DIMENSION);
    CHECK(mech_untouched(sentinel, sizeof sentinel));
    CHECK_STATUS(mech_mechanism_add_point_spring(m, 5, zero, MECH_GROUND, zero, 1.0, 0.0), MECH_STATUS_INVALID_ARGUMENT);
    CHECK_STATUS(mech_mechanism_add_point_spring(m, -3, zero, MECH_GROUND, zero, 1.0, 0.0), MECH_STATUS_INVALID_ARGUMENT);
    CHECK_STATUS(mech_mechanism_add_joint_spring(m, 0, -1.0, 0.0), MECH_STATUS_INVALID_ARGUMENT);
    CHECK_STATUS(mech_mechanism_set_limits(m, 0, 1.0, -1.0), MECH_STATUS_INVALID_ARGUMENT);
    const mech_vec3_t sideways = {1.0, 0.0, 0.0};
    CHECK_STATUS(mech_mechanism_set_rotating_frame(m, sideways, 2.0), MECH_STATUS_INVALID_ARGUMENT);
    const mech_vec3_t nan_gravity = {NAN, 0.0, 0.0};
    CHECK_STATUS(mech_mechanism_set_gravity(m, nan_gravity), MECH_STATUS_NON_FINITE);
    mech_mechanism_destroy(m);

    /* A search that cannot converge: a constant torque on a wheel. It reports the best point. */
    mech_tree_t *tree = NULL;
    CHECK_STATUS(mech_tree_create(&tree), MECH_STATUS_OK);
    const mech_vec3_t z = {0.0, 0.0, 1.0};
    const mech_mat3_t identity = {{1, 0, 0, 0, 1, 0, 0, 0, 1}};
    size_t body = 0;
    CHECK_STATUS(mech_tree_add_body(tree, -1, MECH_JOINT_REVOLUTE, &z, &identity, &zero, &body), MECH_STATUS_OK);
    mech_mechanism_t *unfinished = NULL;
    mech_mass_properties_t wheel;
    memset(&wheel, 0, sizeof wheel);
    wheel.mass = 1.0;
    wheel.inertia_about_com.m[0] = wheel.inertia_about_com.m[4] = 0.1;
    wheel.inertia_about_com.m[8] = 0.2;
    CHECK_STATUS(mech_mechanism_create(tree, &wheel, 1, &unfinished), MECH_STATUS_INVALID_ARGUMENT); /* not finalized */
    CHECK(unfinished == NULL);
    CHECK_STATUS(mech_tree_finalize(tree), MECH_STATUS_OK);
    const mech_mass_properties_t two_wheels[2] = {wheel, wheel};
    CHECK_STATUS(mech_mechanism_create(tree, two_wheels, 2, &unfinished), MECH_STATUS_BAD_DIMENSION);
    mech_mechanism_t *w = NULL;
    CHECK_STATUS(mech_mechanism_create(tree, &wheel, 1, &w), MECH_STATUS_OK);
    const mech_vec3_t rim = {0.1, 0.0, 0.0}, tangential = {0.0, 3.0, 0.0};
    CHECK_STATUS(mech_mechanism_add_force(w, 0, rim, tangential), MECH_STATUS_OK);
    const double start = 0.0;
    double best = 42.0;
    CHECK_STATUS(mech_mechanism_equilibrium(w, &start, 1, MECH_SEEK_STATIONARY, 5, 0.0, &best, &report),
                 MECH_STATUS_NOT_CONVERGED);
    CHECK(best != 42.0 && report.gradient_norm > report.tolerance);
    mech_mechanism_destroy(w);
    mech_mechanism_destroy(NULL);
    mech_tree_destroy(tree);
    return CHECK_DONE();
}
