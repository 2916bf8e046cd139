#include "core/orient/orientation.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <cstdio>

#include "core/geometry/mesh_section.hpp"
#include "core/mesh/convex_hull.hpp"
#include "core/mesh/placement.hpp"
#include "core/orient/planar_regions.hpp"

namespace salient::core {
namespace {

struct Facet {
  Vec3 n;  // unit normal
  double area;
};

std::vector<Facet> facets(const Mesh& mesh) {
  std::vector<Facet> out;
  out.reserve(mesh.triangle_count());
  for (const Triangle& t : mesh.triangles) {
    const Vec3 c =
        cross(mesh.positions[t[1]] - mesh.positions[t[0]], mesh.positions[t[2]] - mesh.positions[t[0]]);
    const double twice = norm(c);
    if (twice > 0 && std::isfinite(twice)) out.push_back({c / twice, twice / 2});
  }
  return out;
}

// The principal direction (largest eigenvalue) of Σ a·n·nᵀ over the facets selected.
template <typename Select>
std::array<Vec3, 3> principal_axes(const std::vector<Facet>& fs, Select&& selected) {
  Eigen::Matrix3d m = Eigen::Matrix3d::Zero();
  for (std::size_t i = 0; i < fs.size(); ++i) {
    if (!selected(i)) continue;
    const Eigen::Vector3d n(fs[i].n.x, fs[i].n.y, fs[i].n.z);
    m += fs[i].area * n * n.transpose();
  }
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver(m);
  std::array<Vec3, 3> out;
  for (int k = 0; k < 3; ++k) {  // largest eigenvalue first
    const Eigen::Vector3d v = solver.eigenvectors().col(2 - k);
    out[static_cast<std::size_t>(k)] = {v.x(), v.y(), v.z()};
  }
  return out;
}

Vec3 unit(const Vec3& v) {
  return v / norm(v);
}

// Within `degrees` of one of `list`.
bool near_any(const std::vector<Vec3>& list, const Vec3& d, double degrees) {
  const double limit = std::cos(degrees * M_PI / 180);
  return std::any_of(list.begin(), list.end(), [&](const Vec3& e) { return dot(unit(e), unit(d)) > limit; });
}

// The centre of the enclosed volume; of the surface where the mesh encloses none (open meshes).
Vec3 centre_of_mass(const Mesh& mesh) {
  Vec3 moment{}, surface{};
  double volume = 0, area = 0;
  for (std::size_t f = 0; f < mesh.triangle_count(); ++f) {
    const Triangle& t = mesh.triangles[f];
    const Vec3 &a = mesh.positions[t[0]], &b = mesh.positions[t[1]], &c = mesh.positions[t[2]];
    const double v = dot(a, cross(b, c)) / 6;  // the tetrahedron (origin, a, b, c)
    volume += v;
    moment += (a + b + c) * (v / 4);
    const double s = norm(area_normal(mesh, f)) / 2;
    area += s;
    surface += (a + b + c) * (s / 3);
  }
  if (volume > 0) return moment / volume;
  return area > 0 ? surface / area : Vec3{};
}

// The area of the convex hull, on the bed, of the points within `band` of it when `up` is up:
// what the model stands on. Four hooves span a cow's body; its round back touches at a speck.
double footprint_area(const Mesh& mesh, const Vec3& up, double band) {
  const Vec3 u = unit(up);
  const Vec3 a = unit(std::fabs(u.x) < 0.9 ? cross(u, Vec3{1, 0, 0}) : cross(u, Vec3{0, 1, 0}));
  const Vec3 b = cross(u, a);
  double lowest = INFINITY;
  for (const Vec3& p : mesh.positions) lowest = std::min(lowest, dot(p, u));
  std::vector<std::pair<double, double>> pts;
  for (const Vec3& p : mesh.positions)
    if (dot(p, u) <= lowest + band) pts.emplace_back(dot(p, a), dot(p, b));
  std::sort(pts.begin(), pts.end());
  pts.erase(std::unique(pts.begin(), pts.end()), pts.end());
  if (pts.size() < 3) return 0;
  // Andrew's monotone chain: lower hull, then upper.
  const auto turn = [](const auto& o, const auto& p, const auto& q) {
    return (p.first - o.first) * (q.second - o.second) - (p.second - o.second) * (q.first - o.first);
  };
  std::vector<std::pair<double, double>> hull(2 * pts.size());
  std::size_t k = 0;
  for (std::size_t i = 0; i < pts.size(); ++i) {
    while (k >= 2 && turn(hull[k - 2], hull[k - 1], pts[i]) <= 0) --k;
    hull[k++] = pts[i];
  }
  for (std::size_t i = pts.size() - 1, lower = k + 1; i-- > 0;) {
    while (k >= lower && turn(hull[k - 2], hull[k - 1], pts[i]) <= 0) --k;
    hull[k++] = pts[i];
  }
  double twice = 0;
  for (std::size_t i = 0; i + 1 < k; ++i)
    twice += hull[i].first * hull[i + 1].second - hull[i + 1].first * hull[i].second;
  return std::fabs(twice) / 2;
}

// The model's extent along `up`.
double extent_along(const Mesh& mesh, const Vec3& up) {
  const Vec3 u = unit(up);
  double lo = INFINITY, hi = -INFINITY;
  for (const Vec3& p : mesh.positions) lo = std::min(lo, dot(p, u)), hi = std::max(hi, dot(p, u));
  return hi > lo ? hi - lo : 0;
}

}  // namespace

std::array<Vec3, 3> candidate_directions(const Mesh& mesh) {
  const std::vector<Facet> fs = facets(mesh);
  if (fs.empty()) return {Vec3{1, 0, 0}, Vec3{0, 1, 0}, Vec3{0, 0, 1}};
  // Seeds, farthest first (weighted by area): the largest facet, then the facet farthest from
  // it, then the one farthest from both. Principal axes of the whole would be arbitrary for a
  // cube, whose Σ a·n·nᵀ is a multiple of the identity.
  const auto distance = [](const Vec3& n, const Vec3& c) { return 1 - dot(n, c) * dot(n, c); };
  std::array<Vec3, 3> centres{};
  std::size_t seed = 0;
  for (std::size_t i = 1; i < fs.size(); ++i)
    if (fs[i].area > fs[seed].area) seed = i;
  centres[0] = fs[seed].n;
  for (std::size_t k = 1; k < 3; ++k) {
    double best = -1;
    for (const Facet& f : fs) {
      double d = 2;
      for (std::size_t j = 0; j < k; ++j) d = std::min(d, distance(f.n, centres[j]));
      if (f.area * d > best) best = f.area * d, centres[k] = f.n;
    }
    if (!(best > 0)) centres[k] = principal_axes(fs, [](std::size_t) { return true; })[k];
  }
  std::vector<int> cluster(fs.size(), -1);
  std::array<double, 3> weight{};
  for (int iteration = 0; iteration < 30; ++iteration) {
    bool moved = false;
    weight = {};
    for (std::size_t i = 0; i < fs.size(); ++i) {
      int best = 0;
      double best_d = 2;
      for (int k = 0; k < 3; ++k) {
        const double d = distance(fs[i].n, centres[static_cast<std::size_t>(k)]);  // n and −n alike
        if (d < best_d) best_d = d, best = k;
      }
      moved = moved || cluster[i] != best;
      cluster[i] = best;
      weight[static_cast<std::size_t>(best)] += fs[i].area;
    }
    if (!moved) break;
    for (int k = 0; k < 3; ++k)
      if (weight[static_cast<std::size_t>(k)] > 0)
        centres[static_cast<std::size_t>(k)] =
            principal_axes(fs, [&](std::size_t i) { return cluster[i] == k; })[0];
  }
  // Heaviest first, then made orthonormal by Gram–Schmidt in that order.
  std::array<int, 3> order{0, 1, 2};
  std::sort(order.begin(), order.end(), [&](int a, int b) {
    return weight[static_cast<std::size_t>(a)] > weight[static_cast<std::size_t>(b)];
  });
  const Vec3 a = unit(centres[static_cast<std::size_t>(order[0])]);
  Vec3 b =
      centres[static_cast<std::size_t>(order[1])] - a * dot(centres[static_cast<std::size_t>(order[1])], a);
  if (norm(b) < 1e-9) {  // degenerate (all normals in one cluster): any perpendicular
    b = std::abs(a.x) < 0.9 ? cross(a, Vec3{1, 0, 0}) : cross(a, Vec3{0, 1, 0});
  }
  b = unit(b);
  return {a, b, unit(cross(a, b))};
}

double bed_contact_area(const Mesh& mesh, const Vec3& up, double tolerance) {
  const Vec3 u = unit(up);
  double lowest = INFINITY;
  for (const Vec3& p : mesh.positions) lowest = std::min(lowest, dot(p, u));
  const double top = lowest + tolerance;
  double area = 0;
  for (const Triangle& t : mesh.triangles) {
    const std::array<Vec3, 3> p{mesh.positions[t[0]], mesh.positions[t[1]], mesh.positions[t[2]]};
    const Vec3 c = cross(p[1] - p[0], p[2] - p[0]);
    if (!(dot(c, u) < 0)) continue;  // faces up or on edge: holds nothing on the bed
    // The part of the triangle at or below `top` (Sutherland–Hodgman against one plane).
    std::array<Vec3, 4> clipped{};
    std::size_t n = 0;
    for (std::size_t i = 0; i < 3; ++i) {
      const Vec3 &a = p[i], &b = p[(i + 1) % 3];
      const double da = dot(a, u) - top, db = dot(b, u) - top;
      if (da <= 0) clipped[n++] = a;
      if ((da < 0 && db > 0) || (da > 0 && db < 0)) clipped[n++] = a + (b - a) * (da / (da - db));
    }
    Vec3 twice{};
    for (std::size_t i = 1; i + 1 < n; ++i)
      twice += cross(clipped[i] - clipped[0], clipped[i + 1] - clipped[0]);
    area += -dot(twice, u) / 2;  // projected onto the bed
  }
  return area;
}

Vec3 pick_up_sign(const Mesh& mesh, const Vec3& d, const CandidateOptions& o) {
  const double tolerance = o.contact_tolerance / o.scale;
  const double plus = bed_contact_area(mesh, d, tolerance),
               minus = bed_contact_area(mesh, d * -1.0, tolerance);
  if (std::fabs(plus - minus) > 0.01 * surface_area(mesh)) return minus > plus ? d * -1.0 : d;
  // Neither side is a base: the side it stands on more widely (its lowest 2 %), so that a cow is
  // stood on its hooves and a bust on its neck rather than on a round back or crown.
  const double band = 0.02 * extent_along(mesh, d);
  const double foot_plus = footprint_area(mesh, d, band), foot_minus = footprint_area(mesh, d * -1.0, band);
  if (foot_plus != foot_minus) return foot_minus > foot_plus ? d * -1.0 : d;
  return minus > plus ? d * -1.0 : d;
}

std::vector<Vec3> base_directions(const Mesh& mesh, const CandidateOptions& o) {
  const double tolerance = o.contact_tolerance / o.scale;
  // A base is flat to within the first layer (twice the contact tolerance, which is half of it):
  // the printer presses that much into the bed. The angle only keeps a fold from joining.
  const double flat = 2 * tolerance, flat_angle = 10 * M_PI / 180;
  const Vec3 mass = centre_of_mass(mesh);
  std::vector<std::pair<double, Vec3>> bases;  // area, up
  // A region is a base if it lies at the bottom once turned down and the model stands over it.
  const auto offer = [&](const Mesh& m, const std::vector<PlanarRegion>& regions, double total) {
    for (const PlanarRegion& r : regions) {
      if (r.area < o.min_share * total) break;  // largest first
      const Vec3 up = r.normal * -1.0;
      double lowest = INFINITY;
      for (const Vec3& p : mesh.positions) lowest = std::min(lowest, dot(p, up));
      // A hull facet can span feet or bumps that touch the bed at specks: it is a base only
      // where the first layer prints a real share of the model.
      if (dot(r.centroid, up) - lowest <= flat && projects_inside(m, r, mass) &&
          bed_contact_area(mesh, up, tolerance) >= 0.5 * o.min_share * surface_area(mesh))
        bases.emplace_back(r.area, up);
    }
  };
  offer(mesh, planar_regions(mesh, flat_angle, flat), surface_area(mesh));
  const Mesh hull = convex_hull(mesh.positions);
  offer(hull, planar_regions(hull, flat_angle, flat), surface_area(hull));
  std::stable_sort(bases.begin(), bases.end(),
                   [](const auto& a, const auto& b) { return a.first > b.first; });
  std::vector<Vec3> out;
  for (const auto& [area, up] : bases)
    if (static_cast<int>(out.size()) < o.max_bases && !near_any(out, up, 10)) out.push_back(up);
  return out;
}

std::vector<Vec3> candidate_ups(const Mesh& mesh, const CandidateOptions& o) {
  std::vector<Vec3> out = base_directions(mesh, o);
  for (const Vec3& d : candidate_directions(mesh)) {
    const Vec3 up = pick_up_sign(mesh, d, o);
    if (!near_any(out, up, 1)) out.push_back(up);
  }
  return out;
}

double volumetric_score(const Mesh& placed, std::span<const double> boundaries) {
  const double volume = signed_volume(placed);
  if (!(volume > 0) || boundaries.size() < 2) return 0;
  std::vector<double> mid(boundaries.size() - 1);
  for (std::size_t i = 0; i + 1 < boundaries.size(); ++i) mid[i] = 0.5 * (boundaries[i] + boundaries[i + 1]);
  const std::vector<Section> sections = section_mesh(placed, mid);
  double printed = 0;
  for (std::size_t i = 0; i < sections.size(); ++i) {
    double area = 0;
    for (const Polygon& ring : sections[i].loops) area += signed_area(ring);
    printed += (boundaries[i + 1] - boundaries[i]) * area;
  }
  return 1 - std::abs(printed - volume) / volume;
}

std::size_t score_orientations(std::vector<OrientationScore>& cs, double surface_area) {
  if (cs.empty()) return 0;
  double lo = INFINITY, hi = -INFINITY;
  for (const auto& c : cs) lo = std::min(lo, c.minutes), hi = std::max(hi, c.minutes);
  std::size_t best = 0;
  for (std::size_t i = 0; i < cs.size(); ++i) {
    OrientationScore& c = cs[i];
    c.time_score = hi > lo ? (hi - c.minutes) / (hi - lo) : 1.0;
    c.stability_score = surface_area > 0 ? c.contact_area / surface_area : 0;
    c.score = 0.3 * c.time_score + 0.3 * c.volume_score + 0.3 * c.stability_score;
    if (c.score > cs[best].score) best = i;
  }
  return best;
}

std::string direction_text(const Vec3& d) {
  char buf[96];
  std::snprintf(buf, sizeof buf, "%.6f,%.6f,%.6f", d.x, d.y, d.z);
  return buf;
}

}  // namespace salient::core
