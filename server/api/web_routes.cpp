// The web page: its own files (clients/web, compiled into salientd) at / and /web/{file}, and
// the JavaScript libraries it uses from Debian's packages (libjs-three, libjs-chart.js) at
// /vendor/{lib}/…, read at run time from web.vendor_dir. All open: the page asks for the key
// itself and sends it with each API call. Every answer carries a Content-Security-Policy that
// allows no other origin and no inline script, an ETag (304 on If-None-Match) and Cache-Control.
#include <sys/stat.h>

#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <mutex>
#include <sstream>
#include <string>
#include <vector>

#include "server/api/routes.hpp"
#include "server/api/web_assets.hpp"
#include "server/store/sha256.hpp"

namespace salient::server {
namespace {

namespace fs = std::filesystem;

// The libraries the page imports, as /vendor/{lib}/… names them: their Debian directories.
constexpr const char* kLibraries[] = {"three", "chart.js"};
constexpr const char* kPackages[] = {"libjs-three", "libjs-chart.js"};
constexpr std::uintmax_t kMaxVendorFile = 16u << 20;

std::string content_type(std::string_view name) {
  const std::size_t dot = name.rfind('.');
  const std::string_view ext = dot == std::string_view::npos ? "" : name.substr(dot + 1);
  if (ext == "html") return "text/html; charset=utf-8";
  if (ext == "js" || ext == "mjs") return "text/javascript; charset=utf-8";
  if (ext == "css") return "text/css; charset=utf-8";
  if (ext == "svg") return "image/svg+xml";
  if (ext == "png") return "image/png";
  if (ext == "json" || ext == "webmanifest") return "application/json";
  return "application/octet-stream";
}

// The Host header, if it is a plain host[:port] (it goes into a header we send back).
std::string safe_host(const HttpRequest& r) {
  const std::string host = r.header("host");
  if (host.empty() || host.size() > 255 ||
      host.find_first_not_of("abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789.-:[]") !=
          std::string::npos)
    return {};
  return host;
}

// Nothing from another origin; no inline script or style; the WebSocket back to this server
// ('self' covers ws: in CSP 3, the explicit source for browsers that predate it).
std::string content_security_policy(const HttpRequest& r) {
  std::string connect = "'self'";
  if (const std::string host = safe_host(r); !host.empty()) connect += " ws://" + host + " wss://" + host;
  return "default-src 'self'; script-src 'self'; style-src 'self'; img-src 'self' data: blob:; "
         "connect-src " +
         connect + "; object-src 'none'; base-uri 'none'; form-action 'none'; frame-ancestors 'none'";
}

// If-None-Match holds `etag` (a list, weak or strong, or "*").
bool not_modified(const HttpRequest& r, const std::string& etag) {
  std::stringstream list(r.header("if-none-match"));
  for (std::string tag; std::getline(list, tag, ',');) {
    tag.erase(0, tag.find_first_not_of(" \t"));
    tag.erase(tag.find_last_not_of(" \t") + 1);
    if (tag.rfind("W/", 0) == 0) tag.erase(0, 2);
    if (tag == etag || tag == "*") return true;
  }
  return false;
}

HttpResponse file_response(const HttpRequest& r, std::string_view name, std::string body,
                           const std::string& etag, const char* cache_control) {
  HttpResponse out;
  if (not_modified(r, etag)) {
    out.status = 304;
  } else {
    out.status = 200;
    out.body = std::move(body);
  }
  out.content_type = content_type(name);
  out.headers = {{"ETag", etag},
                 {"Cache-Control", cache_control},
                 {"Content-Security-Policy", content_security_policy(r)},
                 {"X-Content-Type-Options", "nosniff"},
                 {"Referrer-Policy", "no-referrer"}};
  return out;
}

// The compiled-in files with their ETags (a digest of the bytes), made once.
class PageFiles {
 public:
  PageFiles() {
    for (const WebAsset& a : web_assets()) {
      std::string tag(1, '"');
      tag.append(sha256_hex(a.bytes), 0, 24).push_back('"');
      etags_.push_back(std::move(tag));
    }
  }
  HttpResponse serve(const HttpRequest& r, const std::string& name) const {
    const auto assets = web_assets();
    for (std::size_t i = 0; i < assets.size(); ++i)
      if (assets[i].name == name)  // revalidated each time: an upgraded daemon serves its new page at once
        return file_response(r, name, std::string(assets[i].bytes), etags_[i], "no-cache");
    throw ApiError(404, "not_found", "the web page has no file '" + name.substr(0, 128) + "'");
  }

