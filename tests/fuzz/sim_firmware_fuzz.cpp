// Fuzz target for the simulated printer's parsers: a fault spec, then arbitrary host bytes with
// time passing. It must not crash, and it must never execute more commands than lines it took in.
#include <cstdint>
#include <cstdlib>
#include <stdexcept>
#include <string>

#include "protocol/sim/sim_faults.hpp"
#include "protocol/sim/sim_firmware.hpp"

using namespace salient::protocol::sim;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view all(reinterpret_cast<const char*>(data), size);
  const std::size_t cut = all.find('\n');
  SimConfig config;
  if (cut != std::string_view::npos && cut < 120) {  // the first line may be a fault spec
    try {
      config.faults = parse_faults(all.substr(0, cut));
    } catch (const std::invalid_argument&) {
    }
  }
  config.faults.disconnect_after = 0;
  config.advanced_ok = size % 2 == 0;
  config.emergency_parser = size % 3 == 0;
  config.time_scale = (size % 5) * 0.001;
  config.baud = size % 7 == 0 ? 250000 : 0;
  SimFirmware fw(config);
  Micros now{0};
  fw.boot(now);
  for (std::size_t at = 0; at < size; at += 16) {
    fw.receive(all.substr(at, 16), now);
    now += Micros(data[at] * 97);
    fw.advance(now);
    fw.take_output(now);
    fw.take_executed();
    if (fw.stats().executed > fw.stats().lines_received + 1) std::abort();
  }
  return 0;
}
