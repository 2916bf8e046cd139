// Mesh checks and repairs: weld, drop degenerate and duplicate faces, report boundary and
// non-manifold edges, make orientation consistent (outward for closed parts), close holes.
#pragma once

#include <string>
#include <vector>

#include "core/mesh/mesh.hpp"

namespace salient::core {

struct RepairOptions {
  // Vertices closer than this fraction of the bounding-box diagonal are welded into one.
  double weld_tolerance = 1e-6;
  bool fix_orientation = true;
  // Caps holes (hole_filler.hpp) once the orientation is consistent; needs fix_orientation.
  bool fill_holes = true;
};

struct RepairReport {
  std::size_t vertices_welded = 0;           // merged into another vertex
  std::size_t unused_vertices_removed = 0;   // referenced by no face
  std::size_t degenerate_faces_removed = 0;  // repeated vertex or zero area
  std::size_t duplicate_faces_removed = 0;   // same three vertices as an earlier face
  std::size_t faces_flipped = 0;             // to agree with their neighbours / face outward
  std::size_t holes_filled = 0;              // hole loops capped (open bottoms, sockets)
  std::size_t cap_faces = 0;                 // the faces capping them: the mesh's last ones
  std::size_t components = 0;                // edge-connected parts
  std::size_t boundary_edges = 0;            // used by one face, after filling: the mesh is open there
  std::size_t non_manifold_edges = 0;        // used by three or more faces
  bool orientable = true;                    // false if no consistent orientation exists
  bool watertight = false;                   // closed and manifold

  // One human-readable line per repair made or problem left, e.g. "welded 12 vertices".
  std::vector<std::string> lines() const;
};

// Repairs `mesh` in place and reports what it did and what remains. Never throws on geometry;
// a mesh can end with no triangles (the caller decides whether that is an error).
RepairReport repair_mesh(Mesh& mesh, const RepairOptions& options = {});

}  // namespace salient::core
