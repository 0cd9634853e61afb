/* Free rigid body C ABI: the exact motion against the closed form of an axisymmetric body
 * (ω⊥ turning at λ = (C − A) ω₃ / A in the body) and against the invariants of an asymmetric
 * one (energy, |L|, and L = R I ω fixed in space); the Lie-group integration against the exact
 * motion within its own estimate; rejected arguments leaving the outputs untouched. */
#include "check.h"

static mech_free_body_state_t start(double w1, double w2, double w3) {
    mech_free_body_state_t s;
    memset(&s, 0, sizeof s);
    s.rotation.m[0] = s.rotation.m[4] = s.rotation.m[8] = 1.0;
    s.omega.x = w1;
    s.omega.y = w2;
    s.omega.z = w3;
    return s;
}

/* L in space: R (I ω). */
static void space_momentum(const mech_vec3_t *moments, const mech_free_body_state_t *s, double out[3]) {
    const double l[3] = {moments->x * s->omega.x, moments->y * s->omega.y, moments->z * s->omega.z};
    for (int r = 0; r < 3; ++r) out[r] = s->rotation.m[r] * l[0] + s->rotation.m[r + 3] * l[1] + s->rotation.m[r + 6] * l[2];
}

/* The angle θ of Aᵀ B for two rotations: ‖A − B‖_F = 2√2 sin(θ/2), accurate for small θ
 * (unlike the arccosine of the trace). */
static double angle_between(const mech_mat3_t *a, const mech_mat3_t *b) {
    double sum = 0.0;
    for (int k = 0; k < 9; ++k) sum += (a->m[k] - b->m[k]) * (a->m[k] - b->m[k]);
    double half = sqrt(sum) / (2.0 * sqrt(2.0));
    return 2.0 * asin(half > 1.0 ? 1.0 : half);
}

static void axisymmetric(void) {
    const double a = 2.0, c = 3.5, w1 = 0.3, w2 = -0.7, w3 = 1.9;
    const mech_vec3_t moments = {a, a, c};
    const mech_free_body_state_t s0 = start(w1, w2, w3);
    const double lambda = (c - a) * w3 / a;
    for (double t = 0.0; t < 20.0; t += 1.37) {
        mech_free_body_state_t s;
        CHECK_STATUS(mech_free_body_exact(&moments, &s0, t, &s), MECH_STATUS_OK);
        const double cs = cos(lambda * t), sn = sin(lambda * t);
        CHECK(fabs(s.omega.x - (w1 * cs - w2 * sn)) <= 1e-13 * (1.0 + t));
        CHECK(fabs(s.omega.y - (w1 * sn + w2 * cs)) <= 1e-13 * (1.0 + t));
        CHECK(fabs(s.omega.z - w3) <= 1e-14);
    }
}

static void asymmetric_invariants_and_integration(void) {
    const mech_vec3_t moments = {1.0, 2.0, 3.0};
    /* Near the separatrix 2 B T = Γ²: ω mostly about the middle axis. */
    const mech_free_body_state_t s0 = start(0.02, 1.0, 0.03);
    double l0[3];
    space_momentum(&moments, &s0, l0);
    const double energy0 = 0.5 * (1.0 * 0.02 * 0.02 + 2.0 * 1.0 + 3.0 * 0.03 * 0.03);
    const double tolerances[] = {1e-6, 1e-9};
    const mech_lie_method_t methods[] = {MECH_LIE_SPLITTING4, MECH_LIE_SPLITTING6, MECH_LIE_RKMK4};
    for (double t = 3.0; t < 40.0; t += 11.0) {
        mech_free_body_state_t exact;
        CHECK_STATUS(mech_free_body_exact(&moments, &s0, t, &exact), MECH_STATUS_OK);
        double l[3];
        space_momentum(&moments, &exact, l);
        for (int r = 0; r < 3; ++r) CHECK(fabs(l[r] - l0[r]) <= 1e-12);
        const double energy = 0.5 * (exact.omega.x * exact.omega.x + 2.0 * exact.omega.y * exact.omega.y +
                                     3.0 * exact.omega.z * exact.omega.z);
        CHECK(fabs(energy - energy0) <= 1e-13);
        for (int m = 0; m < 3; ++m) {
            for (int k = 0; k < 2; ++k) {
                mech_free_body_state_t s;
                mech_free_body_report_t rep;
                CHECK_STATUS(mech_free_body_integrate(&moments, &s0, t, methods[m], 0.05, tolerances[k], &s, &rep),
                             MECH_STATUS_OK);
                CHECK(rep.attitude_error <= tolerances[k] && rep.omega_error <= tolerances[k]);
                CHECK(rep.steps > 0);
                /* The estimate compares two runs; allow the true error a margin of 10. */
                CHECK(angle_between(&exact.rotation, &s.rotation) <= 10.0 * tolerances[k]);
            }
        }
    }
}

