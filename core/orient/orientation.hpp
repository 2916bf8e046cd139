// Automatic orientation (paper §6, ALGORITHMS.md §5): candidate up directions — the model's flat
// bases and its convex hull's large facets, and three orthogonal directions from its face
// normals — each scored by printing time (with support), volumetric error
// and stability; the best score wins. The parts here are pure geometry; slicing each candidate
// for its time is core/pipeline/auto_orient.
#pragma once

#include <array>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "core/mesh/mesh.hpp"

namespace salient::core {

// Three orthonormal directions: k-means (k = 3) on the area-weighted unit face normals with the
// antipodal distance 1 − (n·c)², each centre the principal direction (of Σ a·n·nᵀ) of its
// cluster, seeded farthest-first; then made orthonormal, heaviest cluster first (HBA13's normal
// clustering, as the paper uses it). Signs are arbitrary here: see pick_up_sign.
std::array<Vec3, 3> candidate_directions(const Mesh& mesh);

// Tolerances at print scale, for a mesh in its file's units.
struct CandidateOptions {
  double scale = 1;                // print mm per unit of the mesh
  double contact_tolerance = 0.1;  // mm: what lies this close to the bed is printed in the first layer
  double min_share = 0.025;        // a base's area, at least this share of the (hull's) surface
  int max_bases = 3;               // the largest bases offered, at most
};

// Bed contact A_T of StaS once the mesh is turned so that `up` is +Z: the area, seen from below,
// of the downward-facing surface within `tolerance` (the mesh's units) of its lowest point. For a
// closed mesh that is the section at that height — what the first layer prints when `tolerance`
// is half of it, as layers are cut at mid-height — and a flat base counts in full.
double bed_contact_area(const Mesh& mesh, const Vec3& up, double tolerance);

// `d` or `-d`. The one that puts more area on the bed when the two differ by a meaningful share
// (1 %) of the surface; else the one whose lowest 2 % spans the larger footprint on the bed (a
// scanned animal touches the bed at specks either way, but its hooves span its body, its back a
// speck); else `d`.
Vec3 pick_up_sign(const Mesh& mesh, const Vec3& d, const CandidateOptions& options = {});

// The directions a model can rest on, as up directions: −n of each large flat region of the
// mesh that lies at the bottom when turned down, and of each large facet of its convex hull over
// which its centre of mass stands (it would topple off the others). Largest first, at most
// `max_bases`, none within 10° of one before it.
std::vector<Vec3> base_directions(const Mesh& mesh, const CandidateOptions& options = {});

// What --up auto compares: the bases, then the three candidate_directions with pick_up_sign's
// sign (the paper's candidates, kept even near a base: the print can differ, an axis a few
// degrees off a scanned animal's feet is quicker than the facet under them) unless within 1° of one.
std::vector<Vec3> candidate_ups(const Mesh& mesh, const CandidateOptions& options = {});

// Eq. 13, VolS = 1 − |Σ h_k·A_k − V| / V, for a placed mesh and its layer boundaries (bed first).
// A_k is the area of layer k's section at mid height — what the slicer prints — where the paper's
// text has the perimeter P_k (which would make h·P an area, not a volume).
double volumetric_score(const Mesh& placed, std::span<const double> boundaries);

struct OrientationScore {
  Vec3 up;             // the model's direction that goes to +Z
  double minutes = 0;  // estimated printing time, support included
  int layers = 0;
  double contact_area = 0;                                       // mm², on the bed
  double time_score = 0, volume_score = 0, stability_score = 0;  // TimeS, VolS, StaS
  double score = 0;                                              // OS, eq. 11
};

// Fills time_score (eq. 12: (MAX_T − T_i) / (MAX_T − MIN_T), 1 for all when the times are equal),
// stability_score (A_T / surface area) and score = 0.3·TimeS + 0.3·VolS + 0.3·StaS (eq. 11);
// returns the index of the best.
std::size_t score_orientations(std::vector<OrientationScore>& candidates, double surface_area);

// What --up auto chose, and why: every candidate with its scores.
struct OrientationReport {
  std::vector<OrientationScore> candidates;
  std::size_t best = 0;
  std::string up;  // the chosen direction as --up takes it
  // With a target height: the one scale all candidates were compared at, kept for the print (an
  // orientation does not change the object's size; the tallest candidate has the target height).
  std::optional<double> scale;
};

// "0.000000,-1.000000,0.000000": a direction as --up takes it.
std::string direction_text(const Vec3& d);

}  // namespace salient::core
