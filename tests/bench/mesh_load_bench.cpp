// Mesh loading benchmark: read (parse) and load (parse + repair) time per model, median of
// repeated runs. Usage: mesh_load_bench [--runs N] MODEL...
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <string>
#include <vector>

#include "core/mesh/mesh_loader.hpp"

namespace {

double median_ms(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

template <typename F>
double time_ms(F&& f) {
  const auto t0 = std::chrono::steady_clock::now();
  f();
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

}  // namespace

int main(int argc, char** argv) {
  int runs = 7;
  std::vector<std::string> models;
  for (int i = 1; i < argc; ++i) {
    if (std::strcmp(argv[i], "--runs") == 0 && i + 1 < argc)
      runs = std::max(1, std::atoi(argv[++i]));
    else
      models.emplace_back(argv[i]);
  }
  if (models.empty()) {
    std::fprintf(stderr, "usage: mesh_load_bench [--runs N] MODEL...\n");
    return 2;
  }
  std::printf("%-28s %10s %10s %12s %12s\n", "model", "bytes", "triangles", "read ms", "load ms");
  for (const std::string& path : models) {
    std::vector<double> read, load;
    std::size_t triangles = 0;
    for (int r = 0; r < runs; ++r) {
      read.push_back(time_ms([&] { triangles = salient::core::read_mesh_file(path).mesh.triangle_count(); }));
      load.push_back(time_ms([&] { salient::core::load_mesh(std::filesystem::path(path)); }));
    }
    std::printf("%-28s %10ju %10zu %12.2f %12.2f\n", std::filesystem::path(path).filename().c_str(),
                static_cast<std::uintmax_t>(std::filesystem::file_size(path)), triangles, median_ms(read),
                median_ms(load));
  }
  return 0;
}
