// ZProfile construction in one pass over the faces: each face visits only the cells it spans,
// and evaluates the plane crossings on the cell boundaries in closed form.
//
// Within a face with vertices sorted by height (z0 ≤ z1 ≤ z2), the cross-section at height z is
// a segment from the long edge (v0v2) to a short edge (v0v1 below z1, v1v2 above). Saliency is
// linear along it, so the maximum over a slab lies at a slab end or at z1; the face's area
// below z is A·(z−z0)²/((z2−z0)(z1−z0)) under z1 and A·(1 − (z2−z)²/((z2−z0)(z2−z1))) above.
// The saliency weight of a piece is the mean saliency of its mid-height cross-section.
#include "core/slicing/z_profile.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <sstream>

#include "core/common/input_error.hpp"

namespace salient::core {
namespace {

struct SortedFace {
  double z[3];
  double s[3];

  double s_long(double h) const {
    return z[2] > z[0] ? s[0] + (s[2] - s[0]) * (h - z[0]) / (z[2] - z[0]) : s[0];
  }
  double s_short(double h) const {
    if (h <= z[1]) return z[1] > z[0] ? s[0] + (s[1] - s[0]) * (h - z[0]) / (z[1] - z[0]) : s[1];
    return z[2] > z[1] ? s[1] + (s[2] - s[1]) * (h - z[1]) / (z[2] - z[1]) : s[1];
  }
  double s_max_at(double h) const { return std::max(s_long(h), s_short(h)); }
  double s_mean_at(double h) const { return 0.5 * (s_long(h) + s_short(h)); }
  // Fraction of the face's area below height h.
  double area_below(double h) const {
    if (h <= z[0]) return 0;
    if (h >= z[2]) return 1;
    const double span = z[2] - z[0];
    if (h <= z[1]) return (h - z[0]) * (h - z[0]) / (span * (z[1] - z[0]));
    return 1 - (z[2] - h) * (z[2] - h) / (span * (z[2] - z[1]));
  }
};

struct Accumulator {
  std::vector<float> S, S_geo, C;
  std::vector<double> A, A_geo;
  explicit Accumulator(int cells) : S(cells, 0), S_geo(cells, 0), C(cells, 0), A(cells, 0), A_geo(cells, 0) {}

