// The C++ header mechanica.hpp: a double pendulum of point masses read from URDF into RAII
// handles; modes, mass matrix and inverse dynamics against closed forms; errors thrown as
// mechanica::error with the status and the library's message.
#include "check.h"
#include "mechanica.hpp"

#include <cmath>
#include <string>
#include <vector>

namespace {

constexpr double g = 9.81, l = 0.5;

// Two point masses of 1 kg, each l below its joint, on revolute joints about y.
const std::string pendulum =
    "<robot name=\"pendulum\"><link name=\"base\"/>"
    "<link name=\"upper\"><inertial><origin xyz=\"0 0 -0.5\"/><mass value=\"1\"/>"
    "<inertia ixx=\"0\" ixy=\"0\" ixz=\"0\" iyy=\"0\" iyz=\"0\" izz=\"0\"/></inertial></link>"
    "<link name=\"lower\"><inertial><origin xyz=\"0 0 -0.5\"/><mass value=\"1\"/>"
    "<inertia ixx=\"0\" ixy=\"0\" ixz=\"0\" iyy=\"0\" iyz=\"0\" izz=\"0\"/></inertial></link>"
    "<joint name=\"shoulder\" type=\"continuous\"><parent link=\"base\"/><child link=\"upper\"/>"
    "<axis xyz=\"0 1 0\"/></joint>"
    "<joint name=\"elbow\" type=\"continuous\"><parent link=\"upper\"/><child link=\"lower\"/>"
    "<origin xyz=\"0 0 -0.5\"/><axis xyz=\"0 1 0\"/></joint></robot>";

void names_and_modes() {
    auto tree = mechanica::tree::from_urdf_string(pendulum);
    CHECK(tree.body_count() == 3 && tree.dof() == 2);
    CHECK(tree.link_name(1) == "upper" && tree.joint_name(2) == "elbow" && tree.joint_name(0).empty());
    CHECK(tree.coordinate_name(0) == "shoulder");
    auto m = mechanica::mechanism::from_urdf_string(pendulum);
    CHECK(m.dof() == 2 && m.link_name(2) == "lower" && m.coordinate_name(1) == "elbow");
    const std::vector<double> q0{0.1, -0.2};
    mechanica::matrix q = m.equilibrium(q0);
    CHECK(q.rows() == 2 && q.cols() == 1);
    CHECK_NEAR(q[0], 0.0, 1e-10);
    CHECK_NEAR(q[1], 0.0, 1e-10);
    mechanica::mechanism_modes modes = m.modes({q.data(), q.size()});
    CHECK(modes.omega_sq.rows() == 2 && modes.shapes.rows() == 2 && modes.shapes.cols() == 2);
    CHECK_NEAR(modes.omega_sq[0], (2.0 - std::sqrt(2.0)) * g / l, 1e-12);
    CHECK_NEAR(modes.omega_sq[1], (2.0 + std::sqrt(2.0)) * g / l, 1e-12);
    // The lowest mode: absolute angles in the ratio √2, so q2/q1 = √2 − 1.
    CHECK_NEAR(modes.shapes(1, 0) / modes.shapes(0, 0), std::sqrt(2.0) - 1.0, 1e-10);
    CHECK(modes.stability.unstable_directions == 0);

    // Moving a handle transfers it; the moved-from handle holds nothing.
    mechanica::mechanism moved = std::move(m);
    CHECK(m.get() == nullptr && moved.get() != nullptr);
}

void dynamics_closed_forms() {
#if defined(MECH_FEATURE_DYNAMICS)
    auto m = mechanica::mechanism::from_urdf_string(pendulum);
    auto d = mechanica::dynamics::create(m);
    CHECK(d.dof() == 2);
    const std::vector<double> q{0.3, -0.7}, zero{0.0, 0.0};
    // A(q) of two point masses: A11 = l² + (l² + l² + 2l² cos q2), A12 = l² + l² cos q2, A22 = l².
    mechanica::matrix a = d.mass_matrix(q);
    const double c = std::cos(q[1]);
    CHECK(a.rows() == 2 && a.cols() == 2);
    CHECK_NEAR(a(0, 0), l * l * (3.0 + 2.0 * c), 1e-13);
    CHECK_NEAR(a(0, 1), l * l * (1.0 + c), 1e-13);
    CHECK_NEAR(a(1, 0), a(0, 1), 0.0);
    CHECK_NEAR(a(1, 1), l * l, 1e-13);
    // At rest τ = ∂U/∂q with U = −m g l (2 cos q1 + cos(q1 + q2)) (a rotation about +y turns the
    // hanging point (0, 0, −l) to (−l sin q, 0, −l cos q)).
    mechanica::matrix tau = d.rnea(q, zero, zero);
    const double t2 = g * l * std::sin(q[0] + q[1]), t1 = t2 + 2.0 * g * l * std::sin(q[0]);
    CHECK_NEAR(tau[1], t2, 1e-12);
    CHECK_NEAR(tau[0], t1, 1e-12);
    // Forward dynamics inverts it: with τ = RNEA(q, 0, q̈) the recursion returns q̈.
    const std::vector<double> qdd{0.4, -1.1};
    mechanica::matrix tau_q = d.rnea(q, zero, qdd);
    mechanica::matrix back = d.aba(q, zero, {tau_q.data(), tau_q.size()});
    CHECK_NEAR(back[0], qdd[0], 1e-12);
    CHECK_NEAR(back[1], qdd[1], 1e-12);
#endif
}

void modal_solve() {
    // A = diag(1, 2), B = diag(8, 2): ω² = 8 and 1.
    const std::vector<double> a{1.0, 0.0, 0.0, 2.0}, b{8.0, 0.0, 0.0, 2.0};
    auto result = mechanica::modal_result::solve(2, a, b);
    CHECK(result.modes() == 2 && result.dim() == 2);
    mechanica::matrix lambda = result.eigenvalues();
    const double lo = std::fmin(std::fabs(lambda[0]), std::fabs(lambda[1]));
    const double hi = std::fmax(std::fabs(lambda[0]), std::fabs(lambda[1]));
    CHECK_NEAR(lo, 1.0, 1e-14);
    CHECK_NEAR(hi, 8.0, 1e-14);
    CHECK(result.vectors().rows() == 2);
}

void errors_are_thrown() {
    std::string broken = pendulum;
    broken.replace(broken.find("ixx=\"0\""), 7, "ixx=\"5\"");
    bool thrown = false;
    try {
        mechanica::mechanism::from_urdf_string(broken);
    } catch (const mechanica::error &e) {
        thrown = true;
        CHECK(e.status() == MECH_STATUS_INVALID_ARGUMENT);
        CHECK(std::string(e.what()).find("link \"upper\"") != std::string::npos);
    }
    CHECK(thrown);
    thrown = false;
    try {
        mechanica::tree::from_urdf("/nonexistent/robot.urdf");
    } catch (const mechanica::error &e) {
        thrown = e.status() == MECH_STATUS_IO_ERROR;
    }
    CHECK(thrown);
}

}  // namespace

int main() {
    names_and_modes();
    dynamics_closed_forms();
    modal_solve();
    errors_are_thrown();
    return CHECK_DONE();
}
