// Saliency inputs that need no computation: uniform and painted.
#include "core/saliency/saliency.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <sstream>

#include "core/common/input_error.hpp"
#include "core/mesh/text_cursor.hpp"
#include "core/saliency/lee05_saliency.hpp"
#include "core/saliency/spectral_saliency.hpp"

namespace salient::core {
namespace {

std::vector<float> normalised(std::vector<float> v) {
  if (v.empty()) return v;
  const auto [lo, hi] = std::minmax_element(v.begin(), v.end());
  const float a = *lo, b = *hi;
  for (float& x : v) x = b > a ? (x - a) / (b - a) : 1.0f;  // a constant paint means "all equal"
  return v;
}

}  // namespace

const std::vector<std::string_view>& saliency_method_names() {
  static const std::vector<std::string_view> names = {"spectral", "lee05", "painted", "uniform"};
  return names;
}

std::optional<SaliencyMethod> parse_saliency_method(std::string_view name) {
  const auto& names = saliency_method_names();
  for (std::size_t i = 0; i < names.size(); ++i)
    if (names[i] == name) return static_cast<SaliencyMethod>(i);
  return std::nullopt;
}

std::string_view saliency_method_name(SaliencyMethod method) {
  return saliency_method_names().at(static_cast<std::size_t>(method));
}

std::vector<float> compute_saliency(const Mesh& mesh, SaliencyMethod method, const std::string& source,
                                    const RunContext& run) {
  run.check();
  switch (method) {
    case SaliencyMethod::spectral:
      return spectral_saliency(mesh, {}, run);
    case SaliencyMethod::lee05:
      return lee05_saliency(mesh, run);
    case SaliencyMethod::uniform:
      return std::vector<float>(mesh.vertex_count(), 1.0f);
    case SaliencyMethod::painted:
      if (mesh.has_quality()) return normalised(mesh.quality);
      if (mesh.has_colors()) {
        std::vector<float> red(mesh.vertex_count());
        for (std::size_t i = 0; i < red.size(); ++i) red[i] = mesh.colors[i].r;
        return normalised(std::move(red));
      }
      throw InputError(
          source, {}, "{saliency} painted needs vertex quality or vertex colours, and the model has neither");
  }
  return {};
}

std::vector<float> read_vertex_values(const std::filesystem::path& path, std::size_t vertex_count) {
  const std::string name = path.filename().string();
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(name, {}, "cannot open for reading");
  std::ostringstream buffer;
  buffer << in.rdbuf();
  const std::string text = buffer.str();
  TextCursor cur(text, name);
  std::vector<float> values;
  values.reserve(std::min<std::size_t>(vertex_count, text.size() / 2 + 1));
  std::string_view line;
  while (cur.next_line(line)) {
    LineTokens tokens(line);
    std::string_view tok;
    if (!tokens.next(tok) || tok.front() == '#') continue;
    const double v = cur.parse_double(tok, "a vertex value");
    if (!std::isfinite(v)) cur.fail("value is not a finite number");
    if (values.size() == vertex_count)
      cur.fail("more values than the model's " + std::to_string(vertex_count) + " vertices");
    values.push_back(static_cast<float>(v));
  }
  if (values.size() != vertex_count)
    throw InputError(name, {},
                     "has " + std::to_string(values.size()) + " values, the model has " +
                         std::to_string(vertex_count) + " vertices");
  return values;
}

}  // namespace salient::core
