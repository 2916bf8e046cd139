// POST /api/files/local/{path}: OctoPrint's file commands. `select` (with `print`: start it, or
// queue it on a busy printer), `move` and `copy` to a `destination` (an existing folder takes the
// item under its own name; 409 when the target exists or a move would take a file being printed),
// `analyse` (ours is made on demand), `slice` (not here: 415, as OctoPrint without a slicer).
#include <nlohmann/json.hpp>

#include "server/api/api_json.hpp"
#include "server/api/octoprint_files.hpp"
#include "server/api/octoprint_routes.hpp"
#include "server/common/json_text.hpp"
#include "server/store/print_store.hpp"

namespace salient::server {

using nlohmann::json;

namespace {

HttpResponse select_file(const OctoContext& ctx, const std::string& path, const json& body) {
  if (!PrintStore(ctx.store.db()).file(path)) throw ApiError(404, "not_found", "no file '" + path + "'");
  if (!is_gcode(path))
    throw ApiError(415, "unsupported_format", "cannot select " + path + " for printing: not a G-code file");
  const auto print_it = body.find("print");
  const bool print =
      print_it != body.end() &&
      (print_it->is_boolean() ? print_it->get<bool>()
                              : print_it->is_string() && print_it->get<std::string>() == "true");
  Printer& printer = default_printer(ctx.printers);
  if (!print && busy_printing(printer.state()))
    throw ApiError(409, "printer_busy", "the printer is printing: cannot select a new file");
  {
    std::lock_guard lock(ctx.octo.mutex);
    ctx.octo.selected = path;
  }
  if (!print) return HttpResponse::text(204, "");
  const json answer = octo_print_or_queue(ctx, path);
  if (answer.value("effectivePrint", false)) return HttpResponse::text(204, "");
  json out = answer;
  out["effectiveSelect"] = true;
  return json_response(202, out);  // queued: it prints when the printer is free and the bed clear
}

// Where `destination` puts `source`: into it when it is an existing folder (not the source).
std::string target_of(PrintStore& files, const std::string& source, const std::string& destination) {
  if (destination.empty() || (files.folder_exists(destination) && destination != source))
    return join_path(destination, leaf_name(source));
  return destination;
}

HttpResponse move_or_copy(const OctoContext& ctx, const HttpRequest& r, const std::string& source,
                          const std::string& command, const json& body) {
  const auto d = body.find("destination");
  if (d == body.end() || !d->is_string())
    throw ApiError(400, "bad_request", "'" + command + "' needs a 'destination' (a path)");
  const std::string destination = checked_path(d->get<std::string>(), "destination", true);
  const bool move = command == "move";
  if (move && octo_file_busy(ctx.printers, source))
    throw ApiError(409, "file_busy", "trying to move a file or folder in use: " + source);
  std::string target;
  bool is_file = false;
  {
    std::lock_guard lock(ctx.store.files_mutex());
    PrintStore files(ctx.store.db());
    is_file = files.file(source).has_value();
    if (!is_file && !files.folder_exists(source))
      throw ApiError(404, "not_found", "no file or folder '" + source + "'");
    target = target_of(files, source, destination);
    if (target.size() > kMaxPathBytes) throw ApiError(400, "bad_path", "the destination path is too long");
    if (!is_file && in_folder(source, target))
      throw ApiError(400, "bad_path", "cannot " + command + " the folder " + source + " into itself");
    if (target != source || !move) {
      if (files.file(target) || files.folder_exists(target))
        throw ApiError(409, "conflict", "'" + target + "' exists already");
      files.put_folder(parent_path(target), octo_now());
      if (move)
        is_file ? files.move_file(source, target) : files.move_folder(source, target);
      else
        is_file ? files.copy_file(source, target, octo_now()) : files.copy_folder(source, target, octo_now());
    }
  }
  if (move) {
    std::lock_guard lock(ctx.octo.mutex);
    if (in_folder(source, ctx.octo.selected)) ctx.octo.selected.clear();  // as OctoPrint: unselected
  }
  json event = {{"type", move ? "moved" : (is_file ? "added" : "folder_added")}, {"path", target}};
  if (move) event["from"] = source;
  ctx.hub.publish({"files"}, "files", json_text(event));
  ctx.octo.files_changed(is_file && !move ? target : std::string());
  const std::string base = base_url(r);
  json out = {{"name", leaf_name(target)},
              {"path", target},
              {"origin", "local"},
              {"refs", {{"resource", base + "/api/files/local/" + target}}}};
  if (is_file) out["refs"]["download"] = base + "/downloads/files/local/" + target;
  HttpResponse response = json_response(201, out);
  response.headers.emplace_back("Location", out["refs"]["resource"].get<std::string>());
  return response;
}

}  // namespace

HttpResponse octo_file_command(const OctoContext& ctx, const HttpRequest& r, const PathParams& p) {
  const std::string path = checked_path(p.at("path"), "path", false);
  const json body = parse_json_body(r, ctx.max_json, ctx.depth);
  const std::string command = string_field(body, "command", "");
  if (command == "select") return select_file(ctx, path, body);
  if (command == "move" || command == "copy") return move_or_copy(ctx, r, path, command, body);
  if (command == "analyse") {
    if (!PrintStore(ctx.store.db()).file(path)) throw ApiError(404, "not_found", "no file '" + path + "'");
    return HttpResponse::text(204, "");  // analysed when first asked for (file_json_analysed)
  }
  if (command == "slice")
    throw ApiError(415, "unsupported", "cannot slice " + path + " here: send models to /api/v1/jobs");
  throw ApiError(400, "bad_request", "'command' must be select, move, copy, analyse or slice");
}

}  // namespace salient::server
