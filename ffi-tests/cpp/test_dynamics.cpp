// A C++17 program on the dynamics C ABI: a damped, spring-loaded double pendulum with handles
// owned by std::unique_ptr. Along random states the power balance of Lagrange's equations must
// hold for the q̈ of mech_dynamics_forward,
//   d/dt (½ q̇ᵀ A(q) q̇ + U(q)) = τ·q̇ − 2D,
// with A from mech_dynamics_mass_matrix (Ȧ by a central difference along q̇), ∇U from
// mech_mechanism_potential and D = ½ c q̇₁² the joint damper's dissipation function.
#include "check.h"

#include <array>
#include <cstdio>
#include <memory>
#include <random>
#include <vector>

namespace {

struct TreeDeleter {
    void operator()(mech_tree_t *t) const { mech_tree_destroy(t); }
};
struct MechanismDeleter {
    void operator()(mech_mechanism_t *m) const { mech_mechanism_destroy(m); }
};
struct DynamicsDeleter {
    void operator()(mech_dynamics_t *d) const { mech_dynamics_destroy(d); }
};
using Mechanism = std::unique_ptr<mech_mechanism_t, MechanismDeleter>;
using DynamicsHandle = std::unique_ptr<mech_dynamics_t, DynamicsDeleter>;

constexpr double g = 9.81, l1 = 0.8, l2 = 0.5, spring = 4.0, damping = 0.35;

Mechanism double_pendulum() {
    mech_tree_t *raw_tree = nullptr;
    CHECK_STATUS(mech_tree_create(&raw_tree), MECH_STATUS_OK);
    std::unique_ptr<mech_tree_t, TreeDeleter> tree(raw_tree);
    const mech_vec3_t axis{0.0, 1.0, 0.0};
    const mech_mat3_t identity{{1, 0, 0, 0, 1, 0, 0, 0, 1}};
    const std::array<mech_vec3_t, 2> origins{mech_vec3_t{0.0, 0.0, 0.0}, mech_vec3_t{0.0, 0.0, -l1}};
    for (int i = 0; i < 2; ++i) {
        size_t body = 0;
        CHECK_STATUS(mech_tree_add_body(tree.get(), i - 1, MECH_JOINT_REVOLUTE, &axis, &identity, &origins[i], &body),
                     MECH_STATUS_OK);
    }
    CHECK_STATUS(mech_tree_finalize(tree.get()), MECH_STATUS_OK);
    std::array<mech_mass_properties_t, 2> bodies{};
    bodies[0].mass = 1.3;
    bodies[0].center_of_mass = mech_vec3_t{0.05, 0.0, -0.5 * l1};
    bodies[1].mass = 0.9;
    bodies[1].center_of_mass = mech_vec3_t{0.0, 0.02, -l2};
    for (auto &b : bodies) {
        b.inertia_about_com.m[0] = 0.02;
        b.inertia_about_com.m[4] = 0.03;
        b.inertia_about_com.m[8] = 0.015;
    }
    mech_mechanism_t *raw = nullptr;
    CHECK_STATUS(mech_mechanism_create(tree.get(), bodies.data(), bodies.size(), &raw), MECH_STATUS_OK);
    Mechanism mechanism(raw);
    CHECK_STATUS(mech_mechanism_set_gravity(mechanism.get(), mech_vec3_t{0.0, 0.0, -g}), MECH_STATUS_OK);
    CHECK_STATUS(mech_mechanism_add_joint_spring(mechanism.get(), 1, spring, 0.2), MECH_STATUS_OK);
    return mechanism;
}

std::array<double, 4> mass_matrix(mech_dynamics_t *d, const std::array<double, 2> &q) {
    std::array<double, 4> a{};
    CHECK_STATUS(mech_dynamics_mass_matrix(d, q.data(), 2, a.data()), MECH_STATUS_OK);
    return a;
}

}  // namespace

