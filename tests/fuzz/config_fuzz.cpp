// Fuzz target for salientd.toml: only core::InputError may come out, and what is accepted holds
// to the checks the daemon relies on (unique printer ids, limits in range).
#include <cstdint>
#include <cstdlib>
#include <set>
#include <stdexcept>
#include <string>
#include <string_view>

#include "core/common/input_error.hpp"
#include "server/config/daemon_config.hpp"
#include "server/printers/sim_process.hpp"

using namespace salient::server;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  DaemonConfig c;
  try {
    c = parse_daemon_config(text, "fuzz.toml");
  } catch (const salient::core::InputError&) {
    return 0;
  }
  if (c.max_json_depth < 1 || c.max_json_depth > 1000 || c.workers < 1 || c.queue_limit < 1) std::abort();
  if (c.max_bodies_in_flight_bytes < c.max_upload_bytes) std::abort();
  std::set<std::string> ids;
  for (const PrinterConfig& p : c.printers) {
    if (p.id.empty() || !ids.insert(p.id).second) std::abort();
    if (p.kind != PrinterKind::sim && p.port.empty()) std::abort();
    try {
      split_args(p.sim_args);  // what open_printer_connection does with it, at connect time
    } catch (const std::invalid_argument&) {
    }
  }
  return 0;
}
