// Fuzz target for what clients send the daemon: multipart bodies, job settings JSON, request
// targets, JSON bodies and console commands, WebSocket subscription messages, and the printers'
// sim_args. Nothing may crash; a parse either succeeds or says why.
#include <cstdint>
#include <cstdlib>
#include <map>
#include <stdexcept>
#include <string>

#include "server/api/api_json.hpp"
#include "server/events/event_hub.hpp"
#include "server/http/http_message.hpp"
#include "server/http/multipart.hpp"
#include "server/http/router.hpp"
#include "server/jobs/job_settings.hpp"
#include "server/printers/sim_process.hpp"

using namespace salient::server;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string input(reinterpret_cast<const char*>(data), size);
  try {
    for (const FormPart& p : parse_multipart(input, "XyZ")) {
      if (p.body.size() > size) std::abort();
    }
  } catch (const std::invalid_argument&) {
  }
  if (auto b = multipart_boundary(input.substr(0, 200))) {
    if (b->empty()) std::abort();
  }
  try {
    parse_job_settings(input, 8);
  } catch (const ApiError& e) {
    if (e.status() != 400) std::abort();
  }
  std::string path;
  std::map<std::string, std::string> query;
  split_target(input, path, query);
  HttpRequest request;
  request.body = input;
  try {
    const nlohmann::json body = parse_json_body(request, 1 << 16, 8);
    if (!body.is_object()) std::abort();
    for (const std::string& c : parse_commands(body))
      if (c.empty() || c.size() > 96 || c.find('\n') != std::string::npos) std::abort();
  } catch (const ApiError& e) {
    if (e.status() != 400 && e.status() != 413) std::abort();
  }
  EventHub hub;
  auto s = hub.subscribe();
  s->receive(input);
  int replies = 0;
  while (auto m = s->next()) {
    if (nlohmann::json::parse(*m, nullptr, false).is_discarded()) std::abort();  // always valid JSON
    ++replies;
  }
  if (replies < 1) std::abort();  // every message is answered ("subscribed" or "error")
  try {
    split_args(input);
  } catch (const std::invalid_argument&) {
  }
  return 0;
}
