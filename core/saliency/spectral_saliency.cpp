// spectral saliency, as ALGORITHMS.md §1 pins it down:
//  1. simplify to a working mesh M′ of ~1,000 vertices (quadric edge collapse);
//  2. W(i,j) = 1/‖vi − vj‖² on edges, L = D − W;
//  3. all eigenpairs of L, ascending (LAPACK's divide-and-conquer dsyevd: the irregularity needs
//     the whole spectrum, so a partial solver such as Spectra does not apply); λ0 := λ1;
//  4. ℒ(f) = log|λf|, R(f) = |ℒ(f) − (J9 ∗ ℒ)(f)| (centred width-9 mean, replicate padding);
//  5. S(i,j) = Σf B(i,f)·e^R(f)·B(j,f) on edges only, si = Σj∈N(i) |S(i,j)·W(i,j)|;
//  6. five scales tj = j·ε², ε = 0.7·c (below): s′(i,t) = |s_M(k·t)(i) − s_M(t)(i)| where M(t)
//     Gaussian-smooths positions (variance t, radius 2.5√t) and M(k·t) uses the per-vertex
//     factor k(i) = 1 + c·|N(i)| / Σj∈N(i)‖pi − pj‖ (c the mean edge length); summed;
//  7. mapped to the original vertices through the closest point on M′;
//  8. Gaussian-smoothed at t1 and scaled to [0, 1].
// The whole method runs on a copy in a canonical frame (centroid at the origin, unit RMS
// radius, principal axes with signs fixed by the third moment), so that a moved or scaled model
// gives the simplifier the same coordinates (quantised to 2^-30), not ones whose rounding
// breaks ties differently.
// Where we differ: with W = 1/d² the raw si carry the local edge density (a short edge of the
// simplified mesh can weigh a thousand times the rest), so the scales are compared as
// s′(i,t) = |log s_M(k·t)(i) − log s_M(t)(i)| — a relative change, free of that density — and
// min–max scaling (per scale, and of the result) clips at the 1st and 99th percentiles first.
// Also ours: the paper's ε = 0.002·diagonal is set for a full-resolution mesh; on a ~1,000-vertex
// M′ (mean edge c ≈ 0.03·diagonal) its largest smoothing radius, 2.5·√(5·k)·ε ≈ 0.016·diagonal,
// reaches no neighbour, the scale space does nothing, and maps came out as patches the shape of
// M′'s triangles. ε = 0.7·c makes the five radii span one to three rings of M′ (0.7 chosen over
// 0.3–1.0 by the maps' stability under remeshing the input and their look, BENCHMARKS.md). And
// M′ is remeshed isotropically after the collapse (mesh_simplifier.hpp): a sliver of the
// collapse, 1/d² weighing it a thousand times its neighbours, made a hot spot wherever it fell.
#include "core/saliency/spectral_saliency.hpp"

#include <lapacke.h>
#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "core/common/input_error.hpp"
#include "core/geometry/point_grid.hpp"
#include "core/mesh/vertex_adjacency.hpp"
#include "core/saliency/mesh_simplifier.hpp"
#include "core/saliency/surface_locator.hpp"

// OpenBLAS's thread count (declared in its cblas.h, which we need nothing else from).
extern "C" void openblas_set_num_threads(int threads);

