#include "server/api/octoprint_files.hpp"

#include <limits>
#include <set>

#include "server/http/router.hpp"
#include "server/jobs/job_service.hpp"

namespace salient::server {

using nlohmann::json;

namespace {

[[noreturn]] void bad_path(std::string_view field, std::string_view raw, const std::string& why) {
  const std::string shown(raw.substr(0, 120));
  throw ApiError(400, "bad_path", "'" + std::string(field) + "' (\"" + shown + "\"): " + why);
}

// Digits only; saturates instead of overflowing (a huge number is still past any end).
bool parse_count(std::string_view s, std::size_t& out) {
  if (s.empty()) return false;
  out = 0;
  for (char c : s) {
    if (c < '0' || c > '9') return false;
    const auto digit = static_cast<std::size_t>(c - '0');
    out = out > (std::numeric_limits<std::size_t>::max() - digit) / 10
              ? std::numeric_limits<std::size_t>::max()
              : out * 10 + digit;
  }
  return true;
}

std::string_view trim(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t')) s.remove_suffix(1);
  return s;
}

}  // namespace

std::string checked_path(std::string_view raw, std::string_view field, bool root_ok) {
  std::string_view p = raw;
  if (p == "/") p = "";
  if (p.empty()) {
    if (!root_ok) bad_path(field, raw, "a path is needed here");
    return "";
  }
  if (p.size() > kMaxPathBytes)
    bad_path(field, raw, "longer than " + std::to_string(kMaxPathBytes) + " bytes");
  if (p.front() == '/') bad_path(field, raw, "an absolute path: paths are relative to the file area");
  if (p.back() == '/') p.remove_suffix(1);
  std::string out;
  std::size_t depth = 0;
  while (true) {
    const std::size_t slash = p.find('/');
    const std::string_view segment = p.substr(0, slash);
    if (segment.empty()) bad_path(field, raw, "an empty segment (\"//\")");
    if (segment == "." || segment == "..") bad_path(field, raw, "\".\" and \"..\" are not allowed in paths");
    if (segment.size() > kMaxSegmentBytes)
      bad_path(field, raw, "a name longer than " + std::to_string(kMaxSegmentBytes) + " bytes");
    for (char c : segment) {
      const auto u = static_cast<unsigned char>(c);
      if (c == '\\') bad_path(field, raw, "a backslash: separate folders with '/'");
      if (u < 0x20 || u == 0x7f) bad_path(field, raw, "a control character");
    }
    if (++depth > kMaxPathDepth)
      bad_path(field, raw, "deeper than " + std::to_string(kMaxPathDepth) + " folders");
    if (!out.empty()) out += '/';
    out += sanitize_filename(std::string(segment));
    if (slash == std::string_view::npos) break;
    p.remove_prefix(slash + 1);
  }
  return out;
}

std::string join_path(const std::string& folder, const std::string& name) {
  return folder.empty() ? name : folder + "/" + name;
}

std::string parent_path(const std::string& path) {
  const std::size_t slash = path.find_last_of('/');
  return slash == std::string::npos ? std::string() : path.substr(0, slash);
}

std::string leaf_name(const std::string& path) {
  const std::size_t slash = path.find_last_of('/');
  return slash == std::string::npos ? path : path.substr(slash + 1);
}

bool in_folder(const std::string& folder, const std::string& path) {
  if (folder.empty() || path == folder) return true;
  return path.size() > folder.size() && path.compare(0, folder.size(), folder) == 0 &&
         path[folder.size()] == '/';
}

RangeAnswer parse_range(std::string_view header, std::size_t size) {
  RangeAnswer whole;
  header = trim(header);
  constexpr std::string_view unit = "bytes=";
  if (header.size() < unit.size()) return whole;
  for (std::size_t i = 0; i < unit.size(); ++i)
    if (std::tolower(static_cast<unsigned char>(header[i])) != unit[i]) return whole;
  const std::string_view spec = trim(header.substr(unit.size()));
  if (spec.find(',') != std::string_view::npos) return whole;  // several ranges: not honoured
  const std::size_t dash = spec.find('-');
  if (dash == std::string_view::npos) return whole;
  const std::string_view a = trim(spec.substr(0, dash)), b = trim(spec.substr(dash + 1));
  std::size_t first = 0, last = 0;
  RangeAnswer out{RangeAnswer::Kind::partial, 0, 0};
  if (a.empty()) {  // a suffix: the last `b` bytes
    if (!parse_count(b, last)) return whole;
    if (last == 0 || size == 0) return {RangeAnswer::Kind::unsatisfiable, 0, 0};
    out.first = last >= size ? 0 : size - last;
    out.last = size - 1;
    return out;
  }
  if (!parse_count(a, first)) return whole;
  if (b.empty()) {
    last = std::numeric_limits<std::size_t>::max();
  } else if (!parse_count(b, last) || last < first) {
    return whole;  // not a valid range-spec: the header is ignored
  }
  if (first >= size) return {RangeAnswer::Kind::unsatisfiable, 0, 0};
  out.first = first;
  out.last = last >= size ? size - 1 : last;
  return out;
}

json folder_entries(const std::vector<StoredFile>& files, const std::vector<std::string>& folders,
                    const std::string& folder, bool recursive,
                    const std::function<json(const StoredFile&)>& file_json,
                    const std::function<json(const std::string& path)>& folder_json) {
  std::set<std::string> all;
  const auto add_with_ancestors = [&all](std::string path) {
    while (!path.empty() && all.insert(path).second) path = parent_path(path);
  };
  for (const std::string& f : folders) add_with_ancestors(f);
  for (const StoredFile& f : files) add_with_ancestors(parent_path(f.name));
  json out = json::array();
  for (const std::string& sub : all) {
    if (parent_path(sub) != folder || sub == folder) continue;
    json entry = folder_json(sub);
    long long size = 0;
    for (const StoredFile& f : files)
      if (in_folder(sub, f.name)) size += f.size;
    entry["size"] = size;
    if (recursive) entry["children"] = folder_entries(files, folders, sub, true, file_json, folder_json);
    out.push_back(std::move(entry));
  }
  for (const StoredFile& f : files)
    if (parent_path(f.name) == folder) out.push_back(file_json(f));
  return out;
}

}  // namespace salient::server
