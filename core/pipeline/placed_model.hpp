// Loading, repairing and placing a model in one call, with the options every front end shares
// (the CLI's MODEL --up --height --scale, the daemon's job settings).
#pragma once

#include <optional>
#include <string>

#include "core/mesh/mesh_loader.hpp"
#include "core/mesh/placement.hpp"

namespace salient::core {

struct MeshOptions {
  std::string model;
  std::string up = "z";  // x, y, z, or a direction "DX,DY,DZ" ("auto" is chosen by slice_model)
  std::optional<double> height;
  double scale = 1.0;
  double bed_center_x = 0, bed_center_y = 0;  // set from the printer profile where there is one
};

struct PlacedModel {
  core::LoadedMesh loaded;
  core::Placement placement;
  core::UpAxis up = core::UpAxis::z;
  std::optional<Vec3> up_direction;  // when placed by a direction rather than an axis
};

// Loads, repairs and places the model; throws core::InputError on bad input or options.
// A `values_file` (one value per vertex of the file, as read) becomes the vertex quality before
// repair, so it follows welding and compaction.
PlacedModel load_placed(const MeshOptions& options, const std::string& values_file = {});

// Places a loaded `mesh` in place as load_placed does (`options.model` unused): for a front end
// that has the mesh already and checks its placed size. Throws InputError as load_placed.
Placement place_by_options(Mesh& mesh, const MeshOptions& options);

}  // namespace salient::core
