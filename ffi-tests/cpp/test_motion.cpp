// The C++ header's mechanica::simulation over the motion C ABI: a mass dropped on a floor
// (closed-form impact times, losses and rebound apex; the plastic impact thrown as
// mechanica::error with NOT_CONVERGED), and a double pendulum whose elbow is held at zero by a
// coordinate constraint, which must then swing as one compound pendulum (RATTLE keeps the
// elbow at zero to rounding and the energy bounded).
#include "check.h"
#include "mechanica.hpp"

#include <cmath>
#include <vector>

namespace {

constexpr double g = 9.81;
const mech_mat3_t identity{{1, 0, 0, 0, 1, 0, 0, 0, 1}};
const mech_vec3_t origin{0.0, 0.0, 0.0};

mech_mass_properties_t point_mass(double m, mech_vec3_t at) {
    mech_mass_properties_t p{};
    p.mass = m;
    p.center_of_mass = at;
    return p;
}

mechanica::dynamics falling_mass(double m) {
    auto tree = mechanica::tree::create();
    const mech_vec3_t z{0.0, 0.0, 1.0};
    tree.add_body(-1, MECH_JOINT_PRISMATIC, &z, identity, origin);
    tree.finalize();
    auto mechanism = mechanica::mechanism::create(tree, {point_mass(m, origin)});
    mechanism.set_gravity({0.0, 0.0, -g});
    return mechanica::dynamics::create(mechanism);
}

mech_motion_contact_t floor_contact(double e) {
    mech_motion_contact_t c{};
    c.contact.other_body = -1;
    c.contact.normal = {0.0, 0.0, 1.0};
    c.contact.restitution = e;
    c.contact.law = MECH_RESTITUTION_POISSON;
    return c;
}

void bouncing() {
    for (double e : {0.25, 0.5, 0.85}) {
        const double m = 3.0, h0 = 1.3, v1 = std::sqrt(2.0 * g * h0);
        auto d = falling_mass(m);
        auto options = mechanica::simulation::default_options();
        options.rtol = 1e-11;
        options.atol = 1e-13;
        const std::vector<double> q0{h0}, v0{0.0};
        auto s = mechanica::simulation::with_contacts(d, options, {floor_contact(e)}, q0, v0);
        const double t1 = v1 / g, t2 = t1 + 2.0 * e * v1 / g;
        const auto at_apex = s.advance(t2 + e * e * v1 / g);
        CHECK_NEAR(at_apex.q[0], std::pow(e * e * v1, 2) / (2.0 * g), 1e-8);
        const auto impacts = s.impacts();
        CHECK(impacts.size() == 2);
        CHECK_NEAR(impacts[0].t, t1, 1e-9);
        CHECK_NEAR(impacts[1].t, t2, 1e-9);
        CHECK_NEAR(impacts[1].energy_lost, 0.5 * m * e * e * v1 * v1 * (1.0 - e * e), 1e-7);
        CHECK(std::fabs(impacts[1].segment_drift) <= 1e-9);
        CHECK(s.report().max_energy_drift <= 1e-9);
    }
    auto d = falling_mass(1.0);
    const std::vector<double> q0{0.4}, v0{0.0};
    auto plastic = mechanica::simulation::with_contacts(d, mechanica::simulation::default_options(),
                                                        {floor_contact(0.0)}, q0, v0);
    bool thrown = false;
    try {
        plastic.advance(2.0);
    } catch (const mechanica::error &error) {
        thrown = error.status() == MECH_STATUS_NOT_CONVERGED;
    }
    CHECK(thrown);
    CHECK(plastic.impacts().size() == 1);
}

void locked_elbow() {
    const double l1 = 0.7, l2 = 0.4, m1 = 1.5, m2 = 0.6;
    auto tree = mechanica::tree::create();
    const mech_vec3_t y{0.0, 1.0, 0.0};
    tree.add_body(-1, MECH_JOINT_REVOLUTE, &y, identity, origin);
    tree.add_body(0, MECH_JOINT_REVOLUTE, &y, identity, {0.0, 0.0, -l1});
    tree.finalize();
    auto mechanism = mechanica::mechanism::create(
        tree, {point_mass(m1, {0.0, 0.0, -l1}), point_mass(m2, {0.0, 0.0, -l2})});
    mechanism.set_gravity({0.0, 0.0, -g});
    auto d = mechanica::dynamics::create(mechanism);
    std::size_t index = 99;
    CHECK_STATUS(mech_dynamics_add_coordinate_constraint(d.get(), 1, 0.0, &index), MECH_STATUS_OK);
    auto options = mechanica::simulation::default_options();
    options.method = MECH_MOTION_RATTLE;
    options.step = 1e-3;
    const double theta0 = 0.6;
    const std::vector<double> q0{theta0, 0.0}, v0{0.0, 0.0};
    auto s = mechanica::simulation::constrained(d, options, q0, v0);
    // The rigid pendulum: I θ̈ = −M g L sin θ with I = m1 l1² + m2 (l1 + l2)², M L = m1 l1 + m2 (l1 + l2).
    const double inertia = m1 * l1 * l1 + m2 * (l1 + l2) * (l1 + l2), moment = (m1 * l1 + m2 * (l1 + l2)) * g;
    double energy_max = 0.0;
    for (int k = 1; k <= 20; ++k) {
        const auto state = s.advance(0.1 * k);
        CHECK(std::fabs(state.q[1]) <= 1e-12 && std::fabs(state.q_dot[1]) <= 1e-11);
        const double energy = 0.5 * inertia * state.q_dot[0] * state.q_dot[0] - moment * std::cos(state.q[0]);
        energy_max = std::fmax(energy_max, std::fabs(energy + moment * std::cos(theta0)));
    }
    CHECK(energy_max <= 1e-5 * moment);
    mech_motion_constraint_report_t drift;
    CHECK_STATUS(mech_simulation_constraint_report(s.get(), &drift), MECH_STATUS_OK);
    CHECK(drift.max_position_drift <= 1e-12);
}

}  // namespace

int main() {
    bouncing();
    locked_elbow();
    std::printf("test_motion (C++): %d checks passed\n", mech_check_count);
    return 0;
}
