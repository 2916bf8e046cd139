// Replay driver for fuzz targets when libFuzzer is not linked: runs the target over every file
// of the given files and folders, then over deterministic mutations of each (truncations and
// byte flips), so `ctest` exercises the same code paths as the fuzzer on every build. Each input
// goes in behind a selector byte (the targets that pick a parser by their first byte), unless
// `--raw` comes first: then as it is (the targets whose seeds are exactly what a client sends).
#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <random>
#include <string>
#include <vector>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size);

namespace {

bool raw = false;  // --raw: no selector byte

void run(const std::string& bytes, std::uint8_t selector) {
  std::vector<std::uint8_t> input;
  input.reserve(bytes.size() + 1);
  if (!raw) input.push_back(selector);
  input.insert(input.end(), bytes.begin(), bytes.end());
  LLVMFuzzerTestOneInput(input.data(), input.size());
}

std::size_t replay(const std::filesystem::path& file, std::mt19937& rng) {
  std::ifstream in(file, std::ios::binary);
  const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  std::size_t runs = 0;
  for (std::uint8_t sel = 0; sel < (raw ? 1 : 6); ++sel, ++runs) run(bytes, sel);
  if (bytes.size() > (1u << 19)) return runs;  // big files: whole only, to keep the test quick
  for (int i = 1; i <= 8; ++i, ++runs)
    run(bytes.substr(0, bytes.size() * i / 9), static_cast<std::uint8_t>(rng()));
  for (int i = 0; i < 24 && !bytes.empty(); ++i, ++runs) {
    std::string mutated = bytes;
    for (int k = 0; k < 4; ++k) mutated[rng() % mutated.size()] = static_cast<char>(rng());
    run(mutated, static_cast<std::uint8_t>(rng()));
  }
  return runs;
}

}  // namespace

int main(int argc, char** argv) {
  std::mt19937 rng(12345);
  std::size_t runs = 0, files = 0;
  int first = 1;
  if (argc > 1 && std::string(argv[1]) == "--raw") raw = true, first = 2;
  for (int i = first; i < argc; ++i) {
    const std::filesystem::path arg(argv[i]);
    std::vector<std::filesystem::path> paths;
    if (std::filesystem::is_directory(arg)) {
      for (const auto& entry : std::filesystem::directory_iterator(arg))
        if (entry.is_regular_file()) paths.push_back(entry.path());
    } else {
      paths.push_back(arg);
    }
    std::sort(paths.begin(), paths.end());
    for (const auto& p : paths) {
      runs += replay(p, rng);
      ++files;
    }
  }
  std::printf("replayed %zu inputs from %zu files\n", runs, files);
  return files > 0 ? 0 : 1;
}
