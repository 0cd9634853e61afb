// A C++17 program on the damped modes of the dynamics C ABI, with the handles of mechanica.hpp:
// a double pendulum hung from a spherical joint (rotation-vector coordinates) with a revolute
// joint below, gravity and a dashpot to the ground, at random configurations q0 away from
// φ = 0. The linearization needs the rotation vectors at φ = 0, which the library reaches by
// re-centring a copy: the handle must keep its charts, so the count query and two full calls
// with the same q0 agree bit for bit, and the mass matrix at q0 is the same before and after.
#include "check.h"
#include "mechanica.hpp"

#include <array>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <random>
#include <vector>

namespace {

mechanica::mechanism spherical_double_pendulum(std::mt19937_64 &rng) {
    std::uniform_real_distribution<double> unit(-1.0, 1.0), positive(0.2, 2.0);
    const mech_mat3_t identity{{1, 0, 0, 0, 1, 0, 0, 0, 1}};
    mechanica::tree tree = mechanica::tree::create();
    const double ax = unit(rng), ay = unit(rng), norm = std::sqrt(ax * ax + ay * ay + 1.0);
    const mech_vec3_t axis{ax / norm, ay / norm, 1.0 / norm};
    const mech_vec3_t origin{0.0, 0.0, 0.0}, below{0.1 * unit(rng), 0.1 * unit(rng), -positive(rng)};
    CHECK(tree.add_body(-1, MECH_JOINT_SPHERICAL, nullptr, identity, origin) == 0);
    CHECK(tree.add_body(0, MECH_JOINT_REVOLUTE, &axis, identity, below) == 1);
    tree.finalize();
    std::vector<mech_mass_properties_t> bodies(2);
    for (auto &b : bodies) {
        b = mech_mass_properties_t{};
        b.mass = positive(rng);
        b.center_of_mass = mech_vec3_t{0.2 * unit(rng), 0.2 * unit(rng), -positive(rng)};
        // A box of half-sides h: moments m(h₁² + h₂²)/3 and so on (triangle inequalities hold).
        const double h[3] = {0.3 * positive(rng), 0.3 * positive(rng), 0.3 * positive(rng)};
        for (int k = 0; k < 3; ++k) {
            const double p = h[(k + 1) % 3], q = h[(k + 2) % 3];
            b.inertia_about_com.m[4 * k] = b.mass * (p * p + q * q) / 3.0;
        }
    }
    mechanica::mechanism m = mechanica::mechanism::create(tree, bodies);
    m.set_gravity(mech_vec3_t{0.0, 0.0, -9.81});
    return m;
}

/// Every field of a record (the struct has padding, which is not compared).
std::vector<double> fields(const mech_damped_mode_t &m) {
    return {double(m.kind),    double(m.eigenvalue_count), m.natural_frequency, m.damped_frequency,
            m.damping_ratio,   m.s_re[0],                  m.s_re[1],           m.s_im[0],
            m.s_im[1],         m.error_bound[0],           m.error_bound[1],    m.backward_error[0],
            m.backward_error[1]};
}

bool same_bits(const std::vector<double> &a, const std::vector<double> &b) {
    return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(double)) == 0;
}

}  // namespace

int main() {
    std::mt19937_64 rng(77);
    std::uniform_real_distribution<double> angle(-1.5, 1.5);
    int compared = 0;
    for (int trial = 0; trial < 12; ++trial) {
        mechanica::mechanism m = spherical_double_pendulum(rng);
        mechanica::dynamics d = mechanica::dynamics::create(m);
        CHECK(d.dof() == 4);
        const mech_vec3_t hook{0.3, -0.2, 0.5};
        CHECK_STATUS(mech_dynamics_add_point_damper(d.get(), 1, mech_vec3_t{0.0, 0.0, 0.0}, MECH_GROUND, hook, 0.7, 1,
                                                    nullptr),
                     MECH_STATUS_OK);
        CHECK_STATUS(mech_dynamics_add_joint_damper(d.get(), 3, 0.05, nullptr), MECH_STATUS_OK);
        const std::vector<double> q0{angle(rng), angle(rng), angle(rng), angle(rng)};
        const mechanica::matrix a_before = d.mass_matrix(q0);

        size_t needed = 0;
        CHECK_STATUS(mech_dynamics_damped_modes(d.get(), q0.data(), 4, 0, nullptr, &needed, nullptr),
                     MECH_STATUS_BUFFER_TOO_SMALL);
        CHECK(needed >= 4 && needed <= 8);
        std::array<std::vector<mech_damped_mode_t>, 2> runs;
        std::array<double, 2> gradient{};
        for (int call = 0; call < 2; ++call) {
            runs[call].resize(needed);
            size_t count = 0;
            CHECK_STATUS(mech_dynamics_damped_modes(d.get(), q0.data(), 4, needed, runs[call].data(), &count,
                                                    &gradient[call]),
                         MECH_STATUS_OK);
            CHECK(count == needed);
        }
        if (std::memcmp(&gradient[0], &gradient[1], sizeof(double)) != 0)
            std::printf("trial %d: gradient norm %.17g, then %.17g\n", trial, gradient[0], gradient[1]);
        CHECK(std::memcmp(&gradient[0], &gradient[1], sizeof(double)) == 0);
        for (size_t i = 0; i < needed; ++i) {
            CHECK(same_bits(fields(runs[0][i]), fields(runs[1][i])));
            ++compared;
        }
        const mechanica::matrix a_after = d.mass_matrix(q0);
        CHECK(std::memcmp(a_before.data(), a_after.data(), a_before.size() * sizeof(double)) == 0);
    }
    std::printf("damped modes of 12 spherical pendulums: %d records identical across calls\n", compared);
    return CHECK_DONE();
}