int main() {
    Mechanism mechanism = double_pendulum();
    mech_dynamics_t *raw = nullptr;
    CHECK_STATUS(mech_dynamics_create(mechanism.get(), &raw), MECH_STATUS_OK);
    DynamicsHandle dynamics(raw);
    size_t index = 9;
    CHECK_STATUS(mech_dynamics_add_joint_damper(dynamics.get(), 1, damping, &index), MECH_STATUS_OK);
    CHECK(index == 0);

    std::mt19937_64 rng(2024);
    std::uniform_real_distribution<double> angle(-3.0, 3.0), rate(-4.0, 4.0), force(-5.0, 5.0);
    double worst = 0.0;
    for (int trial = 0; trial < 40; ++trial) {
        const std::array<double, 2> q{angle(rng), angle(rng)}, qd{rate(rng), rate(rng)}, tau{force(rng), force(rng)};
        std::array<double, 2> qdd{}, grad{};
        mech_forward_report_t report{};
        CHECK_STATUS(mech_dynamics_forward(dynamics.get(), q.data(), qd.data(), tau.data(), 0.0, 2, qdd.data(), &report),
                     MECH_STATUS_OK);
        CHECK(report.backward_error < 1e-13);
        const double dissipation = 0.5 * damping * qd[1] * qd[1];
        CHECK_NEAR(report.dissipation, dissipation, 1e-15 * (1.0 + dissipation));

        double u = 0.0;
        CHECK_STATUS(mech_mechanism_potential(mechanism.get(), q.data(), 2, &u, grad.data(), nullptr), MECH_STATUS_OK);
        const auto a = mass_matrix(dynamics.get(), q);
        const double h = 1e-5;
        const auto a_plus = mass_matrix(dynamics.get(), {q[0] + h * qd[0], q[1] + h * qd[1]});
        const auto a_minus = mass_matrix(dynamics.get(), {q[0] - h * qd[0], q[1] - h * qd[1]});
        double power = 0.0, scale = 0.0;
        for (int i = 0; i < 2; ++i) {
            for (int j = 0; j < 2; ++j) {
                const double a_dot = (a_plus[i + 2 * j] - a_minus[i + 2 * j]) / (2.0 * h);
                power += qd[i] * a[i + 2 * j] * qdd[j] + 0.5 * qd[i] * a_dot * qd[j];
                scale += std::abs(qd[i] * a[i + 2 * j] * qdd[j]) + std::abs(qd[i] * a_dot * qd[j]);
            }
            power += grad[i] * qd[i];
            scale += std::abs(grad[i] * qd[i]) + std::abs(tau[i] * qd[i]);
        }
        const double supplied = tau[0] * qd[0] + tau[1] * qd[1] - 2.0 * dissipation;
        worst = std::max(worst, std::abs(power - supplied) / scale);
        CHECK_NEAR(power, supplied, 1e-8 * scale);
    }
    std::printf("power balance dE/dt = tau.qdot - 2D: worst relative mismatch %.2e over 40 states\n", worst);

    // The reactions of both joints at one state, in each frame, have the same magnitudes.
    size_t bodies = 0;
    CHECK_STATUS(mech_dynamics_body_count(dynamics.get(), &bodies), MECH_STATUS_OK);
    CHECK(bodies == 2);
    const std::array<double, 2> q{0.4, -0.9}, qd{1.0, 2.0}, qdd{-0.5, 3.0};
    std::vector<double> world(12), body(12), joint(12);
    CHECK_STATUS(mech_dynamics_reactions(dynamics.get(), q.data(), qd.data(), qdd.data(), 2, MECH_REACTION_FRAME_WORLD,
                                         bodies, world.data()),
                 MECH_STATUS_OK);
    CHECK_STATUS(mech_dynamics_reactions(dynamics.get(), q.data(), qd.data(), qdd.data(), 2, MECH_REACTION_FRAME_BODY,
                                         bodies, body.data()),
                 MECH_STATUS_OK);
    CHECK_STATUS(mech_dynamics_reactions(dynamics.get(), q.data(), qd.data(), qdd.data(), 2, MECH_REACTION_FRAME_JOINT,
                                         bodies, joint.data()),
                 MECH_STATUS_OK);
    // Joint 2's frame is body 1's frame; body 2 turns about y by q2 within it: y components
    // agree, and the xz components are those of a rotation by q2 about y.
    const double c = std::cos(q[1]), s = std::sin(q[1]);
    for (int part = 0; part < 2; ++part) {
        const double *b = &body[6 + 3 * part], *j = &joint[6 + 3 * part];
        CHECK_NEAR(j[1], b[1], 1e-13 * (1.0 + std::abs(b[1])));
        CHECK_NEAR(j[0], c * b[0] + s * b[2], 1e-12 * (1.0 + std::abs(b[0]) + std::abs(b[2])));
        CHECK_NEAR(j[2], -s * b[0] + c * b[2], 1e-12 * (1.0 + std::abs(b[0]) + std::abs(b[2])));
    }
    // The y moment of each joint's reaction is the τ the joint applies, and τ₂ includes the
    // spring and the damper it carries: τ from the inverse dynamics.
    std::array<double, 2> tau{};
    CHECK_STATUS(mech_dynamics_inverse(dynamics.get(), q.data(), qd.data(), qdd.data(), 0.0, 2, tau.data(), nullptr,
                                       nullptr, nullptr),
                 MECH_STATUS_OK);
    CHECK_NEAR(world[4], tau[0], 1e-12 * (1.0 + std::abs(tau[0])));
    const double spring_and_damper = -spring * (q[1] - 0.2) - damping * qd[1];
    CHECK_NEAR(body[10], tau[1] + spring_and_damper, 1e-12 * (1.0 + std::abs(tau[1])));
    return CHECK_DONE();
}
