// salientd: the salient daemon (Step 6 builds the HTTP/WebSocket service).
#include <cstdio>
#include <cstring>
#include <string>

#include "server/build_info.hpp"

int main(int argc, char** argv) {
  for (int i = 1; i < argc; ++i) {
    if (std::strcmp(argv[i], "--version") == 0) {
      std::printf("salientd %s\n", std::string(salient::server::version()).c_str());
      return 0;
    }
  }
  std::fprintf(stderr, "salientd %s: not yet: the daemon arrives in step 6; use the `salient` CLI meanwhile\n",
               std::string(salient::server::version()).c_str());
  return 2;
}
