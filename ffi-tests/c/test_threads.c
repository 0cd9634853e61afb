/* Concurrency test of the C ABI. Several threads start together (a barrier) and each calls
 * every handle-free function, works on handles of its own (a tree, a mechanism, modal
 * results) and reads one modal result shared by all threads through its const accessors. Every
 * result must equal, bit for bit, the one the main thread computed alone before the threads
 * started; each thread's last-error message must stay its own. The dense solves are large
 * enough (order 200) to use the library's own worker threads, and one mesh (66 560 triangles)
 * is large enough to be split across scoped threads, while other threads release the modal
 * scratch pool. Built once more with -fsanitize=thread by ffi-tests/tests/threads.rs. */
/* POSIX barriers are outside strict C11. */
#define _POSIX_C_SOURCE 200112L
#include "check.h"
#include <pthread.h>
#include <stddef.h>
#include <stdint.h>

/* check.h counts checks in a plain global, which the threads would race on (ThreadSanitizer
 * reports it): here the checks only fail, they do not count. */
#undef CHECK
#define CHECK(cond)                                                                 \
    do {                                                                            \
        if (!(cond)) {                                                              \
            fprintf(stderr, "%s:%d: CHECK failed: %s\n", __FILE__, __LINE__, #cond); \
            exit(1);                                                                \
        }                                                                           \
    } while (0)
#undef CHECK_STATUS
#define CHECK_STATUS(call, expected)                                                      \
    do {                                                                                  \
        mech_status_t mech_got_ = (call);                                                 \
        if (mech_got_ != (expected)) {                                                    \
            char mech_msg_[512];                                                          \
            mech_last_error(mech_msg_, sizeof mech_msg_);                                 \
            fprintf(stderr, "%s:%d: %s returned %d (%s; last error: %s), expected %s\n",  \
                    __FILE__, __LINE__, #call, (int)mech_got_, mech_status_str(mech_got_), \
                    mech_msg_, #expected);                                                \
            exit(1);                                                                      \
        }                                                                                 \
    } while (0)

#define THREADS 4
#define ROUNDS 3
#define BIG 200
#define SPHERE_U 260
#define SPHERE_V 130

/* Everything one pass computes; compared bytewise between the threads and the reference. */
typedef struct {
    mech_mat3_t euler_rotation, exp_rotation, axis_rotation, polar, from_quat;
    double euler_back[3], rates[3], correction;
    mech_vec3_t omega, log, velocity, acceleration, omega_from_rate;
    mech_quat_t quat;
    mech_relative_decomposition_t decomposition;
    mech_mass_properties_t moved, combined, rest, point, primitive, repaired, mesh;
    mech_mat3_t steiner, axes;
    mech_vec3_t moments, momentum, angular_momentum;
    double line_moment, energy, repair_change;
    mech_mass_validity_t validity;
    mech_mesh_report_t mesh_report;
    mech_collinear_impact_t collinear;
    mech_point_impulse_t point_impulse;
    mech_point_impact_t point_impact;
    mech_impulse_body_t body;
    mech_body_response_t response;
    mech_fixation_t fixation;
    mech_impact_result_t impact;
    size_t below;
    double sparse_omega[2], sparse_bound[2];
    mech_modal_mode_t sparse_modes[2];
    double big_lambda[BIG];
    /* Handle-based results, from the thread's own handles. */
    mech_vec3_t tree_velocity;
    double jacobian[3 * 2], mass_matrix[4], tree_energy, delta_q_dot[2];
    mech_mechanism_response_t mechanism_response;
    double potential, gradient[2], equilibrium[2];
    mech_equilibrium_report_t equilibrium_report;
    double mode_omega[2];
    /* Reads of the shared result. */
    double shared_lambda[BIG];
    double shared_delta[BIG];
} pass_t;

static pass_t reference;
static pthread_barrier_t start_line;
static const mech_modal_result_t *shared_result;
static double big_a[BIG * BIG], big_b[BIG * BIG];
static double *sphere_vertices;
static uint32_t *sphere_indices;
static size_t sphere_vertex_count, sphere_triangle_count;

static mech_vec3_t v3(double x, double y, double z) {
    mech_vec3_t v = {x, y, z};
    return v;
}

/* A spring chain of order BIG (A = I + small coupling, B = tridiagonal). */
static void big_pencil(void) {
    for (int j = 0; j < BIG; ++j) {
        for (int i = 0; i < BIG; ++i) {
            int d = i > j ? i - j : j - i;
            big_a[i + BIG * j] = i == j ? 2.0 : (d == 1 ? 0.5 : 0.0);
            big_b[i + BIG * j] = i == j ? 2.0 + 0.01 * i : (d == 1 ? -1.0 : 0.0);
        }
    }
}

/* A closed UV sphere of 2·SPHERE_U·(SPHERE_V − 1) triangles, outward oriented. */
static void sphere_mesh(void) {
    size_t rings = SPHERE_V - 1;
    sphere_vertex_count = 2 + (size_t)SPHERE_U * rings;
    sphere_triangle_count = 2 * (size_t)SPHERE_U * (SPHERE_V - 1);
    sphere_vertices = malloc(3 * sphere_vertex_count * sizeof(double));
    sphere_indices = malloc(3 * sphere_triangle_count * sizeof(uint32_t));
    CHECK(sphere_vertices != NULL && sphere_indices != NULL);
    const double pi = 3.14159265358979323846;
    double *v = sphere_vertices;
    *v++ = 0.0, *v++ = 0.0, *v++ = 1.0;
    for (size_t r = 1; r <= rings; ++r) {
        double theta = pi * (double)r / SPHERE_V;
        for (size_t s = 0; s < SPHERE_U; ++s) {
            double phi = 2.0 * pi * (double)s / SPHERE_U;
            *v++ = sin(theta) * cos(phi), *v++ = sin(theta) * sin(phi), *v++ = cos(theta);
        }
    }
    *v++ = 0.0, *v++ = 0.0, *v++ = -1.0;
    uint32_t south = (uint32_t)(sphere_vertex_count - 1);
    uint32_t *t = sphere_indices;
#define RING(r, s) ((uint32_t)(1 + ((r) - 1) * SPHERE_U + ((s) % SPHERE_U)))
    for (size_t s = 0; s < SPHERE_U; ++s) {
        *t++ = 0, *t++ = RING(1, s), *t++ = RING(1, s + 1);
        *t++ = south, *t++ = RING(rings, s + 1), *t++ = RING(rings, s);
    }
    for (size_t r = 1; r < rings; ++r) {
        for (size_t s = 0; s < SPHERE_U; ++s) {
            *t++ = RING(r, s), *t++ = RING(r + 1, s), *t++ = RING(r + 1, s + 1);
            *t++ = RING(r, s), *t++ = RING(r + 1, s + 1), *t++ = RING(r, s + 1);
        }
    }
#undef RING
    CHECK((size_t)(t - sphere_indices) == 3 * sphere_triangle_count);
}

static void kinematics_calls(pass_t *p) {
    const double angles[3] = {0.3, -0.2, 1.1}, rates[3] = {0.5, 0.1, -0.4};
    int32_t lock = -1;
    double distance = 0.0;
    CHECK_STATUS(mech_rotation_from_euler(MECH_EULER_ZYX, angles, &p->euler_rotation), MECH_STATUS_OK);
    CHECK_STATUS(mech_euler_from_rotation(&p->euler_rotation, MECH_EULER_ZYX, p->euler_back, &lock, &distance), MECH_STATUS_OK);
    CHECK_STATUS(mech_angular_velocity_from_euler_rates(MECH_EULER_XYZ, angles, rates, MECH_FRAME_BODY, &p->omega), MECH_STATUS_OK);
    CHECK_STATUS(mech_euler_rates_from_angular_velocity(MECH_EULER_XYZ, angles, &p->omega, MECH_FRAME_BODY, p->rates), MECH_STATUS_OK);
    mech_vec3_t phi = v3(0.4, -1.2, 0.7);
    CHECK_STATUS(mech_rotation_exp(&phi, &p->exp_rotation), MECH_STATUS_OK);
    CHECK_STATUS(mech_rotation_log(&p->exp_rotation, &p->log), MECH_STATUS_OK);
    mech_vec3_t axis = v3(0.0, 0.6, 0.8);
    CHECK_STATUS(mech_rotation_from_axis_angle(&axis, 2.5, &p->axis_rotation), MECH_STATUS_OK);
    mech_mat3_t drifted = p->exp_rotation;
    drifted.m[1] += 1e-9;
    CHECK_STATUS(mech_rotation_orthonormalize(&drifted, &p->polar, &p->correction), MECH_STATUS_OK);
    CHECK_STATUS(mech_quat_from_rotation_matrix(&p->exp_rotation, &p->quat), MECH_STATUS_OK);
    CHECK_STATUS(mech_rotation_matrix_from_quat(&p->quat, MECH_QUAT_NORMALIZE, &p->from_quat), MECH_STATUS_OK);
    mech_rigid_motion_t motion = {p->exp_rotation, v3(1, 2, 3), v3(0.1, 0, 0), v3(0, 0.2, 0), v3(0, 0, 1), v3(0.3, 0, 0)};
    mech_vec3_t x = v3(0.5, 0.5, 0.5), xd = v3(1, 0, 0), xdd = v3(0, 1, 0);
    CHECK_STATUS(mech_velocity_field(&motion, &x, &p->velocity), MECH_STATUS_OK);
    CHECK_STATUS(mech_acceleration_field(&motion, &x, &p->acceleration), MECH_STATUS_OK);
    CHECK_STATUS(mech_relative_motion_decompose(&motion, &x, &xd, &xdd, &p->decomposition), MECH_STATUS_OK);
    mech_mat3_t rate;
    memset(&rate, 0, sizeof rate);
    rate.m[1] = 0.5, rate.m[3] = -0.5;
    mech_mat3_t identity = {{1, 0, 0, 0, 1, 0, 0, 0, 1}};
    CHECK_STATUS(mech_angular_velocity_from_rate(&identity, &rate, &p->omega_from_rate), MECH_STATUS_OK);
}

static mech_mass_properties_t sample_body(double mass, double offset) {
    mech_mass_properties_t b;
    memset(&b, 0, sizeof b);
    b.mass = mass;
    b.center_of_mass = v3(offset, 0.1, -0.2);
    b.inertia_about_com.m[0] = 0.4 * mass, b.inertia_about_com.m[4] = 0.5 * mass, b.inertia_about_com.m[8] = 0.6 * mass;
    b.inertia_about_com.m[1] = b.inertia_about_com.m[3] = 0.05 * mass;
    return b;
}

static void mass_calls(pass_t *p) {
    mech_mass_properties_t a = sample_body(2.0, 0.3), b = sample_body(0.5, -0.4);
    mech_quat_t q = {0.8, 0.6, 0.0, 0.0};
    mech_vec3_t t = v3(1.0, -2.0, 0.5), point = v3(0.2, 0.2, 0.2), dir = v3(1, 1, 0), vel = v3(1, 0, 2), w = v3(0, 3, 0);
    CHECK_STATUS(mech_mass_transform(&a, &q, &t, &p->moved), MECH_STATUS_OK);
    mech_mass_properties_t parts[2] = {a, b};
    CHECK_STATUS(mech_mass_combine(parts, NULL, NULL, 2, &p->combined), MECH_STATUS_OK);
    CHECK_STATUS(mech_mass_subtract(&p->combined, &b, &p->rest), MECH_STATUS_OK);
    CHECK_STATUS(mech_mass_inertia_about(&a, &point, &p->steiner), MECH_STATUS_OK);
    CHECK_STATUS(mech_mass_moment_about_line(&a, &point, &dir, &p->line_moment), MECH_STATUS_OK);
    CHECK_STATUS(mech_mass_principal_axes(&a, &p->moments, &p->axes), MECH_STATUS_OK);
    CHECK_STATUS(mech_mass_kinetic_energy(&a, &vel, &w, &p->energy, &p->momentum), MECH_STATUS_OK);
    CHECK_STATUS(mech_mass_angular_momentum(&a, &point, &vel, &w, &p->angular_momentum), MECH_STATUS_OK);
    CHECK_STATUS(mech_mass_point(3.0, &t, &p->point), MECH_STATUS_OK);
    const double dims[2] = {0.2, 1.5};
    CHECK_STATUS(mech_mass_primitive(MECH_PRIMITIVE_CYLINDER, dims, 2, MECH_AMOUNT_DENSITY, 7800.0, &p->primitive), MECH_STATUS_OK);
    CHECK_STATUS(mech_mass_check(&a, 0.0, &p->validity), MECH_STATUS_OK);
    mech_mass_properties_t bad = a;
    bad.inertia_about_com.m[8] = 2.0 * (a.inertia_about_com.m[0] + a.inertia_about_com.m[4]);
    CHECK_STATUS(mech_mass_repair(&bad, 0.0, &p->repaired, &p->repair_change), MECH_STATUS_OK);
    mech_mesh_options_t options;
    CHECK_STATUS(mech_mesh_options_default(&options), MECH_STATUS_OK);
    CHECK_STATUS(mech_mass_mesh(sphere_vertices, sphere_vertex_count, sphere_indices, sphere_triangle_count,
                                MECH_AMOUNT_DENSITY, 1000.0, &options, &p->mesh, &p->mesh_report),
                 MECH_STATUS_OK);
    mech_mass_properties_t again;
    CHECK_STATUS(mech_mass_mesh_same_connectivity(sphere_vertices, sphere_vertex_count, sphere_indices, sphere_triangle_count,
                                                  MECH_AMOUNT_DENSITY, 1000.0, NULL, &p->mesh_report, &again, NULL),
                 MECH_STATUS_OK);
    CHECK(memcmp(&again, &p->mesh, sizeof again) == 0);
}

static void impulse_calls(pass_t *p) {
    CHECK_STATUS(mech_collide_collinear(1.0, 2.0, 3.0, -1.0, 0.5, &p->collinear), MECH_STATUS_OK);
    mech_vec3_t v = v3(1, 2, 3), s = v3(-1, 0, 0.5), n = v3(0, 0, 1);
    CHECK_STATUS(mech_impulse_on_point(2.0, &v, &s, &p->point_impulse), MECH_STATUS_OK);
    mech_vec3_t v2 = v3(0, 0, -1);
    CHECK_STATUS(mech_collide_points(1.0, &v, 2.0, &v2, &n, 0.7, &p->point_impact), MECH_STATUS_OK);
    mech_mass_properties_t a = sample_body(2.0, 0.0);
    mech_vec3_t w = v3(0.1, -0.2, 0.3), contact_point = v3(0.0, 0.0, -0.5);
    CHECK_STATUS(mech_impulse_body_from_mass_properties(&a, &v2, &w, &p->body), MECH_STATUS_OK);
    mech_vec3_t no_moment = v3(0, 0, 0);
    CHECK_STATUS(mech_impulse_apply(&p->body, &s, &contact_point, &no_moment, &p->response), MECH_STATUS_OK);
    CHECK_STATUS(mech_impulse_fix_point(&p->body, &contact_point, &p->fixation), MECH_STATUS_OK);
    mech_impulse_body_t ground;
    memset(&ground, 0, sizeof ground);
    ground.constraint = MECH_BODY_FREE;
    mech_impulse_contact_t c;
    memset(&c, 0, sizeof c);
    c.point = contact_point;
    c.normal = v3(0, 0, 1);
    c.restitution = 0.5;
    c.friction = 0.4;
    c.law = MECH_RESTITUTION_STRONGE;
    c.tolerance = 1e-10;
    CHECK_STATUS(mech_impulse_resolve_contact(&ground, &p->body, &c, &p->impact), MECH_STATUS_OK);
    mech_multi_contact_options_t options;
    CHECK_STATUS(mech_multi_contact_options_default(&options), MECH_STATUS_OK);
}

static void modal_calls(pass_t *p, int big) {
    const double a[4] = {2.0, 0.5, 0.5, 1.0}, b[4] = {3.0, -1.0, -1.0, 2.0};
    CHECK_STATUS(mech_modal_check_pencil(2, a, b), MECH_STATUS_OK);
    CHECK_STATUS(mech_modal_count_below(2, a, b, 2.0, &p->below), MECH_STATUS_OK);
    const size_t ptr[3] = {0, 2, 4}, rows[4] = {0, 1, 0, 1};
    mech_modal_sparse_report_t report;
    CHECK_STATUS(mech_modal_sparse_lowest(2, ptr, rows, a, ptr, rows, b, 2, p->sparse_omega, p->sparse_bound, NULL, &report), MECH_STATUS_OK);
    mech_modal_sparse_options_t options;
    CHECK_STATUS(mech_modal_sparse_options_default(&options), MECH_STATUS_OK);
    options.count = 2;
    CHECK_STATUS(mech_modal_sparse_solve(2, ptr, rows, a, ptr, rows, b, &options, p->sparse_modes, NULL, &report, NULL), MECH_STATUS_OK);
    if (!big) return;
    mech_modal_options_t o;
    CHECK_STATUS(mech_modal_options_default(&o), MECH_STATUS_OK);
    o.vectors = 0;
    mech_modal_result_t *r = NULL;
    CHECK_STATUS(mech_modal_solve(BIG, big_a, big_b, &o, &r), MECH_STATUS_OK);
    CHECK_STATUS(mech_modal_result_eigenvalues(r, p->big_lambda, BIG), MECH_STATUS_OK);
    mech_modal_result_destroy(r);
}

/* A two-body chain (revolute joints) of the thread's own, a mechanism copied from it. */
static void handle_calls(pass_t *p) {
    mech_tree_t *tree = NULL;
    CHECK_STATUS(mech_tree_create(&tree), MECH_STATUS_OK);
    mech_mat3_t identity = {{1, 0, 0, 0, 1, 0, 0, 0, 1}};
    mech_vec3_t axis = v3(0, 1, 0), origin = v3(0, 0, 0), down = v3(0, 0, -1);
    size_t body = 0;
    CHECK_STATUS(mech_tree_add_body(tree, -1, MECH_JOINT_REVOLUTE, &axis, &identity, &origin, &body), MECH_STATUS_OK);
    CHECK_STATUS(mech_tree_add_body(tree, 0, MECH_JOINT_REVOLUTE, &axis, &identity, &down, &body), MECH_STATUS_OK);
    CHECK_STATUS(mech_tree_finalize(tree), MECH_STATUS_OK);
    size_t count = 0, dof = 0;
    CHECK_STATUS(mech_tree_size(tree, &count, &dof), MECH_STATUS_OK);
    CHECK(count == 2 && dof == 2);
    const double q[2] = {0.3, -0.5}, qd[2] = {1.0, 0.5};
    CHECK_STATUS(mech_tree_set_state(tree, q, qd, 2), MECH_STATUS_OK);
    mech_vec3_t omega, tip = v3(0, 0, -1);
    CHECK_STATUS(mech_tree_body_velocity(tree, 1, &tip, &omega, &p->tree_velocity), MECH_STATUS_OK);
    CHECK_STATUS(mech_tree_jacobian(tree, 1, MECH_JACOBIAN_POINT, &tip, p->jacobian, 6), MECH_STATUS_OK);
    mech_mass_properties_t bodies[2] = {sample_body(1.0, 0.0), sample_body(1.0, 0.0)};
    bodies[0].center_of_mass = v3(0, 0, -0.5), bodies[1].center_of_mass = v3(0, 0, -0.5);
    CHECK_STATUS(mech_tree_mass_matrix(tree, bodies, 2, p->mass_matrix, 2), MECH_STATUS_OK);
    double momenta[2];
    CHECK_STATUS(mech_tree_kinetic_energy(tree, bodies, 2, &p->tree_energy, momenta, 2), MECH_STATUS_OK);
    mech_mechanism_impulse_t hit = {1, v3(0, 0, -1), v3(0.5, 0, 0)};
    CHECK_STATUS(mech_impulse_mechanism_apply(tree, bodies, 2, &hit, 1, p->delta_q_dot, 2, &p->mechanism_response), MECH_STATUS_OK);

    mech_mechanism_t *m = NULL;
    CHECK_STATUS(mech_mechanism_create(tree, bodies, 2, &m), MECH_STATUS_OK);
    mech_tree_destroy(tree); /* the mechanism keeps its own copy */
    CHECK_STATUS(mech_mechanism_set_gravity(m, v3(0, 0, -9.81)), MECH_STATUS_OK);
    CHECK_STATUS(mech_mechanism_add_joint_spring(m, 1, 5.0, 0.0), MECH_STATUS_OK);
    CHECK_STATUS(mech_mechanism_potential(m, q, 2, &p->potential, p->gradient, NULL), MECH_STATUS_OK);
    CHECK_STATUS(mech_mechanism_equilibrium(m, q, 2, MECH_SEEK_MINIMUM, 0, 0.0, p->equilibrium, &p->equilibrium_report), MECH_STATUS_OK);
    double bounds[2], shapes[4];
    mech_modal_kind_t kinds[2];
    size_t found = 0;
    mech_stability_t stability;
    CHECK_STATUS(mech_mechanism_modes(m, p->equilibrium, 2, 0, p->mode_omega, bounds, kinds, shapes, &found, &stability), MECH_STATUS_OK);
    CHECK(found == 2);
    mech_mechanism_destroy(m);
}

/* Reads of the result every thread shares (const accessors only). */
static void shared_reads(pass_t *p) {
    size_t modes = 0, dim = 0;
    CHECK_STATUS(mech_modal_result_size(shared_result, &modes, &dim), MECH_STATUS_OK);
    CHECK(modes == BIG && dim == BIG);
    CHECK_STATUS(mech_modal_result_eigenvalues(shared_result, p->shared_lambda, BIG), MECH_STATUS_OK);
    mech_modal_accuracy_t accuracy;
    CHECK_STATUS(mech_modal_result_accuracy(shared_result, &accuracy), MECH_STATUS_OK);
    double delta0[BIG], delta_dot0[BIG];
    for (int i = 0; i < BIG; ++i) delta0[i] = 1e-3 * (i % 7), delta_dot0[i] = 0.0;
    const double time = 0.25;
    CHECK_STATUS(mech_modal_free_response(shared_result, delta0, delta_dot0, &time, 1, p->shared_delta, BIG, NULL, 0, NULL),
                 MECH_STATUS_OK);
}

/* Zeroes the padding between two members of a struct (the library copies whole structs, so
 * their padding bytes are unspecified), so that passes compare bytewise. */
#define ZERO_GAP(s, before, after)                                                      \
    memset((char *)&(s) + offsetof(__typeof__(s), before) + sizeof((s).before), 0,   \
           offsetof(__typeof__(s), after) - offsetof(__typeof__(s), before) - sizeof((s).before))

static void run_pass(pass_t *p, int big) {
    memset(p, 0, sizeof *p);
    kinematics_calls(p);
    mass_calls(p);
    impulse_calls(p);
    modal_calls(p, big);
    handle_calls(p);
    shared_reads(p);
    ZERO_GAP(p->body, constraint, hinge_point);
    ZERO_GAP(p->impact, mode, velocity_after_1);
    for (int k = 0; k < 2; ++k) ZERO_GAP(p->sparse_modes[k], kind, group);
}

/* The offset of the first byte in which two passes differ (sizeof(pass_t) when none does). */
static size_t first_difference(const pass_t *a, const pass_t *b) {
    const unsigned char *x = (const unsigned char *)a, *y = (const unsigned char *)b;
    for (size_t i = 0; i < sizeof *a; ++i) {
        if (x[i] != y[i]) {
            fprintf(stderr, "passes differ at byte %zu of %zu\n", i, sizeof *a);
            return i;
        }
    }
    return sizeof *a;
}

/* Checks that this thread's last error is the one its own failed call left. */
static void own_last_error(int id) {
    char expected[64], message[512];
    snprintf(expected, sizeof expected, "%d", -(id + 2));
    mech_collinear_impact_t out;
    CHECK_STATUS(mech_collide_collinear((double)-(id + 2), 1.0, 1.0, 0.0, 0.5, &out), MECH_STATUS_INVALID_ARGUMENT);
    size_t length = mech_last_error(message, sizeof message);
    CHECK(length > 0 && length < sizeof message);
    CHECK(strstr(message, expected) != NULL);
}

static void *worker(void *arg) {
    int id = (int)(intptr_t)arg;
    pass_t *mine = malloc(sizeof *mine);
    CHECK(mine != NULL);
    CHECK(mech_abi_version() == MECH_ABI_VERSION);
    CHECK(strlen(mech_version()) >= 5);
    CHECK(mech_features() != 0 && strlen(mech_status_str(MECH_STATUS_SINGULAR)) > 0);
    pthread_barrier_wait(&start_line);
    for (int round = 0; round < ROUNDS; ++round) {
        own_last_error(id);
        run_pass(mine, round == 0 || id % 2 == 0);
        if (round > 0 && id % 2 == 1) memcpy(mine->big_lambda, reference.big_lambda, sizeof mine->big_lambda);
        CHECK(first_difference(mine, &reference) == sizeof reference);
        if (id == 0) mech_modal_release_scratch();
        CHECK(mech_selftest_panic_boundary() == MECH_STATUS_PANIC);
        own_last_error(id);
    }
    free(mine);
    return NULL;
}

int main(void) {
    big_pencil();
    sphere_mesh();
    mech_modal_options_t o;
    CHECK_STATUS(mech_modal_options_default(&o), MECH_STATUS_OK);
    mech_modal_result_t *shared = NULL;
    CHECK_STATUS(mech_modal_solve(BIG, big_a, big_b, &o, &shared), MECH_STATUS_OK);
    shared_result = shared;
    run_pass(&reference, 1);
    CHECK(reference.mesh_report.triangles == sphere_triangle_count && sphere_triangle_count >= 65536);

    pthread_t threads[THREADS];
    CHECK(pthread_barrier_init(&start_line, NULL, THREADS) == 0);
    for (int i = 0; i < THREADS; ++i) CHECK(pthread_create(&threads[i], NULL, worker, (void *)(intptr_t)i) == 0);
    for (int i = 0; i < THREADS; ++i) CHECK(pthread_join(threads[i], NULL) == 0);
    pthread_barrier_destroy(&start_line);
    mech_modal_result_destroy(shared);
    free(sphere_vertices);
    free(sphere_indices);
    (void)mech_check_count;
    printf("test_threads: %d threads x %d rounds agree bit for bit with the single-threaded pass\n", THREADS, ROUNDS);
    return 0;
}
