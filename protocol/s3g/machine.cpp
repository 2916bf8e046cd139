#include "protocol/s3g/machine.hpp"

#include <array>

namespace salient::protocol::s3g {
namespace {

// GPX's A/B steps per mm for the MakerBot extruders, to its last digit.
constexpr double kExtruderSteps = 96.275201870333662468889989185642;

// r2 and r2h differ from r2x in X travel, the bed heater (r2 has none) and the second extruder.
const std::array<Machine, 3> kMachines = {{
    {"r2",
     "Replicator 2",
     {18000, 2500, 285, 88.888889, true},
     {18000, 2500, 152, 88.888889, true},
     {1170, 1100, 155, 400, false},
     {1600, kExtruderSteps, false},
     {1600, kExtruderSteps, false},
     0.4,
     1,
     20},
    {"r2h",
     "Replicator 2 with HBP",
     {18000, 2500, 285, 88.888889, true},
     {18000, 2500, 152, 88.888889, true},
     {1170, 1100, 155, 400, false},
     {1600, kExtruderSteps, true},
     {1600, kExtruderSteps, true},
     0.4,
     1,
     20},
    {"r2x",
     "Replicator 2X",
     {18000, 2500, 246, 88.888889, true},
     {18000, 2500, 152, 88.888889, true},
     {1170, 1100, 155, 400, false},
     {1600, kExtruderSteps, true},
     {1600, kExtruderSteps, true},
     0.4,
     2,
     20},
}};

}  // namespace

const Machine* find_machine(std::string_view id) {
  for (const Machine& m : kMachines)
    if (m.id == id) return &m;
  return nullptr;
}

std::vector<std::string> machine_ids() {
  std::vector<std::string> ids;
  for (const Machine& m : kMachines) ids.push_back(m.id);
  return ids;
}

}  // namespace salient::protocol::s3g
