/* The C ABI spine: versions, features, status strings, the last-error message, the panic
 * boundary, and one example of each kind of rejected argument. */
#include "check.h"

#include <stdint.h>

static void versions_agree(void) {
    char expected[64];
    snprintf(expected, sizeof expected, "%d.%d.%d", MECH_VERSION_MAJOR, MECH_VERSION_MINOR, MECH_VERSION_PATCH);
    CHECK(strcmp(mech_version(), expected) == 0);
    CHECK(mech_abi_version() == MECH_ABI_VERSION);
    CHECK(mech_features() == (MECH_FEATURE_BIT_KINEMATICS | MECH_FEATURE_BIT_MASS | MECH_FEATURE_BIT_IMPULSE |
                              MECH_FEATURE_BIT_MODAL | MECH_FEATURE_BIT_MECHANISM | MECH_FEATURE_BIT_DYNAMICS |
                              MECH_FEATURE_BIT_MOTION | MECH_FEATURE_BIT_URDF));
}

static void status_strings(void) {
    const mech_status_t all[] = {MECH_STATUS_OK,           MECH_STATUS_NULL_POINTER,
                                 MECH_STATUS_MISALIGNED_POINTER, MECH_STATUS_NON_FINITE,
                                 MECH_STATUS_BAD_DIMENSION, MECH_STATUS_BAD_ENUM,
                                 MECH_STATUS_INVALID_ARGUMENT, MECH_STATUS_NOT_POSITIVE_DEFINITE,
                                 MECH_STATUS_SINGULAR,     MECH_STATUS_NOT_CONVERGED,
                                 MECH_STATUS_BUFFER_TOO_SMALL, MECH_STATUS_IO_ERROR,
                                 MECH_STATUS_PARSE_ERROR,  MECH_STATUS_PANIC};
    const size_t n = sizeof all / sizeof all[0];
    for (size_t i = 0; i < n; ++i) {
        const char *s = mech_status_str(all[i]);
        CHECK(s != NULL && strlen(s) > 0);
        CHECK(strcmp(s, "unknown status") != 0);
        for (size_t j = 0; j < i; ++j) CHECK(strcmp(s, mech_status_str(all[j])) != 0);
    }
    CHECK(strcmp(mech_status_str(-12345), "unknown status") == 0);
    CHECK(strcmp(mech_status_str(INT32_MAX), "unknown status") == 0);
}

static void panic_boundary_and_last_error(void) {
    CHECK_STATUS(mech_selftest_panic_boundary(), MECH_STATUS_PANIC);
    size_t len = mech_last_error(NULL, 0);
    CHECK(len > 0);
    char small[8];
    FILL_SENTINEL(small, sizeof small);
    CHECK(mech_last_error(small, sizeof small) == len);
    CHECK(small[7] == '\0' && strlen(small) == 7);
    char big[512];
    CHECK(mech_last_error(big, sizeof big) == len);
    CHECK(strstr(big, "deliberate panic") != NULL);
    /* capacity 0 with a non-NULL buffer writes nothing */
    FILL_SENTINEL(small, sizeof small);
    CHECK(mech_last_error(small, 0) == len);
    CHECK(mech_untouched(small, sizeof small));
}

/* One example of each kind of bad argument, through real entry points. Each capability's own
 * test file covers every function's error paths. */
static void each_kind_of_bad_argument(void) {
    mech_quat_t q;
    FILL_SENTINEL(&q, sizeof q);
    CHECK_STATUS(mech_quat_from_rotation_matrix(NULL, &q), MECH_STATUS_NULL_POINTER);
    CHECK(mech_untouched(&q, sizeof q));

    /* a misaligned input pointer */
    union {
        double align;
        unsigned char bytes[sizeof(mech_mat3_t) + 8];
    } storage;
    memset(&storage, 0, sizeof storage);
    const mech_mat3_t *misaligned = (const mech_mat3_t *)(void *)(storage.bytes + 1);
    CHECK_STATUS(mech_quat_from_rotation_matrix(misaligned, &q), MECH_STATUS_MISALIGNED_POINTER);
    CHECK(mech_untouched(&q, sizeof q));

    mech_mat3_t r = {{1, 0, 0, 0, 1, 0, 0, 0, 1}};
    r.m[4] = NAN;
    CHECK_STATUS(mech_quat_from_rotation_matrix(&r, &q), MECH_STATUS_NON_FINITE);
    CHECK(mech_untouched(&q, sizeof q));
    char msg[256];
    mech_last_error(msg, sizeof msg);
    CHECK(strstr(msg, "rotation") != NULL);

    mech_quat_t unit = {1, 0, 0, 0};
    mech_mat3_t out;
    FILL_SENTINEL(&out, sizeof out);
    CHECK_STATUS(mech_rotation_matrix_from_quat(&unit, 7, &out), MECH_STATUS_BAD_ENUM);
    CHECK_STATUS(mech_rotation_matrix_from_quat(&unit, -1, &out), MECH_STATUS_BAD_ENUM);
    CHECK(mech_untouched(&out, sizeof out));

    const double a[1] = {1.0};
    CHECK_STATUS(mech_modal_check_pencil(0, a, a), MECH_STATUS_BAD_DIMENSION);
    CHECK_STATUS(mech_modal_check_pencil(SIZE_MAX, a, a), MECH_STATUS_BAD_DIMENSION);

    mech_collinear_impact_t impact;
    FILL_SENTINEL(&impact, sizeof impact);
    CHECK_STATUS(mech_collide_collinear(1.0, 1.0, 1.0, 0.0, 1.5, &impact), MECH_STATUS_INVALID_ARGUMENT);
    CHECK(mech_untouched(&impact, sizeof impact));
}

int main(void) {
    versions_agree();
    status_strings();
    panic_boundary_and_last_error();
    each_kind_of_bad_argument();
    return CHECK_DONE();
}
