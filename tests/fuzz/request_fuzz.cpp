// Fuzz target for what clients send the daemon: multipart bodies, job settings JSON and request
// targets. Nothing may crash; a parse either succeeds or says why.
#include <cstdint>
#include <cstdlib>
#include <map>
#include <stdexcept>
#include <string>

#include "server/http/http_message.hpp"
#include "server/http/multipart.hpp"
#include "server/http/router.hpp"
#include "server/jobs/job_settings.hpp"

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
  return 0;
}
