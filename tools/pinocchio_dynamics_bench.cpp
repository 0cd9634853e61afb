// Pinocchio (C++) peer for the dynamics benchmarks: rnea, aba, crba and forwardKinematics
// behind a small C ABI, so that benches/benches/dynamics.rs times Pinocchio and mechanica in the
// same run on the same models and states.
//
// The model is built here joint by joint from the neutral description of
// tools/dynamics_pinocchio_reference.json (the one mechanica's side reads), so both sides use
// the same placements and inertias bit for bit. A revolute or prismatic axis along +x, +y or +z
// becomes JointModelRX/RY/RZ (PX/PY/PZ), any other axis the Unaligned joint, as Pinocchio's URDF
// parser does. Everything is compiled from Pinocchio's headers in this translation unit (no
// library of the wheel is linked), with the flags of tools/pinocchio_dynamics_bench.sh
// (-O3 -march=native -DNDEBUG). Conventions are Pinocchio's defaults (LOCAL for aba and crba).
//
// C ABI (arrays are caller-owned, of length nq, nv, nv * nv or as stated; nothing is checked):
//   void* pin_bench_new(void)                     an empty model, gravity (0, 0, -9.81)
//   int pin_bench_add_joint(void* h, int parent, int kind, const double axis[3],
//       const double rotation[9], const double translation[3], double mass,
//       const double com[3], const double inertia[9])
//       parent: index of an earlier joint or -1 (the world); kind: 0 revolute, 1 prismatic,
//       2 free flyer; rotation row-major; com and the central inertia (row-major) in the joint
//       frame. Returns the joint's index (0-based), or -1 for a bad parent or kind.
//   void pin_bench_set_gravity(void* h, const double g[3])
//   void pin_bench_finish(void* h)                allocates the data; call before timing
//   void pin_bench_free(void* h)
//   int pin_bench_nq(const void* h), pin_bench_nv(const void* h)
//   void pin_bench_rnea(void* h, const double* q, const double* v, const double* a, double* tau)
//   void pin_bench_aba(void* h, const double* q, const double* v, const double* tau, double* a)
//   void pin_bench_crba(void* h, const double* q, double* m)    upper triangle, column-major
//   void pin_bench_forward_kinematics(void* h, const double* q, const double* v, const double* a)

#include <pinocchio/multibody.hpp>
#include <pinocchio/algorithm/aba.hpp>
#include <pinocchio/algorithm/crba.hpp>
#include <pinocchio/algorithm/kinematics.hpp>
#include <pinocchio/algorithm/rnea.hpp>

#include <cstring>
#include <string>
#include <memory>

namespace {

struct Handle {
    pinocchio::Model model;
    std::unique_ptr<pinocchio::Data> data;
};

using ConstVector = Eigen::Map<const Eigen::VectorXd>;

Handle* handle(void* h) { return static_cast<Handle*>(h); }
const Handle* handle(const void* h) { return static_cast<const Handle*>(h); }

bool along(const Eigen::Vector3d& axis, int k) { return axis == Eigen::Vector3d::Unit(k); }

pinocchio::JointModel revolute(const Eigen::Vector3d& axis) {
    if (along(axis, 0)) return pinocchio::JointModelRX();
    if (along(axis, 1)) return pinocchio::JointModelRY();
    if (along(axis, 2)) return pinocchio::JointModelRZ();
    return pinocchio::JointModelRevoluteUnaligned(axis);
}

pinocchio::JointModel prismatic(const Eigen::Vector3d& axis) {
    if (along(axis, 0)) return pinocchio::JointModelPX();
    if (along(axis, 1)) return pinocchio::JointModelPY();
    if (along(axis, 2)) return pinocchio::JointModelPZ();
    return pinocchio::JointModelPrismaticUnaligned(axis);
}

}  // namespace

extern "C" {

void* pin_bench_new(void) { return new Handle(); }

int pin_bench_add_joint(void* h, int parent, int kind, const double axis[3], const double rotation[9],
                        const double translation[3], double mass, const double com[3], const double inertia[9]) {
    auto& model = handle(h)->model;
    if (parent < -1 || parent + 1 >= model.njoints || kind < 0 || kind > 2) return -1;
    const Eigen::Vector3d a(axis[0], axis[1], axis[2]);
    const Eigen::Matrix3d r = Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(rotation);
    const pinocchio::SE3 placement(r, Eigen::Vector3d(translation[0], translation[1], translation[2]));
    const pinocchio::JointModel joint =
        kind == 0 ? revolute(a) : kind == 1 ? prismatic(a) : pinocchio::JointModel(pinocchio::JointModelFreeFlyer());
    const auto id = model.addJoint(static_cast<pinocchio::JointIndex>(parent + 1), joint, placement,
                                   "joint" + std::to_string(model.njoints));
    const Eigen::Matrix3d i = Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(inertia);
    model.appendBodyToJoint(id, pinocchio::Inertia(mass, Eigen::Vector3d(com[0], com[1], com[2]), i),
                            pinocchio::SE3::Identity());
    return static_cast<int>(id) - 1;
}

void pin_bench_set_gravity(void* h, const double g[3]) {
    handle(h)->model.gravity.linear(Eigen::Vector3d(g[0], g[1], g[2]));
}

void pin_bench_finish(void* h) { handle(h)->data = std::make_unique<pinocchio::Data>(handle(h)->model); }

void pin_bench_free(void* h) { delete handle(h); }

int pin_bench_nq(const void* h) { return handle(h)->model.nq; }

int pin_bench_nv(const void* h) { return handle(h)->model.nv; }

void pin_bench_rnea(void* h, const double* q, const double* v, const double* a, double* tau) {
    Handle* p = handle(h);
    const int nq = p->model.nq, nv = p->model.nv;
    pinocchio::rnea(p->model, *p->data, ConstVector(q, nq), ConstVector(v, nv), ConstVector(a, nv));
    std::memcpy(tau, p->data->tau.data(), sizeof(double) * nv);
}

void pin_bench_aba(void* h, const double* q, const double* v, const double* tau, double* a) {
    Handle* p = handle(h);
    const int nq = p->model.nq, nv = p->model.nv;
    pinocchio::aba(p->model, *p->data, ConstVector(q, nq), ConstVector(v, nv), ConstVector(tau, nv));
    std::memcpy(a, p->data->ddq.data(), sizeof(double) * nv);
}

void pin_bench_crba(void* h, const double* q, double* m) {
    Handle* p = handle(h);
    const int nq = p->model.nq, nv = p->model.nv;
    pinocchio::crba(p->model, *p->data, ConstVector(q, nq));
    std::memcpy(m, p->data->M.data(), sizeof(double) * nv * nv);
}

void pin_bench_forward_kinematics(void* h, const double* q, const double* v, const double* a) {
    Handle* p = handle(h);
    const int nq = p->model.nq, nv = p->model.nv;
    pinocchio::forwardKinematics(p->model, *p->data, ConstVector(q, nq), ConstVector(v, nv), ConstVector(a, nv));
}

}  // extern "C"
