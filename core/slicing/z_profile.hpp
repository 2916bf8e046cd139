// ZProfile: the model reduced to what slicing needs, on a grid of δ along Z (ALGORITHMS.md §2).
#pragma once

#include <span>
#include <vector>

#include "core/common/progress.hpp"
#include "core/mesh/mesh.hpp"
#include "core/slicing/range_max.hpp"
#include "core/slicing/slicing_params.hpp"

namespace salient::core {

// Per cell k (the slab [kδ, (k+1)δ)), for one saliency field:
//   S[k]  largest saliency of any surface point in the cell,
//   A[k]  Σ over faces of saliency × |n_z| × (area of the face inside the cell)  (mm²),
// and, shared by both fields, C[k] the largest |n_z| of any face touching the cell (cos θ).
struct ProfileChannel {
  std::vector<float> S;
  std::vector<double> A_prefix;  // A_prefix[k] = Σ A[0..k-1], size cells + 1
  RangeMax S_max;
};

class ZProfile {
 public:
  // `mesh` must be placed (lowest point at z = 0); `saliency` has one value per vertex.
  // Throws InputError when the model is lower than α or cannot be cut into layers of α..ᾱ.
  // `height` > 0 sets the profile's height instead of the mesh's top (a part of a segmented
  // model is profiled on the whole model's grid, so the parts' layers can meet).
  static ZProfile build(const Mesh& mesh, std::span<const float> saliency, const SlicingParams& params,
                        const RunContext& run = {}, double height = 0);

  // The cells [first, last) as a profile of their own, from z = 0 (a horizontal slab of a
  // segmented model). Throws InputError if the slab cannot be cut into layers of α..ᾱ.
  ZProfile window(int first, int last) const;

  int cells() const { return cells_; }          // M
  double height() const { return height_; }     // H, mm
  double grid() const { return params_.grid; }  // δ
  const SlicingParams& params() const { return params_; }
  int min_cells() const { return min_cells_; }  // α / δ
  int max_cells() const { return max_cells_; }  // ᾱ / δ
  double z(int k) const { return k >= cells_ ? height_ : k * params_.grid; }
  std::size_t dropped_faces() const { return dropped_faces_; }

  // `geometric` selects the field with saliency ≡ 1 (what a geometry-only method sees).
  const ProfileChannel& channel(bool geometric) const { return geometric ? geometric_ : salient_; }
  const std::vector<float>& cos_theta() const { return C_; }
  float max_cos(int i, int j) const { return C_max_(i, j); }

  // Layer counts any valid plan can have: [fewest, most].
  int fewest_layers() const { return (cells_ + max_cells_ - 1) / max_cells_; }
  int most_layers() const { return cells_ / min_cells_; }

 private:
  SlicingParams params_;
  int cells_ = 0, min_cells_ = 1, max_cells_ = 1;
  double height_ = 0;
  std::size_t dropped_faces_ = 0;
  ProfileChannel salient_, geometric_;
  std::vector<float> C_;
  RangeMax C_max_;
};

}  // namespace salient::core