  void add(int k, double cos, double s_max, double projected_area, double s_mean) {
    C[k] = std::max(C[k], static_cast<float>(cos));
    S[k] = std::max(S[k], static_cast<float>(s_max));
    S_geo[k] = 1;
    A[k] += projected_area * s_mean;
    A_geo[k] += projected_area;
  }
};

ProfileChannel make_channel(std::vector<float> S, const std::vector<double>& A) {
  ProfileChannel c;
  c.A_prefix.resize(A.size() + 1, 0);
  for (std::size_t k = 0; k < A.size(); ++k) c.A_prefix[k + 1] = c.A_prefix[k] + A[k];
  c.S_max = RangeMax(S);
  c.S = std::move(S);
  return c;
}

std::string mm(double v) {
  std::ostringstream s;
  s << v;
  return s.str();
}

}  // namespace

ZProfile ZProfile::build(const Mesh& mesh, std::span<const float> saliency, const SlicingParams& params,
                         const RunContext& run, double height) {
  validate(params);
  if (saliency.size() != mesh.vertex_count())
    throw std::invalid_argument("ZProfile::build: one saliency value per vertex is required");
  ZProfile p;
  p.params_ = params;
  p.min_cells_ = params.min_cells();
  p.max_cells_ = params.max_cells();
  const BoundingBox box = bounding_box(mesh);
  p.height_ = height > 0 ? height : box.max.z;
  const double delta = params.grid;
  if (!(p.height_ >= params.min_layer))
    throw InputError(
        "model", {},
        "is " + mm(p.height_) + " mm tall, lower than {min_layer} " + mm(params.min_layer) + " mm");
  // A height within a millionth of a cell of the grid counts as on it.
  p.cells_ = static_cast<int>(std::ceil(p.height_ / delta - 1e-6));
  if (p.fewest_layers() > p.most_layers())
    throw InputError("model", {},
                     "height " + mm(p.height_) + " mm cannot be cut into layers of " + mm(params.min_layer) +
                         " to " + mm(params.max_layer) + " mm");

  Accumulator acc(p.cells_);
  const double flat_eps = 1e-9 * std::max(1.0, p.height_);
  for (std::size_t t = 0; t < mesh.triangle_count(); ++t) {
    if (t % 65536 == 0) {
      run.check();
      run.report("profile", static_cast<double>(t) / mesh.triangle_count());
    }
    const Triangle& tri = mesh.triangles[t];
    const Vec3 an = area_normal(mesh, t);
    const double double_area = norm(an);
    if (!(double_area > 0) || !std::isfinite(double_area)) {
      ++p.dropped_faces_;
      continue;
    }
    std::array<int, 3> order{0, 1, 2};
    std::sort(order.begin(), order.end(),
              [&](int a, int b) { return mesh.positions[tri[a]].z < mesh.positions[tri[b]].z; });
    SortedFace f;
    for (int k = 0; k < 3; ++k) {
      f.z[k] = mesh.positions[tri[order[k]]].z;
      f.s[k] = saliency[tri[order[k]]];
    }
    const double cos = std::fabs(an.z) / double_area;
    const double projected = 0.5 * std::fabs(an.z);
    if (f.z[2] - f.z[0] <= flat_eps) {
      // A flat face on the bed or the top is printed exactly by every plan (it is the first or
      // last boundary), so it adds nothing; any other flat face belongs to the cell it lies in.
      if (f.z[0] <= flat_eps || f.z[0] >= p.height_ - flat_eps) continue;
      const int k = std::min(static_cast<int>(f.z[0] / delta), p.cells_ - 1);
      acc.add(k, cos, std::max({f.s[0], f.s[1], f.s[2]}), projected, (f.s[0] + f.s[1] + f.s[2]) / 3);
      continue;
    }
    const int k_lo = std::clamp(static_cast<int>(std::floor(f.z[0] / delta)), 0, p.cells_ - 1);
    const int k_hi = std::clamp(static_cast<int>(std::ceil(f.z[2] / delta)) - 1, k_lo, p.cells_ - 1);
    double below = 0;
    double s_at_lo = f.s_max_at(std::max(f.z[0], k_lo * delta));
    for (int k = k_lo; k <= k_hi; ++k) {
      const double za = std::max(f.z[0], k * delta);
      const double zb = k == k_hi ? f.z[2] : std::min(f.z[2], (k + 1) * delta);
      const double s_at_hi = f.s_max_at(zb);
      double s_max = std::max(s_at_lo, s_at_hi);
      if (f.z[1] > za && f.z[1] < zb) s_max = std::max(s_max, f.s_max_at(f.z[1]));
      const double below_hi = f.area_below(zb);
      acc.add(k, cos, s_max, projected * (below_hi - below), f.s_mean_at(0.5 * (za + zb)));
      below = below_hi;
      s_at_lo = s_at_hi;
    }
  }
  p.salient_ = make_channel(std::move(acc.S), acc.A);
  p.geometric_ = make_channel(std::move(acc.S_geo), acc.A_geo);
  p.C_max_ = RangeMax(acc.C);
  p.C_ = std::move(acc.C);
  run.report("profile", 1.0);
  return p;
}

}  // namespace salient::core

namespace salient::core {
namespace {

ProfileChannel channel_window(const ProfileChannel& c, int first, int last) {
  std::vector<double> A(last - first);
  for (int k = first; k < last; ++k) A[k - first] = c.A_prefix[k + 1] - c.A_prefix[k];
  return make_channel(std::vector<float>(c.S.begin() + first, c.S.begin() + last), A);
}

}  // namespace

ZProfile ZProfile::window(int first, int last) const {
  if (first < 0 || last > cells_ || first >= last)
    throw std::invalid_argument("ZProfile::window: bad cell range");
  ZProfile p;
  p.params_ = params_;
  p.min_cells_ = min_cells_;
  p.max_cells_ = max_cells_;
  p.cells_ = last - first;
  p.height_ = z(last) - z(first);
  if (p.fewest_layers() > p.most_layers())
    throw InputError("model", {},
                     "the slab from " + mm(z(first)) + " to " + mm(z(last)) +
                         " mm cannot be cut into layers of " + mm(params_.min_layer) + " to " +
                         mm(params_.max_layer) + " mm");
  p.salient_ = channel_window(salient_, first, last);
  p.geometric_ = channel_window(geometric_, first, last);
  p.C_.assign(C_.begin() + first, C_.begin() + last);
  p.C_max_ = RangeMax(p.C_);
  return p;
}

}  // namespace salient::core
