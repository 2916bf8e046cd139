// cura_adaptive_plan: a binary STL of the placed mesh (lowest point at z = 0: CuraEngine keeps
// the mesh where it is), CuraEngine run without a shell, its G-code read as any other plan file.
// Walls, infill and skins are cut to the least (one wall, no infill, no skins): Cura's adaptive
// heights depend on the mesh alone, and the run is then a few seconds.
#include "clients/cli/cura_peer.hpp"

#include <fcntl.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <sstream>
#include <vector>

#include "core/common/input_error.hpp"

extern char** environ;

namespace salient::cli {
namespace {

std::optional<std::filesystem::path> on_path(const std::string& program) {
  const char* path = std::getenv("PATH");
  std::stringstream dirs(path ? path : "/usr/bin:/bin");
  for (std::string dir; std::getline(dirs, dir, ':');) {
    const std::filesystem::path p = std::filesystem::path(dir.empty() ? "." : dir) / program;
    if (::access(p.c_str(), X_OK) == 0) return p;
  }
  return std::nullopt;
}

std::optional<std::filesystem::path> cura_definitions() {
  for (const char* dir :
       {"/usr/share/cura/resources/definitions", "/usr/local/share/cura/resources/definitions"}) {
    const std::filesystem::path p = std::filesystem::path(dir) / "fdmprinter.def.json";
    if (std::filesystem::exists(p)) return p;
  }
  return std::nullopt;
}

void write_binary_stl(const std::filesystem::path& path, const core::Mesh& mesh) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  char header[80] = "salient: placed mesh for CuraEngine";
  out.write(header, sizeof header);
  const auto count = static_cast<std::uint32_t>(mesh.triangles.size());
  out.write(reinterpret_cast<const char*>(&count), 4);  // little-endian hosts only, as STL is
  for (const core::Triangle& t : mesh.triangles) {
    float v[12] = {0, 0, 0};
    for (int k = 0; k < 3; ++k) {
      const core::Vec3& p = mesh.positions[t[k]];
      v[3 + 3 * k] = static_cast<float>(p.x);
      v[4 + 3 * k] = static_cast<float>(p.y);
      v[5 + 3 * k] = static_cast<float>(p.z);
    }
    out.write(reinterpret_cast<const char*>(v), sizeof v);
    out.write("\0\0", 2);
  }
  if (!out) throw core::InputError(path.string(), {}, "cannot write");
}

std::string num(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.4g", v);
  return buf;
}

// Runs argv with stdout and stderr to `log`; its exit status (-1: it could not be started).
int run(const std::vector<std::string>& args, const std::filesystem::path& log) {
  std::vector<char*> argv;
  for (const std::string& a : args) argv.push_back(const_cast<char*>(a.c_str()));
  argv.push_back(nullptr);
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, 1, log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  posix_spawn_file_actions_adddup2(&actions, 1, 2);
  pid_t pid = 0;
  const int rc = posix_spawn(&pid, argv[0], &actions, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  if (rc != 0) return -1;
  int status = 0;
  while (::waitpid(pid, &status, 0) < 0 && errno == EINTR) {
  }
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

}  // namespace

std::optional<CuraPlan> cura_adaptive_plan(const core::Mesh& placed, const CuraSettings& s,
                                           const std::filesystem::path& work_dir, std::string& why) {
  const auto engine = on_path("CuraEngine");
  const auto definitions = cura_definitions();
  if (!engine || !definitions) {
    why = !engine ? "CuraEngine not installed (deploy/install-deps.sh --peers: cura-engine)"
                  : "Cura's fdmprinter.def.json not found (deploy/install-deps.sh --peers: cura)";
    return std::nullopt;
  }
  std::filesystem::create_directories(work_dir);
  const std::filesystem::path stl = work_dir / "cura-model.stl", gcode = work_dir / "cura.gcode",
                              log = work_dir / "cura.log";
  write_binary_stl(stl, placed);
  // Cura varies its layers by ± variation around layer_height: centre and half-width of α..ᾱ.
  const double centre = 0.5 * (s.min_layer + s.max_layer), variation = 0.5 * (s.max_layer - s.min_layer);
  std::vector<std::string> args = {engine->string(), "slice", "-j", definitions->string()};
  for (const auto& [key, value] :
       std::vector<std::pair<std::string, std::string>>{{"adaptive_layer_height_enabled", "true"},
                                                        {"layer_height", num(centre)},
                                                        {"adaptive_layer_height_variation", num(variation)},
                                                        {"adaptive_layer_height_variation_step", num(s.step)},
                                                        {"layer_height_0", num(s.first_layer)},
                                                        {"machine_width", "2000"},
                                                        {"machine_depth", "2000"},
                                                        {"machine_height", "2000"},
                                                        {"adhesion_type", "none"},
                                                        {"wall_line_count", "1"},
                                                        {"infill_sparse_density", "0"},
                                                        {"top_layers", "0"},
                                                        {"bottom_layers", "0"}}) {
    args.push_back("-s");
    args.push_back(key + "=" + value);
  }
  for (const std::string& a : {std::string("-l"), stl.string(), std::string("-o"), gcode.string()})
    args.push_back(a);
  CuraPlan out;
  for (const std::string& a : args) out.command += (out.command.empty() ? "" : " ") + a;
  const auto t0 = std::chrono::steady_clock::now();
  const int status = run(args, log);
  out.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  if (status != 0)
    throw core::InputError("CuraEngine", {},
                           "exited with status " + std::to_string(status) + " (see " + log.string() + ")");
  out.layers = core::read_plan_file(gcode);
  return out;
}

}  // namespace salient::cli
