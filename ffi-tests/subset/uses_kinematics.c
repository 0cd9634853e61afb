/* Must NOT compile with -DMECH_FEATURES_EXPLICIT -DMECH_FEATURE_MODAL: the kinematics
 * declarations are guarded out of the header. Compiles and runs with the default header. */
#include "check.h"

int main(void) {
    mech_mat3_t r = {{1, 0, 0, 0, 1, 0, 0, 0, 1}};
    mech_quat_t q;
    CHECK_STATUS(mech_quat_from_rotation_matrix(&r, &q), MECH_STATUS_OK);
    CHECK_NEAR(q.w, 1.0, 1e-15);
    return CHECK_DONE();
}
