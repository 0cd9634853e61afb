// The Spectra peer of `mechanica-modal`'s sparse solver (tools/modal_sparse_spectra.sh runs both):
// the 10 lowest modes of the 5-point Dirichlet Laplacian of an N x N grid (unit spacing, mass
// matrix I, so the standard problem B x = w x), by Spectra's SymEigsShiftSolver at sigma = 0 in
// two ways: Spectra's own SparseSymShiftSolve operator (Eigen SparseLU), and an operator on
// Eigen's SimplicialLDLT (the symmetric factorization, the best case for the peer).
// Prints: method, N, n, best wall time (s) of the repetitions, converged count, max relative error against
// the closed form 4 sin^2(p pi/(2(N+1))) + 4 sin^2(q pi/(2(N+1))).
#include <Eigen/Sparse>
#include <Eigen/SparseCholesky>
#include <Spectra/MatOp/SparseSymShiftSolve.h>
#include <Spectra/SymEigsShiftSolver.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

using Sparse = Eigen::SparseMatrix<double>;

static Sparse grid(int m) {
    std::vector<Eigen::Triplet<double>> t;
    for (int j = 0; j < m; ++j) {
        for (int i = 0; i < m; ++i) {
            int r = i + m * j;
            t.emplace_back(r, r, 4.0);
            if (i > 0) t.emplace_back(r, r - 1, -1.0);
            if (i + 1 < m) t.emplace_back(r, r + 1, -1.0);
            if (j > 0) t.emplace_back(r, r - m, -1.0);
            if (j + 1 < m) t.emplace_back(r, r + m, -1.0);
        }
    }
    Sparse b(m * m, m * m);
    b.setFromTriplets(t.begin(), t.end());
    b.makeCompressed();
    return b;
}

static std::vector<double> exact(int m, int k) {
    std::vector<double> s(m), w;
    for (int p = 1; p <= m; ++p) s[p - 1] = 4.0 * std::pow(std::sin(p * M_PI / (2.0 * (m + 1))), 2);
    for (int p = 0; p < std::min(m, k + 1); ++p)
        for (int q = 0; q < std::min(m, k + 1); ++q) w.push_back(s[p] + s[q]);
    std::sort(w.begin(), w.end());
    w.resize(k);
    return w;
}

// y = (B - sigma I)^{-1} x through Eigen's SimplicialLDLT.
struct LdltShiftSolve {
    const Sparse &b;
    Eigen::SimplicialLDLT<Sparse> ldlt;
    using Scalar = double;
    explicit LdltShiftSolve(const Sparse &m) : b(m) {}
    Eigen::Index rows() const { return b.rows(); }
    Eigen::Index cols() const { return b.cols(); }
    void set_shift(double sigma) {
        Sparse i(b.rows(), b.cols());
        i.setIdentity();
        ldlt.compute(b - sigma * i);
    }
    void perform_op(const double *x, double *y) const {
        Eigen::Map<const Eigen::VectorXd> xin(x, b.rows());
        Eigen::Map<Eigen::VectorXd> yout(y, b.rows());
        yout = ldlt.solve(xin);
    }
};

template <class Op>
static void run(const char *name, int m, int k, const Sparse &b, const std::vector<double> &ref, int reps) {
    double best = 1e300, err = 0.0;
    long conv = 0;
    for (int rep = 0; rep < reps; ++rep) {
        auto t0 = std::chrono::steady_clock::now();
        Op op(b);
        Spectra::SymEigsShiftSolver<Op> eigs(op, k, 3 * k, 0.0);
        eigs.init();
        conv = eigs.compute(Spectra::SortRule::LargestMagn, 1000, 1e-12);
        Eigen::VectorXd w = eigs.eigenvalues();
        double dt = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
        best = std::min(best, dt);
        std::vector<double> got(w.data(), w.data() + w.size());
        std::sort(got.begin(), got.end());
        err = 0.0;
        for (size_t i = 0; i < got.size() && i < ref.size(); ++i) err = std::max(err, std::abs(got[i] - ref[i]) / ref[i]);
    }
    std::printf("%s %d %d %.4f %ld %.2e\n", name, m, m * m, best, conv, err);
}

// Arguments: N (default 300), repetitions (default 3), and "ldlt" to run only the LDLT operator.
int main(int argc, char **argv) {
    int m = argc > 1 ? std::atoi(argv[1]) : 300, k = 10;
    int reps = argc > 2 ? std::atoi(argv[2]) : 3;
    bool ldlt_only = argc > 3 && std::string(argv[3]) == "ldlt";
    Sparse b = grid(m);
    std::vector<double> ref = exact(m, k);
    if (!ldlt_only) run<Spectra::SparseSymShiftSolve<double>>("spectra_sparselu", m, k, b, ref, reps);
    run<LdltShiftSolve>("spectra_simplicial_ldlt", m, k, b, ref, reps);
    return 0;
}
