#include "core/pipeline/auto_orient.hpp"

#include <algorithm>
#include <cmath>
#include <span>

#include "core/pipeline/placed_model.hpp"

namespace salient::core {

OrientationReport choose_orientation(const SliceSettings& settings, const PrinterProfile& printer,
                                     const RunContext& run) {
  run.report("orient", 0);
  MeshOptions raw;  // the file's own frame (up z, scale 1): candidate directions are expressed in it
  raw.model = settings.plan.mesh.model;
  const PlacedModel model = load_placed(raw);
  const Mesh& mesh = model.loaded.mesh;
  OrientationReport report;
  CandidateOptions options;
  options.scale = settings.plan.mesh.scale;
  options.contact_tolerance = printer.first_layer_height / 2;  // layers are cut at mid-height
  // Candidates are compared at one scale. With a target height, that is the scale at which the
  // tallest of them has that height; the print keeps it (report.scale). The bases' tolerances are
  // in print millimetres, so they are found at the scale the three axes give, close to the final one.
  const auto tallest = [&](std::span<const Vec3> ds) {
    double out = 0;
    for (const Vec3& d : ds) {
      double lo = INFINITY, hi = -INFINITY;
      for (const Vec3& p : mesh.positions) lo = std::min(lo, dot(p, d)), hi = std::max(hi, dot(p, d));
      out = std::max(out, (hi - lo) / norm(d));
    }
    return out;
  };
  const auto target = settings.plan.mesh.height;
  if (target && tallest(candidate_directions(mesh)) > 0)
    options.scale = *target / tallest(candidate_directions(mesh));
  const std::vector<Vec3> directions = candidate_ups(mesh, options);
  std::optional<double> common_scale;
  if (target && tallest(directions) > 0) common_scale = options.scale = *target / tallest(directions);
  const double n = static_cast<double>(directions.size());
  const double units = options.scale * options.scale;  // mm² of print per unit² of the file
  for (std::size_t i = 0; i < directions.size(); ++i) {
    run.check();
    OrientationScore c;
    c.up = directions[i];
    c.contact_area = bed_contact_area(mesh, c.up, options.contact_tolerance / options.scale) * units;
    SliceSettings s = settings;
    s.plan.mesh.up = direction_text(c.up);
    if (common_scale) s.plan.mesh.height.reset(), s.plan.mesh.scale = *common_scale;
    s.support = true;  // time with support: an orientation that needs more of it pays for it
    s.artefacts = false;
    const RunContext inner{run.cancel, [&](std::string_view, double f) {
                             run.report("orient",
                                        (static_cast<double>(i) + std::clamp(f, 0.0, 1.0) * 0.9) / n);
                           }};
    const SliceResult r = slice_model(s, printer, inner);
    c.minutes = r.print_seconds / 60;
    c.layers = r.layers;
    MeshOptions placed_options = s.plan.mesh;
    PlacedModel placed = load_placed(placed_options);
    std::vector<double> boundaries{0};
    boundaries.insert(boundaries.end(), r.z.begin(), r.z.end());
    c.volume_score = volumetric_score(placed.loaded.mesh, boundaries);
    report.candidates.push_back(c);
  }
  report.best = score_orientations(report.candidates, surface_area(mesh) * units);
  report.up = direction_text(report.candidates[report.best].up);
  report.scale = common_scale;
  run.report("orient", 1);
  return report;
}

}  // namespace salient::core
