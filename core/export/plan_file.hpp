// PlanFile: the layer tops of a plan made anywhere — our plan JSON, a G-code file (PrusaSlicer's,
// ours: `;Z:` comments; Cura's: `;LAYER:n` and the Z it extrudes at), or a 3MF with PrusaSlicer's
// layer-height profile — so `salient compare --plan` can score it in our metric.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

namespace salient::core {

struct PlanFile {
  std::string format;                // what it was read as, for the user: "G-code (;Z:)", …
  std::vector<double> tops;          // layer tops, mm, strictly increasing, bottom first
  std::vector<std::uint64_t> lines;  // the line of the file each top was read from (0: none)
};

// The format is told by content, not by name: "PK\3\4" a 3MF, '{' our plan JSON, text with
// `;Z:` or `;LAYER:` lines G-code. Throws InputError naming `name` (and the line where there is
// one) for an empty or unknown file, a top not above the one before, a file with no layers.
PlanFile parse_plan_file(std::string_view bytes, const std::string& name);
PlanFile read_plan_file(const std::filesystem::path& path);  // names the file by its file name

// The tops of PrusaSlicer's layer-height profile text ("object_id=1|z;h;z;h;…", the first
// object's line), walked from z = 0 up to the profile's last z, each layer as thick as the
// profile at its bottom (PrusaSlicer reads it a little higher, at mid-layer: the same on the
// step profiles we write, within a grid cell on its own smooth ones).
std::vector<double> prusa_profile_tops(std::string_view profile, const std::string& name);

}  // namespace salient::core
