// Automatic orientation (paper §6, ALGORITHMS.md §5): three orthogonal candidate up directions
// from the model's face normals, each scored by printing time (with support), volumetric error
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

// Area of the faces that lie on the bed (within `tolerance` mm of the lowest z and facing down
// within 10°) once the mesh is turned so that `up` is +Z: the contact area A_T of StaS.
double bed_contact_area(const Mesh& mesh, const Vec3& up, double tolerance = 0.05);

// `d` or `-d`: the one that puts more area on the bed (d on a tie).
Vec3 pick_up_sign(const Mesh& mesh, const Vec3& d);

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
