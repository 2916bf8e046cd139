// Saliency benchmark: seconds per method and model (median of runs); run it under
// `/usr/bin/time -f %M` for peak memory. Usage: saliency_bench [--runs N] METHOD MODEL ...
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <string>
#include <vector>

#include "core/mesh/mesh_loader.hpp"
#include "core/saliency/saliency.hpp"

using namespace salient::core;

int main(int argc, char** argv) {
  int runs = 3;
  int i = 1;
  if (i + 1 < argc && std::strcmp(argv[i], "--runs") == 0) runs = std::max(1, std::atoi(argv[i + 1])), i += 2;
  if (i >= argc) return 2;
  const auto method = parse_saliency_method(argv[i++]);
  if (!method) return 2;
  for (; i < argc; ++i) {
    const Mesh m = load_mesh(std::filesystem::path(argv[i])).mesh;
    std::vector<double> t;
    for (int r = 0; r < runs; ++r) {
      const auto t0 = std::chrono::steady_clock::now();
      compute_saliency(m, *method, argv[i]);
      t.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
    }
    std::sort(t.begin(), t.end());
    std::printf("%-10s %-22s %8zu vertices %8zu faces %8.2f s\n",
                std::string(saliency_method_name(*method)).c_str(),
                std::filesystem::path(argv[i]).filename().c_str(), m.vertex_count(), m.triangle_count(),
                t[t.size() / 2]);
  }
  return 0;
}
