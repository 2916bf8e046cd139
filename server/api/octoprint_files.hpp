// The pure parts of OctoPrint's file area: checking a path a client sends (a URL, a form's `path`,
// a move's `destination`), the Range of a download, and the folder tree of a listing. No I/O:
// the routes (octoprint_file_routes.cpp) feed them what the store holds. Included from .cpp only.
#pragma once

#include <cstddef>
#include <functional>
#include <nlohmann/json.hpp>
#include <string>
#include <string_view>
#include <vector>

#include "server/store/print_store.hpp"

namespace salient::server {

// Bounds of a stored path: OctoPrint has none, but a path is a key in every listing and URL.
constexpr std::size_t kMaxPathBytes = 1024, kMaxSegmentBytes = 255, kMaxPathDepth = 16;

// A path inside the file area, "a/b/c.gcode", as stored: every segment passed through
// sanitize_filename (OctoPrint's sanitize_path), so that a stored path holds only [A-Za-z0-9._-]
// and '/'. "" and "/" are the root (allowed only when `root_ok`); one trailing '/' is a folder's
// spelling and dropped. ApiError 400, naming `field`, for an absolute path, "..", ".", an empty
// segment, a backslash, a control character, or one past the bounds above. Checked *before*
// sanitizing, so that "../x" is refused rather than quietly turned into "_./x".
std::string checked_path(std::string_view raw, std::string_view field, bool root_ok);

std::string join_path(const std::string& folder, const std::string& name);  // "" folder: the root
std::string parent_path(const std::string& path);                           // "" at the top
std::string leaf_name(const std::string& path);
// Whether `path` is `folder` itself or lies anywhere under it ("" holds everything).
bool in_folder(const std::string& folder, const std::string& path);

// A Range header (RFC 9110 §14) against a body of `size` bytes. Only one range is honoured: a
// header with several, or one that does not parse, is ignored (the whole body, 200), as the RFC
// allows. A first byte past the end, or a zero-length suffix, cannot be satisfied (416); a last
// byte past the end, however large, is the end.
struct RangeAnswer {
  enum class Kind { whole, partial, unsatisfiable } kind = Kind::whole;
  std::size_t first = 0, last = 0;  // inclusive, for `partial`
};
RangeAnswer parse_range(std::string_view header, std::size_t size);

// The entries directly in `folder` ("" the root): its sub-folders first, then its files, each as
// `file_json`/`folder_json` make it. Folders also come from the files' paths (a file can only be
// stored inside a folder that exists, but a listing must not lose one whose row is missing). With
// `recursive`, each folder carries its own entries as "children"; each folder has the total
// "size" of the files under it.
nlohmann::json folder_entries(const std::vector<StoredFile>& files, const std::vector<std::string>& folders,
                              const std::string& folder, bool recursive,
                              const std::function<nlohmann::json(const StoredFile&)>& file_json,
                              const std::function<nlohmann::json(const std::string& path)>& folder_json);

}  // namespace salient::server
