#include "core/segment/mesh_split.hpp"

#include <map>
#include <utility>

namespace salient::core {
namespace {

// Builds one part, reusing a vertex per source vertex and per cut edge so the part stays
// connected where the source was.
class PartBuilder {
 public:
  PartBuilder(const Mesh& source, std::span<const float> values) : source_(source), values_(values) {}

  std::uint32_t vertex(std::uint32_t v) {
    auto [it, fresh] = own_.try_emplace(v, 0);
    if (fresh) it->second = push(source_.positions[v], values_[v]);
    return it->second;
  }
  // The point on edge (a, b) where the plane's distance is zero.
  std::uint32_t on_edge(std::uint32_t a, std::uint32_t b, double da, double db) {
    const auto key = a < b ? std::make_pair(a, b) : std::make_pair(b, a);
    auto [it, fresh] = cut_.try_emplace(key, 0);
    if (fresh) {
      const double t = da / (da - db);
      const Vec3 p = source_.positions[a] + (source_.positions[b] - source_.positions[a]) * t;
      it->second = push(p, static_cast<float>(values_[a] + (values_[b] - values_[a]) * t));
    }
    return it->second;
  }
  void face(std::uint32_t a, std::uint32_t b, std::uint32_t c) {
    part.mesh.triangles.push_back({a, b, c});
    part.area += 0.5 * norm(cross(part.mesh.positions[b] - part.mesh.positions[a],
                                  part.mesh.positions[c] - part.mesh.positions[a]));
  }

  MeshPart part;

 private:
  std::uint32_t push(const Vec3& p, float value) {
    part.mesh.positions.push_back(p);
    part.values.push_back(value);
    return static_cast<std::uint32_t>(part.mesh.positions.size() - 1);
  }
  const Mesh& source_;
  std::span<const float> values_;
  std::map<std::uint32_t, std::uint32_t> own_;
  std::map<std::pair<std::uint32_t, std::uint32_t>, std::uint32_t> cut_;
};

// Side 0 where distance(p) < 0.
template <class Distance>
std::array<MeshPart, 2> split_by(const Mesh& mesh, std::span<const float> values, const Distance& distance) {
  PartBuilder parts[2] = {PartBuilder(mesh, values), PartBuilder(mesh, values)};
  for (const Triangle& t : mesh.triangles) {
    double d[3];
    int side[3], count1 = 0;
    for (int k = 0; k < 3; ++k) {
      d[k] = distance(mesh.positions[t[k]]);
      side[k] = d[k] < 0 ? 0 : 1;
      count1 += side[k];
    }
    if (count1 == 0 || count1 == 3) {
      PartBuilder& p = parts[side[0]];
      p.face(p.vertex(t[0]), p.vertex(t[1]), p.vertex(t[2]));
      continue;
    }
    // One vertex (`lone`) is alone on its side: a triangle there, a quad (two triangles) on the
    // other, keeping the face's winding.
    const int lone_side = count1 == 1 ? 1 : 0;
    int k = 0;
    while (side[k] != lone_side) ++k;
    const std::uint32_t a = t[k], b = t[(k + 1) % 3], c = t[(k + 2) % 3];
    const double da = d[k], db = d[(k + 1) % 3], dc = d[(k + 2) % 3];
    PartBuilder& lone = parts[lone_side];
    PartBuilder& rest = parts[1 - lone_side];
    const std::uint32_t ab_l = lone.on_edge(a, b, da, db), ca_l = lone.on_edge(a, c, da, dc);
    lone.face(lone.vertex(a), ab_l, ca_l);
    const std::uint32_t ab_r = rest.on_edge(a, b, da, db), ca_r = rest.on_edge(a, c, da, dc);
    const std::uint32_t vb = rest.vertex(b), vc = rest.vertex(c);
    rest.face(ab_r, vb, vc);
    rest.face(ab_r, vc, ca_r);
  }
  return {std::move(parts[0].part), std::move(parts[1].part)};
}

}  // namespace

std::array<MeshPart, 2> split_mesh(const Mesh& mesh, std::span<const float> values, const CutPlane& plane) {
  return split_by(mesh, values, [&](const Vec3& p) { return plane.distance(p); });
}

MeshPart crop_z(const Mesh& mesh, std::span<const float> values, double z0, double z1) {
  auto above = std::move(split_by(mesh, values, [&](const Vec3& p) { return p.z - z0; })[1]);
  return std::move(split_by(above.mesh, above.values, [&](const Vec3& p) { return p.z - z1; })[0]);
}

}  // namespace salient::core
