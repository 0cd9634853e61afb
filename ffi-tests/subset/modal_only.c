/* Built against a library compiled with only the `modal` cargo feature, with
 * -DMECH_FEATURES_EXPLICIT -DMECH_FEATURE_MODAL. */
#include "check.h"

#if defined(MECH_FEATURE_KINEMATICS) || defined(MECH_FEATURE_MASS) || defined(MECH_FEATURE_IMPULSE)
#error "only MECH_FEATURE_MODAL should be defined for this program"
#endif

int main(void) {
    CHECK(mech_features() == MECH_FEATURE_BIT_MODAL);
    CHECK(mech_abi_version() == MECH_ABI_VERSION);
    const double a[4] = {2.0, 0.0, 0.0, 1.0};
    const double b[4] = {3.0, -1.0, -1.0, 3.0};
    CHECK_STATUS(mech_modal_check_pencil(2, a, b), MECH_STATUS_OK);
    return CHECK_DONE();
}
