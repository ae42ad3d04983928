// bench_cg_eigen.cpp - the peer of bench_cg.c: Eigen's ConjugateGradient
// (Lower|Upper, DiagonalPreconditioner = Jacobi) on the same system
// (bench_cg_problem.h), same tolerance (1e-8 relative), same cap (2n), x0 = 0.
// Prints
//     cg_laplacian_100k_eigen <ms> ms
//     cg_laplacian_100k_eigen <steps> iterations
// The time is compute() + solve() (the preconditioner's setup and the
// iteration; the matrix is built once), median of 5 runs after a warm-up.
// Needs Eigen 3 (Debian: libeigen3-dev); build it single-threaded, as the
// tiledtex solver is:
//     c++ -O2 -DNDEBUG -I/usr/include/eigen3 -I. bench_cg_eigen.cpp -o bench_cg_eigen
#include <Eigen/IterativeLinearSolvers>
#include <Eigen/Sparse>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <vector>

#include "bench_cg_problem.h"

int main()
{
    const int n = bench_cg_size(), runs = 5;
    std::vector<bench_cg_entry> e((size_t)bench_cg_capacity());
    const int count = bench_cg_triplets(e.data());
    std::vector<double> xs((size_t)n), bv((size_t)n);
    bench_cg_solution(xs.data());
    bench_cg_rhs(e.data(), count, xs.data(), bv.data());

    std::vector<Eigen::Triplet<double> > t;
    t.reserve((size_t)count);
    for (int i = 0; i < count; i++) t.push_back(Eigen::Triplet<double>(e[i].row, e[i].col, e[i].value));
    Eigen::SparseMatrix<double> A(n, n);
    A.setFromTriplets(t.begin(), t.end());   // duplicates summed, as tt_sparse_from_triplets does
    A.makeCompressed();
    Eigen::Map<const Eigen::VectorXd> b(bv.data(), n);
    Eigen::VectorXd x(n);

    std::vector<double> ms;
    int iterations = 0;
    double residual = 0.0;
    for (int run = 0; run <= runs; run++) {   // run 0 warms up
        Eigen::ConjugateGradient<Eigen::SparseMatrix<double>, Eigen::Lower | Eigen::Upper,
                                 Eigen::DiagonalPreconditioner<double> > cg;
        cg.setTolerance(1e-8);
        cg.setMaxIterations(2 * n);
        std::chrono::steady_clock::time_point start = std::chrono::steady_clock::now();
        cg.compute(A);
        x = cg.solve(b);
        double elapsed =
            std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
        if (cg.info() != Eigen::Success) {
            std::fprintf(stderr, "bench_cg_eigen: did not converge (%d steps, error %g)\n", (int)cg.iterations(),
                         cg.error());
            return 1;
        }
        if (run > 0) ms.push_back(elapsed);
        iterations = (int)cg.iterations();
        residual = (b - A * x).norm() / b.norm();
    }
    double err = 0.0;
    for (int i = 0; i < n; i++) err = std::max(err, std::fabs(x[i] - xs[(size_t)i]));
    std::sort(ms.begin(), ms.end());
    std::printf("cg_laplacian_100k_eigen %.1f ms\n", ms[(size_t)runs / 2]);
    std::printf("cg_laplacian_100k_eigen %d iterations\n", iterations);
    std::fprintf(stderr,
                 "bench_cg_eigen: Eigen %d.%d.%d, %d unknowns, %d entries; runs %.1f..%.1f ms; %.3f ms a step; "
                 "residual %.3g; |x - x*|_inf %.3g\n",
                 EIGEN_WORLD_VERSION, EIGEN_MAJOR_VERSION, EIGEN_MINOR_VERSION, n, (int)A.nonZeros(), ms.front(),
                 ms.back(), ms[(size_t)runs / 2] / iterations, residual, err);
    return 0;
}
