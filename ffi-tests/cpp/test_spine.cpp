// The header used from C++17: the same declarations, usable with RAII and std containers.
#include "check.h"

#include <array>
#include <string>
#include <vector>

namespace {

std::string last_error() {
    std::string message(mech_last_error(nullptr, 0), '\0');
    std::vector<char> buffer(message.size() + 1);
    mech_last_error(buffer.data(), buffer.size());
    return std::string(buffer.data());
}

}  // namespace

int main() {
    CHECK(std::string(mech_version()) == std::to_string(MECH_VERSION_MAJOR) + "." +
                                             std::to_string(MECH_VERSION_MINOR) + "." +
                                             std::to_string(MECH_VERSION_PATCH));
    CHECK(mech_abi_version() == MECH_ABI_VERSION);

    // A quarter turn about z: quaternion and back.
    const double h = std::sqrt(0.5);
    const mech_quat_t q{h, 0.0, 0.0, h};
    mech_mat3_t r{};
    CHECK_STATUS(mech_rotation_matrix_from_quat(&q, MECH_QUAT_REQUIRE_UNIT, &r), MECH_STATUS_OK);
    CHECK_NEAR(r.m[1], 1.0, 1e-15);   // R e_x = e_y: column 0 is (0, 1, 0)
    CHECK_NEAR(r.m[3], -1.0, 1e-15);  // R e_y = -e_x
    mech_quat_t back{};
    CHECK_STATUS(mech_quat_from_rotation_matrix(&r, &back), MECH_STATUS_OK);
    CHECK_NEAR(std::abs(back.w * q.w + back.z * q.z), 1.0, 1e-15);

    // A detailed message survives into C++ strings.
    const mech_quat_t twice{2.0, 0.0, 0.0, 0.0};
    CHECK_STATUS(mech_rotation_matrix_from_quat(&twice, MECH_QUAT_REQUIRE_UNIT, &r), MECH_STATUS_INVALID_ARGUMENT);
    CHECK(last_error().find("norm = 2") != std::string::npos);

    // Column-major matrices from std::array.
    const std::array<double, 4> a{1.0, 0.0, 0.0, 1.0};
    const std::array<double, 4> b{2.0, -1.0, -1.0, 2.0};
    CHECK_STATUS(mech_modal_check_pencil(2, a.data(), b.data()), MECH_STATUS_OK);
    CHECK_STATUS(mech_selftest_panic_boundary(), MECH_STATUS_PANIC);
    return CHECK_DONE();
}
