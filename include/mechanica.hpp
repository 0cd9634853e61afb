/**
 * @file mechanica.hpp
 * @brief mechanica for C++17: RAII handles and exceptions over the C ABI of mechanica.h.
 *
 * Header-only; link the same library as for C (pkg-config `mechanica`, or the CMake target
 * `mechanica::mechanica`). Every failed C call throws mechanica::error, which carries the
 * ::mech_status_t and the text of mech_last_error(). Handles (tree, mechanism, modal_result,
 * dynamics, simulation) own their C handle, are movable and not copyable. Arrays are passed as
 * mechanica::const_span (std::span<const double> when the standard library has it, else a
 * pointer and a size); results come back as mechanica::matrix, column-major with data(),
 * rows() and cols(), so `Eigen::Map<const Eigen::MatrixXd>(m.data(), m.rows(), m.cols())` views
 * one without this header depending on Eigen.
 */
#ifndef MECHANICA_HPP
#define MECHANICA_HPP

#include <cstddef>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>
#if __has_include(<version>)
#include <version>
#endif
#if defined(__cpp_lib_span)
#include <span>
#endif

#include "mechanica.h"

namespace mechanica {

/** A failed call: the C status and the library's message (mech_last_error). */
class error : public std::runtime_error {
public:
    error(mech_status_t status, const std::string &message) : std::runtime_error(message), status_(status) {}
    /** The ::mech_status_t of the failed call. */
    mech_status_t status() const noexcept { return status_; }

private:
    mech_status_t status_;
};

namespace detail {
/** This thread's last error message. */
inline std::string last_error() {
    std::string text(mech_last_error(nullptr, 0) + 1, '\0');
    text.resize(mech_last_error(&text[0], text.size()));
    return text;
}

/** Throws mechanica::error unless `status` is MECH_STATUS_OK. */
inline void check(mech_status_t status) {
    if (status != MECH_STATUS_OK) throw error(status, std::string(mech_status_str(status)) + ": " + last_error());
}

/** A name from one of the mech_*_name functions (length query, then the copy). */
template <class Handle, class Query>
std::string name(Handle *handle, std::size_t index, Query query) {
    std::size_t length = 0;
    check(query(handle, index, nullptr, 0, &length));
    std::string text(length + 1, '\0');
    check(query(handle, index, &text[0], text.size(), &length));
    text.resize(length);
    return text;
}
}  // namespace detail

#if defined(__cpp_lib_span)
/** A read-only array of doubles. */
using const_span = std::span<const double>;
#else
/** A read-only array of doubles: a pointer and a size (std::span<const double> in C++20). */
class const_span {
public:
    const_span(const double *data, std::size_t size) : data_(data), size_(size) {}
    const_span(const std::vector<double> &v) : data_(v.data()), size_(v.size()) {}
    const double *data() const noexcept { return data_; }
    std::size_t size() const noexcept { return size_; }

private:
    const double *data_;
    std::size_t size_;
};
#endif

/** A dense matrix (or a vector, with one column) of doubles in column-major order. */
class matrix {
public:
    matrix() = default;
    matrix(std::size_t rows, std::size_t cols) : values_(rows * cols), rows_(rows), cols_(cols) {}
    double *data() noexcept { return values_.data(); }
    const double *data() const noexcept { return values_.data(); }
    std::size_t rows() const noexcept { return rows_; }
    std::size_t cols() const noexcept { return cols_; }
    std::size_t size() const noexcept { return values_.size(); }
    /** Entry (i, j), unchecked. */
    double operator()(std::size_t i, std::size_t j) const { return values_[i + rows_ * j]; }
    double &operator()(std::size_t i, std::size_t j) { return values_[i + rows_ * j]; }
    /** Entry i of the column-major storage, unchecked. */
    double operator[](std::size_t i) const { return values_[i]; }

private:
    std::vector<double> values_;
    std::size_t rows_ = 0, cols_ = 0;
};

/** Owns one C handle; moves transfer ownership, the destructor calls `Destroy`. */
template <class T, void (*Destroy)(T *)>
class handle {
public:
    handle() = default;
    explicit handle(T *raw) noexcept : raw_(raw) {}
    handle(handle &&other) noexcept : raw_(std::exchange(other.raw_, nullptr)) {}
    handle &operator=(handle &&other) noexcept {
        if (this != &other) {
            Destroy(raw_);
            raw_ = std::exchange(other.raw_, nullptr);
        }
        return *this;
    }
    handle(const handle &) = delete;
    handle &operator=(const handle &) = delete;
    ~handle() { Destroy(raw_); }
    /** The C handle, for calls this header does not wrap; still owned by this object. */
    T *get() const noexcept { return raw_; }

private:
    T *raw_ = nullptr;
};

#if defined(MECH_FEATURE_URDF)
/** Options of the URDF readers; the defaults refuse invalid inertias and unusable meshes. */
inline mech_urdf_options_t urdf_options() {
    mech_urdf_options_t options;
    detail::check(mech_urdf_options_default(&options));
    return options;
}
#endif

#if defined(MECH_FEATURE_KINEMATICS)
/** A kinematic tree (mech_tree_t). */
class tree : public handle<mech_tree_t, mech_tree_destroy> {
public:
    using handle::handle;
    /** An empty tree to fill with add_body and finalize (mech_tree_create). */
    static tree create() {
        mech_tree_t *raw = nullptr;
        detail::check(mech_tree_create(&raw));
        return tree(raw);
    }
    /** Adds a body (mech_tree_add_body); returns its index. */
    std::size_t add_body(long long parent, mech_joint_type_t type, const mech_vec3_t *axis, const mech_mat3_t &rotation,
                         const mech_vec3_t &translation) {
        std::size_t body = 0;
        detail::check(mech_tree_add_body(get(), parent, type, axis, &rotation, &translation, &body));
        return body;
    }
    /** Validates the tree (mech_tree_finalize). */
    void finalize() { detail::check(mech_tree_finalize(get())); }
    /** Number of bodies. */
    std::size_t body_count() const { return size().first; }
    /** Number of coordinates. */
    std::size_t dof() const { return size().second; }
#if defined(MECH_FEATURE_URDF)
    /** A tree from a URDF file (mech_tree_from_urdf). */
    static tree from_urdf(const std::string &path, const mech_urdf_options_t &options = urdf_options()) {
        mech_tree_t *raw = nullptr;
        detail::check(mech_tree_from_urdf(path.c_str(), &options, &raw));
        return tree(raw);
    }
    /** A tree from a URDF text, meshes looked for in `mesh_dir` (mech_tree_from_urdf_string). */
    static tree from_urdf_string(const std::string &text, const std::string &mesh_dir = ".",
                                 const mech_urdf_options_t &options = urdf_options()) {
        mech_tree_t *raw = nullptr;
        detail::check(mech_tree_from_urdf_string(text.data(), text.size(), mesh_dir.c_str(), &options, &raw));
        return tree(raw);
    }
    /** The link name of body `body`. */
    std::string link_name(std::size_t body) const { return detail::name(get(), body, mech_tree_link_name); }
    /** The name of the joint of body `body` (empty for the root link). */
    std::string joint_name(std::size_t body) const { return detail::name(get(), body, mech_tree_joint_name); }
    /** The name of coordinate `k`. */
    std::string coordinate_name(std::size_t k) const { return detail::name(get(), k, mech_tree_coordinate_name); }
#endif

private:
    std::pair<std::size_t, std::size_t> size() const {
        std::size_t bodies = 0, dof = 0;
        detail::check(mech_tree_size(get(), &bodies, &dof));
        return {bodies, dof};
    }
};
#endif

#if defined(MECH_FEATURE_MODAL)
/** The result of a dense modal solve of det(λA + B) = 0 (mech_modal_result_t). */
class modal_result : public handle<mech_modal_result_t, mech_modal_result_destroy> {
public:
    using handle::handle;
    /** Solves the pencil of order n (A and B column-major n·n; mech_modal_solve); NULL
     * options: mech_modal_options_default(). */
    static modal_result solve(std::size_t n, const_span a, const_span b, const mech_modal_options_t *options = nullptr) {
        if (a.size() != n * n || b.size() != n * n) throw error(MECH_STATUS_BAD_DIMENSION, "A and B must hold n·n values");
        mech_modal_options_t defaults;
        if (options == nullptr) {
            detail::check(mech_modal_options_default(&defaults));
            options = &defaults;
        }
        mech_modal_result_t *raw = nullptr;
        detail::check(mech_modal_solve(n, a.data(), b.data(), options, &raw));
        return modal_result(raw);
    }
    /** Number of modes. */
    std::size_t modes() const { return size().first; }
    /** Order n of the pencil. */
    std::size_t dim() const { return size().second; }
    /** The eigenvalues λ (one column). */
    matrix eigenvalues() const {
        matrix lambda(modes(), 1);
        detail::check(mech_modal_result_eigenvalues(get(), lambda.data(), lambda.size()));
        return lambda;
    }
    /** The eigenvectors, n × modes. */
    matrix vectors() const {
        matrix x(dim(), modes());
        detail::check(mech_modal_result_vectors(get(), x.data(), x.size()));
        return x;
    }

private:
    std::pair<std::size_t, std::size_t> size() const {
        std::size_t modes = 0, dim = 0;
        detail::check(mech_modal_result_size(get(), &modes, &dim));
        return {modes, dim};
    }
};
#endif

#if defined(MECH_FEATURE_MECHANISM)
/** The modes of a mechanism about a configuration (mech_mechanism_modes). */
struct mechanism_modes {
    /** ω² per mode (rad²/s²), one column. */
    matrix omega_sq;
    /** Error bound of each ω². */
    matrix error_bounds;
    /** MECH_MODAL_KIND_* per mode. */
    std::vector<mech_modal_kind_t> kinds;
    /** A-normalised shapes in q, dof × modes. */
    matrix shapes;
    /** The stability verdict. */
    mech_stability_t stability;
};

/** A mechanism: tree, body masses and loads (mech_mechanism_t). */
class mechanism : public handle<mech_mechanism_t, mech_mechanism_destroy> {
public:
    using handle::handle;
    /** A mechanism from a finalized tree and one mass-properties value per body. */
    static mechanism create(tree &t, const std::vector<mech_mass_properties_t> &bodies) {
        mech_mechanism_t *raw = nullptr;
        detail::check(mech_mechanism_create(t.get(), bodies.data(), bodies.size(), &raw));
        return mechanism(raw);
    }
#if defined(MECH_FEATURE_URDF)
    /** A mechanism from a URDF file (mech_mechanism_from_urdf). */
    static mechanism from_urdf(const std::string &path, const mech_urdf_options_t &options = urdf_options()) {
        mech_mechanism_t *raw = nullptr;
        detail::check(mech_mechanism_from_urdf(path.c_str(), &options, &raw));
        return mechanism(raw);
    }
    /** A mechanism from a URDF text (mech_mechanism_from_urdf_string). */
    static mechanism from_urdf_string(const std::string &text, const std::string &mesh_dir = ".",
                                      const mech_urdf_options_t &options = urdf_options()) {
        mech_mechanism_t *raw = nullptr;
        detail::check(mech_mechanism_from_urdf_string(text.data(), text.size(), mesh_dir.c_str(), &options, &raw));
        return mechanism(raw);
    }
    /** The link name of body `body`. */
    std::string link_name(std::size_t body) const { return detail::name(get(), body, mech_mechanism_link_name); }
    /** The name of coordinate `k`. */
    std::string coordinate_name(std::size_t k) const {
        return detail::name(get(), k, mech_mechanism_coordinate_name);
    }
#endif
    /** Number of coordinates. */
    std::size_t dof() const {
        std::size_t n = 0;
        detail::check(mech_mechanism_dof(get(), &n));
        return n;
    }
    /** Sets gravity (base frame, m/s²). */
    void set_gravity(const mech_vec3_t &g) { detail::check(mech_mechanism_set_gravity(get(), g)); }
    /** An equilibrium near q0 (mech_mechanism_equilibrium with the default iteration limit and tolerance). */
    matrix equilibrium(const_span q0, mech_seek_t seek = MECH_SEEK_MINIMUM) {
        matrix q(q0.size(), 1);
        mech_equilibrium_report_t report;
        detail::check(mech_mechanism_equilibrium(get(), q0.data(), q0.size(), seek, 0, 0.0, q.data(), &report));
        return q;
    }
    /** The lowest `count` modes about q (0: all). */
    mechanism_modes modes(const_span q, std::size_t count = 0) {
        const std::size_t n = q.size(), k = count == 0 ? n : count;
        mechanism_modes m{matrix(k, 1), matrix(k, 1), std::vector<mech_modal_kind_t>(k), matrix(n, k), {}};
        std::size_t found = 0;
        detail::check(mech_mechanism_modes(get(), q.data(), n, count, m.omega_sq.data(), m.error_bounds.data(),
                                           m.kinds.data(), m.shapes.data(), &found, &m.stability));
        return m;
    }
};
#endif

#if defined(MECH_FEATURE_DYNAMICS)
/** Equations of motion of a mechanism (mech_dynamics_t). */
class dynamics : public handle<mech_dynamics_t, mech_dynamics_destroy> {
public:
    using handle::handle;
    /** Dynamics of a copy of `m` (mech_dynamics_create). */
    static dynamics create(const mechanism &m) {
        mech_dynamics_t *raw = nullptr;
        detail::check(mech_dynamics_create(m.get(), &raw));
        return dynamics(raw);
    }
    /** Number of coordinates. */
    std::size_t dof() const {
        std::size_t n = 0;
        detail::check(mech_dynamics_dof(get(), &n));
        return n;
    }
    /** The mass matrix A(q), n × n (mech_dynamics_mass_matrix). */
    matrix mass_matrix(const_span q) {
        matrix a(q.size(), q.size());
        detail::check(mech_dynamics_mass_matrix(get(), q.data(), q.size(), a.data()));
        return a;
    }
    /** Inverse dynamics τ(q, q̇, q̈) (mech_dynamics_rnea). */
    matrix rnea(const_span q, const_span q_dot, const_span q_ddot) {
        same_length(q, q_dot, q_ddot);
        matrix tau(q.size(), 1);
        detail::check(mech_dynamics_rnea(get(), q.data(), q_dot.data(), q_ddot.data(), q.size(), tau.data()));
        return tau;
    }
    /** Forward dynamics q̈(q, q̇, τ) by the articulated-body recursion (mech_dynamics_aba). */
    matrix aba(const_span q, const_span q_dot, const_span tau) {
        same_length(q, q_dot, tau);
        matrix q_ddot(q.size(), 1);
        detail::check(mech_dynamics_aba(get(), q.data(), q_dot.data(), tau.data(), q.size(), q_ddot.data()));
        return q_ddot;
    }

private:
    static void same_length(const_span a, const_span b, const_span c) {
        if (a.size() != b.size() || a.size() != c.size())
            throw error(MECH_STATUS_BAD_DIMENSION, "the three vectors must have the same length");
    }
};
#endif

#if defined(MECH_FEATURE_MOTION)
/** A simulation (mech_simulation_t): a copy of a dynamics integrated in time from an initial
 * state, with its global error estimate, monitors and, with contacts, its impacts. */
class simulation : public handle<mech_simulation_t, mech_simulation_destroy> {
public:
    /** The state (q, q̇) at a time. */
    struct state {
        std::vector<double> q, q_dot;
    };
    /** The default options (mech_motion_options_default). */
    static mech_motion_options_t default_options() {
        mech_motion_options_t options;
        detail::check(mech_motion_options_default(&options));
        return options;
    }
    /** A simulation of `d` without its constraints (mech_simulation_create). */
    static simulation create(const dynamics &d, const mech_motion_options_t &options, const_span q0, const_span q_dot0) {
        same_length(q0, q_dot0);
        mech_simulation_t *raw = nullptr;
        detail::check(mech_simulation_create(d.get(), &options, q0.data(), q_dot0.data(), nullptr, q0.size(), &raw));
        return simulation(raw, q0.size());
    }
    /** A simulation that keeps the holonomic constraints of `d` (mech_simulation_create_constrained). */
    static simulation constrained(const dynamics &d, const mech_motion_options_t &options, const_span q0,
                                  const_span q_dot0) {
        same_length(q0, q_dot0);
        mech_simulation_t *raw = nullptr;
        detail::check(
            mech_simulation_create_constrained(d.get(), &options, q0.data(), q_dot0.data(), nullptr, q0.size(), &raw));
        return simulation(raw, q0.size());
    }
    /** A simulation with unilateral contacts and their impacts (mech_simulation_create_with_contacts). */
    static simulation with_contacts(const dynamics &d, const mech_motion_options_t &options,
                                    const std::vector<mech_motion_contact_t> &contacts, const_span q0,
                                    const_span q_dot0) {
        same_length(q0, q_dot0);
        mech_simulation_t *raw = nullptr;
        detail::check(mech_simulation_create_with_contacts(d.get(), &options, contacts.data(), contacts.size(),
                                                           q0.data(), q_dot0.data(), nullptr, q0.size(), &raw));
        return simulation(raw, q0.size());
    }
    /** Integrates to `t` (mech_simulation_advance) and gives (q, q̇) there. */
    state advance(double t) {
        state s{std::vector<double>(n_), std::vector<double>(n_)};
        detail::check(mech_simulation_advance(get(), t, n_, s.q.data(), s.q_dot.data()));
        return s;
    }
    /** The error estimate and energy monitor at the time reached (mech_simulation_report). */
    mech_motion_report_t report() const {
        mech_motion_report_t r;
        detail::check(mech_simulation_report(get(), &r));
        return r;
    }
    /** The impacts so far, in time order (mech_simulation_impact). */
    std::vector<mech_motion_impact_t> impacts() const {
        std::size_t count = 0;
        detail::check(mech_simulation_impact_count(get(), &count));
        std::vector<mech_motion_impact_t> out(count);
        for (std::size_t k = 0; k < count; ++k) detail::check(mech_simulation_impact(get(), k, &out[k]));
        return out;
    }
    /** Number of coordinates. */
    std::size_t dof() const noexcept { return n_; }

private:
    simulation(mech_simulation_t *raw, std::size_t n) : handle(raw), n_(n) {}
    static void same_length(const_span a, const_span b) {
        if (a.size() != b.size()) throw error(MECH_STATUS_BAD_DIMENSION, "q0 and q_dot0 must have the same length");
    }
    std::size_t n_ = 0;
};
#endif

}  // namespace mechanica

#endif
