// Eigen-decomposition choices for the spectral saliency: Eigen's dense solver for the whole
// spectrum (what the method needs) against Spectra's Lanczos solver for part of it, on the
// Laplacian of a simplified model. Usage: eigen_bench MODEL [n ...]
#include <Spectra/MatOp/SparseSymMatProd.h>
#include <Spectra/SymEigsSolver.h>

#include <Eigen/Dense>
#include <Eigen/Sparse>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>

#include "core/mesh/mesh_loader.hpp"
#include "core/mesh/vertex_adjacency.hpp"
#include "core/saliency/mesh_simplifier.hpp"

using namespace salient::core;

namespace {
double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}
}  // namespace

int main(int argc, char** argv) {
  if (argc < 2) return 2;
  const Mesh full = load_mesh(std::filesystem::path(argv[1])).mesh;
  std::vector<int> sizes;
  for (int i = 2; i < argc; ++i) sizes.push_back(std::atoi(argv[i]));
  if (sizes.empty()) sizes = {500, 1000, 2000};
  std::printf("%6s %14s %18s %18s\n", "n", "Eigen full s", "Spectra k=n/10 s", "Spectra k=n/4 s");
  for (int n : sizes) {
    const Mesh m = simplify_mesh(full, n);
    const VertexAdjacency adj(m);
    const auto nv = static_cast<int>(m.vertex_count());
    Eigen::MatrixXd dense = Eigen::MatrixXd::Zero(nv, nv);
    std::vector<Eigen::Triplet<double>> entries;
    for (int i = 0; i < nv; ++i)
      for (std::uint32_t j : adj.neighbours(i)) {
        const Vec3 d = m.positions[i] - m.positions[j];
        const double w = 1.0 / std::max(dot(d, d), 1e-30);
        dense(i, j) = -w;
        dense(i, i) += w;
        entries.emplace_back(i, static_cast<int>(j), -w);
        entries.emplace_back(i, i, w);
      }
    Eigen::SparseMatrix<double> sparse(nv, nv);
    sparse.setFromTriplets(entries.begin(), entries.end());
    auto t0 = std::chrono::steady_clock::now();
    const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(dense);
    const double t_eigen = seconds_since(t0);
    double t_spectra[2];
    int k_index = 0;
    for (int k : {nv / 10, nv / 4}) {
      t0 = std::chrono::steady_clock::now();
      Spectra::SparseSymMatProd<double> op(sparse);
      Spectra::SymEigsSolver<Spectra::SparseSymMatProd<double>> solver(op, k, std::min(nv, 2 * k + 1));
      solver.init();
      solver.compute(Spectra::SortRule::LargestMagn, 1000, 1e-10);
      t_spectra[k_index++] = seconds_since(t0);
    }
    std::printf("%6d %14.3f %18.3f %18.3f\n", nv, t_eigen, t_spectra[0], t_spectra[1]);
  }
  return 0;
}
