// `salient info MODEL`: counts, size, volume, area, watertightness and every repair made.
#include <CLI/CLI.hpp>
#include <cstdio>
#include <memory>
#include <nlohmann/json.hpp>

#include "clients/cli/cli_options.hpp"
#include "clients/cli/commands.hpp"
#include "core/orient/orientation.hpp"

namespace salient::cli {
namespace {

struct InfoOptions {
  core::MeshOptions mesh;
  bool json = false;
};

nlohmann::json to_json(const core::PlacedModel& m) {
  const core::LoadedMesh& l = m.loaded;
  const core::RepairReport& r = l.repair;
  const core::BoundingBox& b = m.placement.bounds;
  const core::Vec3 size = b.size();
  return {
      {"format", std::string(core::format_name(l.format))},
      {"vertices", l.mesh.vertex_count()},
      {"triangles", l.mesh.triangle_count()},
      {"faces_read", l.polygons},
      {"triangles_read", l.triangles_read},
      {"vertices_read", l.vertices_read},
      {"has_colors", l.mesh.has_colors()},
      {"has_quality", l.mesh.has_quality()},
      {"placement",
       {{"up",
         (m.up_direction ? core::direction_text(*m.up_direction) : std::string(core::up_axis_name(m.up)))},
        {"scale", m.placement.scale}}},
      {"size_mm", {size.x, size.y, size.z}},
      {"bounds_mm", {{"min", {b.min.x, b.min.y, b.min.z}}, {"max", {b.max.x, b.max.y, b.max.z}}}},
      {"volume_mm3", core::signed_volume(l.mesh)},
      {"area_mm2", core::surface_area(l.mesh)},
      {"watertight", r.watertight},
      {"components", r.components},
      {"boundary_edges", r.boundary_edges},
      {"non_manifold_edges", r.non_manifold_edges},
      {"orientable", r.orientable},
      {"repairs",
       {{"vertices_welded", r.vertices_welded},
        {"unused_vertices_removed", r.unused_vertices_removed},
        {"degenerate_faces_removed", r.degenerate_faces_removed},
        {"duplicate_faces_removed", r.duplicate_faces_removed},
        {"holes_filled", r.holes_filled},
        {"faces_flipped", r.faces_flipped}}},
      {"notes", r.lines()},
  };
}

void print_text(const std::string& name, const core::PlacedModel& m) {
  const core::LoadedMesh& l = m.loaded;
  const core::RepairReport& r = l.repair;
  const core::Vec3 size = m.placement.bounds.size();
  std::printf("%s: %s, %zu faces read (%zu triangles)\n", name.c_str(),
              std::string(core::format_name(l.format)).c_str(), l.polygons, l.triangles_read);
  std::printf("  mesh        %zu vertices, %zu triangles, %zu part%s%s%s\n", l.mesh.vertex_count(),
              l.mesh.triangle_count(), r.components, r.components == 1 ? "" : "s",
              l.mesh.has_colors() ? ", vertex colours" : "", l.mesh.has_quality() ? ", vertex quality" : "");
  std::printf("  size        %.6g x %.6g x %.6g mm (up %s, scale %.6g)\n", size.x, size.y, size.z,
              (m.up_direction ? core::direction_text(*m.up_direction) : std::string(core::up_axis_name(m.up)))
                  .c_str(),
              m.placement.scale);
  std::printf("  volume      %.6g mm3\n", core::signed_volume(l.mesh));
  std::printf("  area        %.6g mm2\n", core::surface_area(l.mesh));
  std::printf("  watertight  %s\n", r.watertight ? "yes" : "no");
  const auto notes = r.lines();
  if (notes.empty()) std::printf("  repairs     none needed\n");
  for (std::size_t i = 0; i < notes.size(); ++i)
    std::printf("  %s %s\n", i == 0 ? "repairs    " : "           ", notes[i].c_str());
}

}  // namespace

void add_info_command(CLI::App& app, CommandAction& action) {
  auto options = std::make_shared<InfoOptions>();
  CLI::App* cmd = app.add_subcommand("info", "Load a model, repair it and describe it");
  add_mesh_options(*cmd, options->mesh, true);
  cmd->add_flag("--json", options->json, "Print JSON instead of text");
  cmd->callback([options, &action] {
    action = [options] {
      resolve_auto_up(options->mesh, nullptr, options->json);
      const core::PlacedModel m = core::load_placed(options->mesh);
      const std::string name = std::filesystem::path(options->mesh.model).filename().string();
      if (options->json) {
        nlohmann::json j = to_json(m);
        j["file"] = name;
        std::printf("%s\n", j.dump(2).c_str());
      } else {
        print_text(name, m);
      }
      return 0;
    };
  });
}

}  // namespace salient::cli
