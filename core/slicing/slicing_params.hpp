// SlicingParams: the printer's layer limits and the planning grid, checked once.
#pragma once

namespace salient::core {

struct SlicingParams {
  double min_layer = 0.1;  // α, mm: the thinnest layer the printer prints
  double max_layer = 0.4;  // ᾱ, mm: the thickest
  double grid = 0.01;      // δ, mm: every boundary lies on a multiple of it; must divide α and ᾱ

  int min_cells() const;  // α / δ
  int max_cells() const;  // ᾱ / δ
};

// Throws InputError naming the setting (min_layer, max_layer, grid) when the
// parameters are impossible: non-positive, α > ᾱ, or a grid that does not divide α and ᾱ.
void validate(const SlicingParams& params);

// Throws InputError naming rho unless 0 <= rho <= 1.
void validate_rho(double rho);

}  // namespace salient::core
