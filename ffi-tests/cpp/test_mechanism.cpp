// A C++17 program that builds a small mechanism — a triple pendulum of equal point masses —
// through the C ABI, finds its equilibrium and prints its modes, checking them against the
// roots of μ³ − 9μ² + 18μ − 6 = 0 (μ = ω² l / g).
#include "check.h"

#include <array>
#include <cstdio>
#include <memory>
#include <vector>

namespace {

struct TreeDeleter {
    void operator()(mech_tree_t *t) const { mech_tree_destroy(t); }
};
struct MechanismDeleter {
    void operator()(mech_mechanism_t *m) const { mech_mechanism_destroy(m); }
};

double cubic(double mu) { return ((mu - 9.0) * mu + 18.0) * mu - 6.0; }

}  // namespace

int main() {
    constexpr double g = 9.81, l = 0.6, m = 2.0;
    mech_tree_t *raw_tree = nullptr;
    CHECK_STATUS(mech_tree_create(&raw_tree), MECH_STATUS_OK);
    std::unique_ptr<mech_tree_t, TreeDeleter> tree(raw_tree);
    const mech_vec3_t axis{0.0, 1.0, 0.0};
    const mech_mat3_t identity{{1, 0, 0, 0, 1, 0, 0, 0, 1}};
    for (int i = 0; i < 3; ++i) {
        const mech_vec3_t origin{0.0, 0.0, i == 0 ? 0.0 : -l};
        size_t body = 0;
        CHECK_STATUS(mech_tree_add_body(tree.get(), i - 1, MECH_JOINT_REVOLUTE, &axis, &identity, &origin, &body),
                     MECH_STATUS_OK);
    }
    CHECK_STATUS(mech_tree_finalize(tree.get()), MECH_STATUS_OK);
    std::array<mech_mass_properties_t, 3> bodies{};
    for (auto &b : bodies) {
        b.mass = m;
        b.center_of_mass = mech_vec3_t{0.0, 0.0, -l};
    }
    mech_mechanism_t *raw = nullptr;
    CHECK_STATUS(mech_mechanism_create(tree.get(), bodies.data(), bodies.size(), &raw), MECH_STATUS_OK);
    std::unique_ptr<mech_mechanism_t, MechanismDeleter> mechanism(raw);
    CHECK_STATUS(mech_mechanism_set_gravity(mechanism.get(), mech_vec3_t{0.0, 0.0, -g}), MECH_STATUS_OK);

    const std::vector<double> start{0.2, -0.1, 0.3};
    std::vector<double> q(3);
    mech_equilibrium_report_t report{};
    CHECK_STATUS(mech_mechanism_equilibrium(mechanism.get(), start.data(), 3, MECH_SEEK_MINIMUM, 0, 0.0, q.data(),
                                            &report),
                 MECH_STATUS_OK);
    std::printf("equilibrium q = (%.3e, %.3e, %.3e), |grad U*| = %.2e after %zu iterations\n", q[0], q[1], q[2],
                report.gradient_norm, report.iterations);

    std::vector<double> omega_sq(3), bounds(3), shapes(9);
    std::vector<mech_modal_kind_t> kinds(3);
    size_t found = 0;
    mech_stability_t stability{};
    CHECK_STATUS(mech_mechanism_modes(mechanism.get(), q.data(), 3, 0, omega_sq.data(), bounds.data(), kinds.data(),
                                      shapes.data(), &found, &stability),
                 MECH_STATUS_OK);
    CHECK(found == 3 && stability.unstable_directions == 0 && stability.zero_modes == 0);
    for (size_t k = 0; k < found; ++k) {
        const double mu = omega_sq[k] * l / g;
        std::printf("mode %zu: f = %.6f Hz (omega^2 = %.12e +- %.1e), shape (%.3f, %.3f, %.3f)\n", k + 1,
                    std::sqrt(omega_sq[k]) / (2.0 * 3.14159265358979323846), omega_sq[k], bounds[k], shapes[3 * k], shapes[3 * k + 1],
                    shapes[3 * k + 2]);
        CHECK(kinds[k] == MECH_MODAL_KIND_OSCILLATORY);
        CHECK(std::abs(cubic(mu)) <= 1e-11);
    }
    return CHECK_DONE();
}