static void rejected(void) {
    const mech_vec3_t moments = {1.0, 2.0, 3.0};
    const mech_free_body_state_t s0 = start(0.1, 0.2, 0.3);
    mech_free_body_state_t s;
    mech_free_body_report_t rep;
    FILL_SENTINEL(&s, sizeof s);
    FILL_SENTINEL(&rep, sizeof rep);
    const mech_vec3_t zero_moment = {1.0, 0.0, 3.0};
    CHECK_STATUS(mech_free_body_exact(&zero_moment, &s0, 1.0, &s), MECH_STATUS_INVALID_ARGUMENT);
    CHECK_STATUS(mech_free_body_exact(&moments, &s0, NAN, &s), MECH_STATUS_NON_FINITE);
    mech_free_body_state_t skewed = s0;
    skewed.rotation.m[1] = 0.1;
    CHECK_STATUS(mech_free_body_exact(&moments, &skewed, 1.0, &s), MECH_STATUS_INVALID_ARGUMENT);
    CHECK_STATUS(mech_free_body_exact(NULL, &s0, 1.0, &s), MECH_STATUS_NULL_POINTER);
    CHECK_STATUS(mech_free_body_integrate(&moments, &s0, 1.0, 9, 0.1, 1e-8, &s, &rep), MECH_STATUS_BAD_ENUM);
    CHECK_STATUS(mech_free_body_integrate(&moments, &s0, 1.0, MECH_LIE_SPLITTING6, 0.1, 0.0, &s, &rep),
                 MECH_STATUS_INVALID_ARGUMENT);
    CHECK_STATUS(mech_free_body_integrate(&moments, &s0, -1.0, MECH_LIE_SPLITTING6, 0.1, 1e-8, &s, &rep),
                 MECH_STATUS_INVALID_ARGUMENT);
    CHECK_STATUS(mech_free_body_integrate(&moments, &s0, 1.0, MECH_LIE_SPLITTING6, 0.0, 1e-8, &s, &rep),
                 MECH_STATUS_INVALID_ARGUMENT);
    CHECK_STATUS(mech_free_body_integrate(&moments, &s0, 1.0, MECH_LIE_SPLITTING6, 0.1, 1e-8, &s, NULL),
                 MECH_STATUS_NULL_POINTER);
    /* A tolerance below the rounding floor: the estimate stops falling long before 2^30 steps. */
    CHECK_STATUS(mech_free_body_integrate(&moments, &s0, 50.0, MECH_LIE_RKMK4, 0.05, 1e-18, &s, &rep),
                 MECH_STATUS_NOT_CONVERGED);
    CHECK(mech_untouched(&s, sizeof s));
    CHECK(mech_untouched(&rep, sizeof rep));
}

int main(void) {
    axisymmetric();
    asymmetric_invariants_and_integration();
    rejected();
    printf("test_free_body: %d checks passed\n", mech_check_count);
    return 0;
}