 private:
  std::vector<std::string> etags_;
};

// A path segment that names a file or directory in place: no "..", no "/", no hidden names.
bool plain_segment(const std::string& s) {
  return !s.empty() && s.size() <= 128 && s[0] != '.' &&
         s.find_first_not_of("abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789._-") ==
             std::string::npos;
}

// Debian's JavaScript libraries under `root`, read when first asked for and kept (until the file
// changes: its size and time are its ETag).
class VendorFiles {
 public:
  explicit VendorFiles(std::string root) : root_(std::move(root)) {}

  HttpResponse serve(const HttpRequest& r, const std::string& lib, const std::vector<std::string>& rest) {
    std::size_t which = std::size(kLibraries);
    for (std::size_t i = 0; i < std::size(kLibraries); ++i)
      if (lib == kLibraries[i]) which = i;
    if (which == std::size(kLibraries))
      throw ApiError(404, "not_found",
                     "no library '" + lib.substr(0, 64) + "' here: /vendor/ serves three and chart.js");
    fs::path path = fs::path(root_) / lib;
    for (const std::string& s : rest) {
      if (!plain_segment(s))
        throw ApiError(400, "bad_request", "'" + s.substr(0, 64) + "' is not a file name");
      path /= s;
    }
    const std::string name = rest.back();
    if (!name.ends_with(".js") && !name.ends_with(".mjs"))
      throw ApiError(404, "not_found", "/vendor/ serves JavaScript modules only");
    std::error_code ec;
    if (!fs::is_directory(fs::path(root_) / lib, ec))
      throw ApiError(404, "not_installed",
                     (fs::path(root_) / lib).string() + " is missing: install Debian's " + kPackages[which] +
                         " (deploy/install-deps.sh), or set web.vendor_dir in the config");
    // Symbolic links inside the package (three's build/ points at ../) are fine; out of it, not.
    const fs::path real = fs::weakly_canonical(path, ec);
    const fs::path base = fs::weakly_canonical(fs::path(root_) / lib, ec);
    const auto rel = real.lexically_relative(base);
    if (ec || rel.empty() || *rel.begin() == ".." || !fs::is_regular_file(real, ec))
      throw ApiError(404, "not_found", "no file /vendor/" + lib + "/" + relative_name(rest));
    return file_response(r, name, read(real), etag(real), "public, max-age=3600");
  }

 private:
  static std::string relative_name(const std::vector<std::string>& rest) {
    std::string out;
    for (const std::string& s : rest) out += (out.empty() ? "" : "/") + s;
    return out;
  }

  static std::string etag(const fs::path& path) {
    struct stat st {};
    if (::stat(path.c_str(), &st) != 0) return "\"0\"";
    std::ostringstream tag;
    tag << "\"" << std::hex << st.st_size << "-" << st.st_mtim.tv_sec << "-" << st.st_mtim.tv_nsec << "\"";
    return tag.str();
  }

  std::string read(const fs::path& path) {
    const std::string tag = etag(path);
    std::lock_guard lock(mutex_);
    auto& entry = cache_[path.string()];
    if (entry.first == tag) return *entry.second;
    std::error_code ec;
    if (fs::file_size(path, ec) > kMaxVendorFile)
      throw ApiError(404, "not_found", path.filename().string() + " is larger than a library should be");
    std::ifstream in(path, std::ios::binary);
    if (!in) throw ApiError(404, "not_found", "cannot read " + path.string());
    std::ostringstream bytes;
    bytes << in.rdbuf();
    entry = {tag, std::make_shared<const std::string>(bytes.str())};
    return *entry.second;
  }

  std::string root_;
  std::mutex mutex_;
  std::map<std::string, std::pair<std::string, std::shared_ptr<const std::string>>> cache_;
};

}  // namespace

void add_web_routes(Router& router, const DaemonConfig& config) {
  auto page = std::make_shared<const PageFiles>();
  auto vendor = std::make_shared<VendorFiles>(config.web_vendor_dir);
  router.add("GET", "/", Access::open,
             [page](const HttpRequest& r, const PathParams&) { return page->serve(r, "index.html"); });
  router.add("GET", "/web/{file}", Access::open,
             [page](const HttpRequest& r, const PathParams& p) { return page->serve(r, p.at("file")); });
  router.add("GET", "/vendor/{lib}/{file}", Access::open,
             [vendor](const HttpRequest& r, const PathParams& p) {
               return vendor->serve(r, p.at("lib"), {p.at("file")});
             });
  // chart.js's module imports its helpers from chunks/.
  router.add("GET", "/vendor/{lib}/{dir}/{file}", Access::open,
             [vendor](const HttpRequest& r, const PathParams& p) {
               return vendor->serve(r, p.at("lib"), {p.at("dir"), p.at("file")});
             });
}

}  // namespace salient::server
