// Fuzz target for job settings JSON (the "settings" part of a submission): only BadRequest ("bad_settings")
// may come out, at the daemon's depth limit, and accepted settings give canonical JSON that parses
// back to itself (the worker parses it again when the job runs).
#include <cstdint>
#include <cstdlib>
#include <nlohmann/json.hpp>
#include <string>

#include "server/common/domain_error.hpp"
#include "server/config/daemon_config.hpp"
#include "server/jobs/job_settings.hpp"

using namespace salient::server;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const auto depth = static_cast<std::size_t>(DaemonConfig{}.max_json_depth);
  const std::string text(reinterpret_cast<const char*>(data), size);
  JobSettings s;
  try {
    s = parse_job_settings(text, depth);
  } catch (const DomainError& e) {
    if (e.kind() != ErrorKind::bad_request || e.code() != "bad_settings") std::abort();
    return 0;
  }
  if (!nlohmann::json::parse(s.canonical, nullptr, false).is_object()) std::abort();
  try {
    const JobSettings again = parse_job_settings(s.canonical, depth);
    if (again.canonical != s.canonical || again.printer != s.printer) std::abort();
  } catch (const DomainError&) {
    std::abort();  // accepted at submission, refused when the job runs
  }
  return 0;
}