namespace salient::core {
namespace {

// The scale-space unit ε as a share of M′'s mean edge length c (see the opening comment).
constexpr double kScaleOverEdge = 0.7;

// The largest working mesh per 1,000 asked for: remeshing lands near the target; 2,500 vertices
// are 50 MB a matrix (four of them a decomposition) and a few seconds each.
constexpr std::size_t kMostWorkingVertices = 2500;

// Positions Gaussian-smoothed with per-vertex variance t·k(i) over Euclidean neighbours within
// 2.5 standard deviations.
std::vector<Vec3> smoothed(const Mesh& mesh, const PointGrid& grid, double t, const std::vector<double>& k) {
  std::vector<Vec3> out(mesh.vertex_count());
  for (std::size_t i = 0; i < out.size(); ++i) {
    const double var = t * k[i], radius = 2.5 * std::sqrt(var);
    Vec3 sum{};
    double wsum = 0;
    grid.for_each_within(mesh.positions[i], radius, [&](std::uint32_t j, double d2) {
      const double w = std::exp(-d2 / (2 * var));
      sum += mesh.positions[j] * w;
      wsum += w;
    });
    out[i] = wsum > 0 ? sum / wsum : mesh.positions[i];
  }
  return out;
}

bool same_positions(const std::vector<Vec3>& a, const std::vector<Vec3>& b) {
  return std::equal(a.begin(), a.end(), b.begin(), b.end(),
                    [](const Vec3& p, const Vec3& q) { return p.x == q.x && p.y == q.y && p.z == q.z; });
}

Mesh canonical_copy(const Mesh& mesh) {
  const std::size_t n = mesh.vertex_count();
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (const Vec3& p : mesh.positions) mean += Eigen::Vector3d(p.x, p.y, p.z);
  mean /= std::max<std::size_t>(1, n);
  Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
  for (const Vec3& p : mesh.positions) {
    const Eigen::Vector3d d = Eigen::Vector3d(p.x, p.y, p.z) - mean;
    cov += d * d.transpose();
  }
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(cov);
  Eigen::Matrix3d axes = eig.eigenvectors();
  const double rms = std::sqrt(std::max(cov.trace() / std::max<std::size_t>(1, n), 1e-300));
  for (int a = 0; a < 3; ++a) {
    double third = 0;
    for (const Vec3& p : mesh.positions)
      third += std::pow(axes.col(a).dot(Eigen::Vector3d(p.x, p.y, p.z) - mean), 3);
    if (third < 0) axes.col(a) = -axes.col(a);
  }
  if (axes.determinant() < 0) axes.col(0) = -axes.col(0);  // stay a rotation: no mirror
  Mesh out;
  out.triangles = mesh.triangles;
  out.positions.reserve(n);
  for (const Vec3& p : mesh.positions) {
    const Eigen::Vector3d q = axes.transpose() * (Eigen::Vector3d(p.x, p.y, p.z) - mean) / rms;
    // Quantised to 2^-30 of the RMS radius: copies that differ only by rounding become identical.
    constexpr double grid = 1073741824.0;
    out.positions.push_back(
        {std::round(q.x() * grid) / grid, std::round(q.y() * grid) / grid, std::round(q.z() * grid) / grid});
  }
  return out;
}

double mean_edge(const Mesh& mesh, const VertexAdjacency& adj) {
  double total = 0;
  std::size_t edges = 0;
  for (std::size_t i = 0; i < mesh.vertex_count(); ++i)
    for (std::uint32_t j : adj.neighbours(i)) total += norm(mesh.positions[j] - mesh.positions[i]), ++edges;
  return edges ? total / edges : 0;
}

std::vector<double> scale_factors(const Mesh& mesh, const VertexAdjacency& adj) {
  const double c = mean_edge(mesh, adj);
  std::vector<double> k(mesh.vertex_count(), 1);
  for (std::size_t i = 0; i < k.size(); ++i) {
    double sum = 0;
    for (std::uint32_t j : adj.neighbours(i)) sum += norm(mesh.positions[j] - mesh.positions[i]);
    if (sum > 0) k[i] = 1 + c * static_cast<double>(adj.neighbours(i).size()) / sum;
  }
  return k;
}

// Scales to [0, 1] between the 1st and the 99th percentile (values outside are clipped): one
// outlier at either end must not squash the rest of the map into one colour.
std::vector<double> normalised(std::vector<double> v) {
  if (v.empty()) return v;
  std::vector<double> sorted = v;
  const std::size_t p1 = (sorted.size() - 1) / 100, p99 = (sorted.size() - 1) * 99 / 100;
  std::nth_element(sorted.begin(), sorted.begin() + p99, sorted.end());
  const double b = sorted[p99];
  std::nth_element(sorted.begin(), sorted.begin() + p1, sorted.begin() + p99);
  const double a = sorted[p1];
  for (double& x : v) x = b > a ? std::clamp((x - a) / (b - a), 0.0, 1.0) : 0.0;
  return v;
}

// The n×n buffers of one decomposition (L then its eigenvectors, their rows, dsyevd's work),
// kept by each thread across the ten: fresh 8 MB allocations cost a page fault per 4 kB.
struct SpectralWorkspace {
  std::vector<double> matrix, rows, work;
  std::vector<lapack_int> iwork;
};

std::vector<double> spectral_irregularity(const Mesh& mesh, SpectralWorkspace& ws) {
  const std::size_t n = mesh.vertex_count();
  if (n == 0) return {};
  const VertexAdjacency adj(mesh);
  const double diag = bounding_box(mesh).diagonal();
  const double min_d2 = 1e-24 * diag * diag;
  auto weight = [&](std::size_t i, std::size_t j) {
    const Vec3 d = mesh.positions[i] - mesh.positions[j];
    return 1.0 / std::max(dot(d, d), min_d2);
  };
  std::vector<double>& B = ws.matrix;  // L, column-major; dsyevd overwrites it with the eigenvectors
  B.assign(n * n, 0.0);
  for (std::size_t i = 0; i < n; ++i)
    for (std::uint32_t j : adj.neighbours(i)) {
      const double w = weight(i, j);
      B[i + j * n] = -w;
      B[i + i * n] += w;
    }
  std::vector<double> lambda(n);
  const auto ln = static_cast<lapack_int>(n);
  double lwork = 0;
  lapack_int liwork = 0;
  if (LAPACKE_dsyevd_work(LAPACK_COL_MAJOR, 'V', 'U', ln, B.data(), ln, lambda.data(), &lwork, -1, &liwork,
                          -1) != 0)
    throw std::runtime_error("spectral saliency: the eigensolver's workspace query failed");
  ws.work.resize(static_cast<std::size_t>(lwork));
  ws.iwork.resize(static_cast<std::size_t>(liwork));
  if (LAPACKE_dsyevd_work(LAPACK_COL_MAJOR, 'V', 'U', ln, B.data(), ln, lambda.data(), ws.work.data(),
                          static_cast<lapack_int>(ws.work.size()), ws.iwork.data(),
                          static_cast<lapack_int>(ws.iwork.size())) != 0)
    throw std::runtime_error("spectral saliency: the eigensolver did not converge");
  // Eigenvalues closer than tol (rounding: a few ε·‖L‖) are one repeated eigenvalue, as a symmetric
  // mesh has; those within tol of 0 are the null space, one per connected part. (Pairs just above
  // tol are still ill-determined, their vectors turned by ~ε·‖L‖ / gap: measured on a UV sphere,
  // 6e-4 of the maximum; on the shared scans no pair comes that close.)
  const double tol = 64 * std::numeric_limits<double>::epsilon() *
                     std::max(std::fabs(lambda.front()), std::fabs(lambda.back()));
  // λ0 := λ1 (paper), for every null eigenvalue: their logs would be of rounding noise.
  std::size_t nulls = 0;
  while (nulls < n && std::fabs(lambda[nulls]) <= tol) ++nulls;
  nulls = std::max<std::size_t>(nulls, 1);
  std::vector<double> log_spectrum(n);
  for (std::size_t f = 0; f < n; ++f)
    log_spectrum[f] = std::log(std::max(std::fabs(lambda[f < nulls ? std::min(nulls, n - 1) : f]), 1e-300));
  std::vector<double> weights(n);
  for (std::size_t f = 0; f < n; ++f) {
    double mean = 0;
    for (int d = -4; d <= 4; ++d)
      mean += log_spectrum[std::clamp<std::ptrdiff_t>(static_cast<std::ptrdiff_t>(f) + d, 0, n - 1)];
    weights[f] = std::exp(std::fabs(log_spectrum[f] - mean / 9));
  }
  // Eigenvectors of a repeated eigenvalue are any basis of its eigenspace, and e^R differs along a
  // cluster (the moving average does), so S would depend on the solver's choice of basis. One
  // weight per cluster (their mean) makes S = Σ w_c·P_c, P_c the cluster's projector: basis-free.
  for (std::size_t a = 0, b; a < n; a = b) {
    for (b = a + 1; b < n && (b < nulls || lambda[b] - lambda[b - 1] <= tol);) ++b;
    if (b - a < 2) continue;
    double mean = 0;
    for (std::size_t f = a; f < b; ++f) mean += weights[f];
    std::fill(weights.begin() + a, weights.begin() + b, mean / (b - a));
  }
  // Rows of B, contiguous for the edge products S(i,j) (step 5); S is symmetric, so each edge
  // is summed once, for both of its ends.
  std::vector<double>& rows = ws.rows;
  rows.resize(n * n);
  for (std::size_t f = 0; f < n; ++f)
    for (std::size_t i = 0; i < n; ++i) rows[i * n + f] = B[i + f * n];
  std::vector<double> s(n, 0);
  for (std::size_t i = 0; i < n; ++i)
    for (std::uint32_t j : adj.neighbours(i)) {
      if (j <= i) continue;
      const double* bi = &rows[i * n];
      const double* bj = &rows[std::size_t(j) * n];
      double sij = 0;
      for (std::size_t f = 0; f < n; ++f) sij += bi[f] * weights[f] * bj[f];
      const double term = std::fabs(sij * weight(i, j));
      s[i] += term;
      s[j] += term;
    }
  return s;
}

}  // namespace

std::vector<double> spectral_irregularity(const Mesh& mesh) {
  SpectralWorkspace ws;
  return spectral_irregularity(mesh, ws);
}

std::vector<float> spectral_saliency(const Mesh& input, const SpectralOptions& options,
                                     const RunContext& run) {
  run.report("saliency", 0.0);
  run.check();
  const Mesh mesh = canonical_copy(input);
  const Mesh work = working_mesh(mesh, options.working_vertices, run);
  run.check();
  // Each decomposition holds a few n×n matrices and takes n³ steps: a mesh the collapse cannot
  // reduce (thousands of loose triangles, none sharing an edge) would ask for gigabytes and hours.
  const std::size_t most = kMostWorkingVertices * std::max<std::size_t>(options.working_vertices, 1) / 1000;
  if (work.vertex_count() > most)
    throw InputError(SettingId::saliency,
                     "spectral could only simplify the model to " + std::to_string(work.vertex_count()) +
                         " vertices, more than the " + std::to_string(most) +
                         " it can work on (the model's triangles share too few edges); use {saliency} lee05 "
                         "or uniform");
  run.report("saliency", 0.1);
  const VertexAdjacency adj(work);
  const std::vector<double> k = scale_factors(work, adj);
  const std::vector<double> ones(work.vertex_count(), 1.0);
  const double eps = kScaleOverEdge * mean_edge(work, adj);
  const PointGrid grid(work.positions, 2.5 * std::sqrt(5 * 2.5) * eps);
  // Ten meshes, M(t) and M(k·t) at five scales; their spectra are independent: in parallel, one
  // decomposition per TBB thread. OpenBLAS's own threads inside would oversubscribe the cores and
  // spin (measured: slower than either alone), so they are turned off; this file is the process's
  // only user of BLAS.
  std::vector<Mesh> meshes(10);
  for (int job = 0; job < 10; ++job) {
    meshes[job].triangles = work.triangles;
    meshes[job].positions = smoothed(work, grid, (job / 2 + 1) * eps * eps, job % 2 == 0 ? ones : k);
  }
  // Where the smoothing radius is below every edge, a scale leaves the mesh as it was: equal
  // meshes have equal spectra, so each distinct one is decomposed once.
  std::vector<int> same(10), distinct;
  for (int job = 0; job < 10; ++job) {
    same[job] = job;
    for (int earlier : distinct)
      if (same_positions(meshes[earlier].positions, meshes[job].positions)) same[job] = earlier;
    if (same[job] == job) distinct.push_back(job);
  }
  std::vector<std::vector<double>> s(10);
  openblas_set_num_threads(1);
  tbb::enumerable_thread_specific<SpectralWorkspace> workspaces;
  tbb::parallel_for(std::size_t(0), distinct.size(), [&](std::size_t d) {
    run.check();
    s[distinct[d]] = spectral_irregularity(meshes[distinct[d]], workspaces.local());
  });
  for (int job = 0; job < 10; ++job) s[job] = s[same[job]];
  run.check();
  run.report("saliency", 0.8);
  std::vector<double> multi(work.vertex_count(), 0);
  for (int scale = 0; scale < 5; ++scale) {
    std::vector<double> level(work.vertex_count());
    for (std::size_t i = 0; i < level.size(); ++i)
      level[i] = std::fabs(std::log(s[2 * scale + 1][i] + 1e-300) - std::log(s[2 * scale][i] + 1e-300));
    level = normalised(std::move(level));
    for (std::size_t i = 0; i < multi.size(); ++i) multi[i] += level[i];
  }
  // Back to the original vertices, then one more Gaussian pass at t1 on the original surface.
  const std::vector<double> mapped = transfer_values(work, multi, mesh);
  const PointGrid fine_grid(mesh.positions, 2.5 * eps);
  std::vector<double> out(mesh.vertex_count());
  tbb::parallel_for(
      tbb::blocked_range<std::size_t>(0, out.size(), 1024), [&](const tbb::blocked_range<std::size_t>& r) {
        for (std::size_t i = r.begin(); i != r.end(); ++i) {
          double sum = 0, wsum = 0;
          fine_grid.for_each_within(mesh.positions[i], 2.5 * eps, [&](std::uint32_t j, double d2) {
            const double w = std::exp(-d2 / (2 * eps * eps));
            sum += w * mapped[j];
            wsum += w;
          });
          out[i] = wsum > 0 ? sum / wsum : mapped[i];
        }
      });
  out = normalised(std::move(out));
  run.report("saliency", 1.0);
  return std::vector<float>(out.begin(), out.end());
}

}  // namespace salient::core
