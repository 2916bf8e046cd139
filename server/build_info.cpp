// Build information, stamped by CMake.
#include "server/build_info.hpp"

namespace salient::server {

std::string_view version() {
  return SALIENT_VERSION;
}

}  // namespace salient::server
