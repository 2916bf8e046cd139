// OctoPrint's file area (files/local and downloads/files/local) as FDM Monster, OctoPod and the
// slicers use it: uploads into folders, folder creation, nested listings, select (and print or
// queue), move, copy, delete, and downloads with a Range. Paths are checked (octoprint_files.hpp)
// before anything is looked up; every change is published on the hub's "files" topic.
#include <filesystem>
#include <nlohmann/json.hpp>
#include <optional>

#include "server/api/api_json.hpp"
#include "server/api/octoprint_files.hpp"
#include "server/api/octoprint_routes.hpp"
#include "server/common/json_text.hpp"
#include "server/http/multipart.hpp"
#include "server/jobs/job_service.hpp"
#include "server/printers/print_file.hpp"
#include "server/store/print_store.hpp"

namespace salient::server {

using nlohmann::json;

namespace {

// {type: added|removed|moved|folder_added, path, …} on the "files" topic.
void publish_files(EventHub& hub, const std::string& type, json data) {
  data["type"] = type;
  hub.publish({"files"}, "files", json_text(data));
}

HttpResponse created(const json& body, const std::string& location) {
  HttpResponse out = json_response(201, body);
  out.headers.emplace_back("Location", location);
  return out;
}

struct Upload {
  std::vector<FormPart> parts;
  const FormPart* file = nullptr;  // in `parts` (a moved vector keeps its elements where they are)
  std::optional<std::string> foldername;
  std::string path;
  bool select = false, print = false;
};

Upload read_upload(const HttpRequest& r) {
  const auto boundary = multipart_boundary(r.header("content-type"));
  if (!boundary)
    throw ApiError(400, "bad_request", "send multipart/form-data with a 'file' part or a 'foldername'");
  Upload u;
  try {
    u.parts = parse_multipart(r.body, *boundary);
  } catch (const std::invalid_argument& e) {
    throw ApiError(400, "bad_request", e.what());
  }
  for (const FormPart& p : u.parts) {
    if (p.name == "file" && p.filename) u.file = &p;
    if (p.name == "foldername") u.foldername = p.body;
    if (p.name == "path") u.path = p.body;
    if (p.name == "select") u.select = p.body == "true";
    if (p.name == "print") u.print = p.body == "true";
  }
  return u;
}

// POST /api/files/local with `foldername` (and `path`): 201 {folder, done}; 409 when something
// of that name exists, or the name is a printable file's.
HttpResponse create_folder(const OctoContext& ctx, const Upload& u, const HttpRequest& r) {
  const std::string path =
      join_path(checked_path(u.path, "path", true), checked_path(*u.foldername, "foldername", false));
  if (is_gcode(path))
    throw ApiError(409, "conflict",
                   "cannot create a folder named " + leaf_name(path) + ": that is a file's name");
  std::lock_guard lock(ctx.store.files_mutex());
  PrintStore files(ctx.store.db());
  if (files.folder_exists(path) || files.file(path))
    throw ApiError(409, "conflict", "'" + path + "' exists already");
  files.put_folder(path, octo_now());
  ctx.octo.files_changed();  // the push socket's UpdatedFiles
  publish_files(ctx.hub, "folder_added", {{"path", path}, {"name", leaf_name(path)}});
  const json folder = folder_json(path, r);
  return created(
      {{"folder", {{"name", folder["name"]}, {"path", path}, {"origin", "local"}, {"refs", folder["refs"]}}},
       {"done", true}},
      folder["refs"]["resource"]);
}

// POST /api/files/local with a `file` (and `path`, `select`, `print`), as PrusaSlicer, Cura and
// FDM Monster send it: 201 + Location. With print on a busy printer the file is queued
// (effectivePrint false, queued {entry, position}); 409 for a file being printed.
HttpResponse upload_file(const OctoContext& ctx, const Upload& u, const HttpRequest& r) {
  const std::string folder = checked_path(u.path, "path", true);
  const std::string name = sanitize_filename(*u.file->filename);
  if (!is_gcode(name))
    throw ApiError(415, "unsupported_format",
                   name +
                       ": only G-code (.gcode, .gco, .g) can be uploaded here; send models to /api/v1/jobs "
                       "to slice them");
  const std::string path = checked_path(join_path(folder, name), "path", false);
  check_printable(name, u.file->body);  // 422 now, not a print that stalls later
  if (octo_file_busy(ctx.printers, path))
    throw ApiError(409, "file_busy", "trying to overwrite a file that is being printed: " + path);
  std::optional<std::string> replaced;
  {
    std::lock_guard files_lock(ctx.store.files_mutex());  // the file and its row land together
    PrintStore files(ctx.store.db());
    if (files.folder_exists(path)) throw ApiError(409, "conflict", "'" + path + "' is a folder");
    if (auto old = files.file(path)) replaced = old->digest;
    files.put_folder(folder, octo_now());
    const std::string digest = ctx.store.files().put(u.file->body);
    files.put_file(path, digest, static_cast<long long>(u.file->body.size()), octo_now());
  }
  if (replaced) ctx.store.remove_unreferenced({*replaced});  // an upload to the same path replaces it
  ctx.octo.files_changed(path);                              // the push socket's FileAdded
  publish_files(ctx.hub, "added", {{"path", path}, {"name", name}, {"size", u.file->body.size()}});
  if (u.select || u.print) {
    std::lock_guard lock(ctx.octo.mutex);
    ctx.octo.selected = path;
  }
  json print = {{"effectivePrint", false}};
  if (u.print) {
    try {
      print = octo_print_or_queue(ctx, path);
    } catch (const Conflict&) {  // a printer that is not connected: stored, not printed (as OctoPrint)
    }
  }
  const json f = file_json(*PrintStore(ctx.store.db()).file(path), r);
  json body = {{"files",
                {{"local",
                  {{"name", f["name"]},
                   {"display", f["display"]},
                   {"path", f["path"]},
                   {"origin", "local"},
                   {"refs", f["refs"]}}}}},
               {"done", true},
               {"effectiveSelect", u.select || u.print}};
  body.update(print);
  return created(body, f["refs"]["resource"]);
}

json listing(const OctoContext& ctx, const HttpRequest& r, const std::string& folder, bool recursive) {
  PrintStore store(ctx.store.db());
  return folder_entries(
      store.files(), store.folders(), folder, recursive,
      [&](const StoredFile& f) { return file_json_analysed(f, r, ctx.store, ctx.printers, ctx.octo); },
      [&](const std::string& p) { return folder_json(p, r); });
}

bool recursive_query(const HttpRequest& r) {
  const auto it = r.query.find("recursive");
  return it != r.query.end() && (it->second == "true" || it->second == "1" || it->second == "yes");
}

HttpResponse download(const OctoContext& ctx, const HttpRequest& r, const PathParams& p) {
  const std::string path = checked_path(p.at("path"), "path", false);
  const auto f = PrintStore(ctx.store.db()).file(path);
  if (!f) throw ApiError(404, "not_found", "no file '" + path + "'");
  const std::filesystem::path file = ctx.store.files().path_of(f->digest);
  std::error_code size_error;
  const std::uintmax_t size = std::filesystem::file_size(file, size_error);
  if (size_error) throw StoreError("no stored file " + f->digest);  // as read() says it
  const RangeAnswer range = parse_range(r.header("range"), size);
  HttpResponse out;
  // Streamed from disk, a chunk at a time as the client reads (HttpResponse::file).
  if (range.kind == RangeAnswer::Kind::unsatisfiable) {
    out = error_response(416, "range_not_satisfiable",
                         "the file has " + std::to_string(size) + " bytes: the Range asks for none of them");
    out.headers.emplace_back("Content-Range", "bytes */" + std::to_string(size));
  } else if (range.kind == RangeAnswer::Kind::partial) {
    out = HttpResponse::from_file(206, {file, range.first, range.last - range.first + 1}, "text/x.gcode");
    out.headers.emplace_back("Content-Range", "bytes " + std::to_string(range.first) + "-" +
                                                  std::to_string(range.last) + "/" + std::to_string(size));
  } else {
    out = HttpResponse::from_file(200, {file, 0, size}, "text/x.gcode");
  }
  out.headers.emplace_back("Accept-Ranges", "bytes");
  return out;
}

HttpResponse remove_path(const OctoContext& ctx, const PathParams& p) {
  const std::string path = checked_path(p.at("path"), "path", false);
  if (octo_file_busy(ctx.printers, path))
    throw ApiError(409, "file_busy",
                   "trying to delete a file that is being printed (or a folder holding it): " + path);
  std::vector<std::string> digests;
  std::string kind = "file";
  {
    std::lock_guard lock(ctx.store.files_mutex());
    PrintStore files(ctx.store.db());
    if (const auto f = files.file(path)) {
      files.remove_file(path);
      digests.push_back(f->digest);
    } else if (files.folder_exists(path)) {
      kind = "folder";
      for (const StoredFile& gone : files.remove_folder(path)) digests.push_back(gone.digest);
    } else {
      throw ApiError(404, "not_found", "no file or folder '" + path + "'");
    }
  }
  {
    std::lock_guard lock(ctx.octo.mutex);
    if (in_folder(path, ctx.octo.selected)) ctx.octo.selected.clear();
  }
  ctx.store.remove_unreferenced(digests);
  ctx.octo.files_changed();
  publish_files(ctx.hub, "removed", {{"path", path}, {"kind", kind}});
  return HttpResponse::text(204, "");
}

}  // namespace

HttpResponse octo_file_command(const OctoContext& ctx, const HttpRequest& r, const PathParams& p);

void add_octoprint_file_routes(Router& router, const OctoContext& ctx) {
  router.add("POST", "/api/files/local", Access::key, [ctx](const HttpRequest& r, const PathParams&) {
    const Upload u = read_upload(r);
    if (u.file) return upload_file(ctx, u, r);
    if (u.foldername) return create_folder(ctx, u, r);
    throw ApiError(400, "bad_request", "no file to upload ('file' part with a filename) and no 'foldername'");
  });
  const auto list_files = [ctx](const HttpRequest& r, const PathParams&) {
    // free and total: bytes on the file system the uploads are kept on (farm managers show them).
    const auto space = ctx.store.files().space();
    return json_response(200, {{"files", listing(ctx, r, "", recursive_query(r))},
                               {"free", space ? json(space->available) : json(nullptr)},
                               {"total", space ? json(space->capacity) : json(nullptr)}});
  };
  router.add("GET", "/api/files", Access::key, list_files);
  router.add("GET", "/api/files/local", Access::key, list_files);
  router.add("GET", "/api/files/local/{path*}", Access::key,
             [ctx](const HttpRequest& r, const PathParams& p) {
               const std::string path = checked_path(p.at("path"), "path", false);
               PrintStore files(ctx.store.db());
               if (const auto f = files.file(path))
                 return json_response(200, file_json_analysed(*f, r, ctx.store, ctx.printers, ctx.octo));
               if (!files.folder_exists(path))
                 throw ApiError(404, "not_found", "no file or folder '" + path + "'");
               json folder = folder_json(path, r);
               folder["children"] = listing(ctx, r, path, recursive_query(r));
               return json_response(200, folder);
             });
  router.add("POST", "/api/files/local/{path*}", Access::key,
             [ctx](const HttpRequest& r, const PathParams& p) { return octo_file_command(ctx, r, p); });
  router.add("DELETE", "/api/files/local/{path*}", Access::key,
             [ctx](const HttpRequest&, const PathParams& p) { return remove_path(ctx, p); });
  router.add("GET", "/downloads/files/local/{path*}", Access::key,
             [ctx](const HttpRequest& r, const PathParams& p) { return download(ctx, r, p); });
}

}  // namespace salient::server
