/* The smallest C program using an installed mechanica (see README, "Using it from C and C++"). */
#include <mechanica.h>
#include <stdio.h>

int main(void) {
    if (mech_abi_version() != MECH_ABI_VERSION) {
        fprintf(stderr, "header and library ABI versions differ\n");
        return 1;
    }
    /* A quarter turn about z, as a quaternion, to a rotation matrix (column-major). */
    const mech_quat_t q = {0.7071067811865476, 0.0, 0.0, 0.7071067811865476};
    mech_mat3_t r;
    mech_status_t status = mech_rotation_matrix_from_quat(&q, MECH_QUAT_REQUIRE_UNIT, &r);
    if (status != MECH_STATUS_OK) {
        fprintf(stderr, "mechanica: %s\n", mech_status_str(status));
        return 1;
    }
    printf("mechanica %s: R e_x = (%.3f, %.3f, %.3f)\n", mech_version(), r.m[0], r.m[1], r.m[2]);
    return (r.m[1] > 0.999999) ? 0 : 1;
}
