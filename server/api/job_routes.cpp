#include <filesystem>
#include <nlohmann/json.hpp>

#include "core/common/input_error.hpp"
#include "server/api/api_json.hpp"
#include "server/api/routes.hpp"
#include "server/http/multipart.hpp"
#include "server/store/job_store.hpp"

namespace salient::server {
namespace {

using nlohmann::json;

Job job_or_404(Store& store, const std::string& id) {
  if (auto j = JobStore(store.db()).get(id)) return *j;
  throw ApiError(404, "not_found", "no job " + id);
}

int query_int(const HttpRequest& r, const char* key, int fallback, int min, int max) {
  const auto it = r.query.find(key);
  if (it == r.query.end()) return fallback;
  try {
    std::size_t used = 0;
    const int v = std::stoi(it->second, &used);
    if (used != it->second.size() || v < min || v > max) throw std::invalid_argument(key);
    return v;
  } catch (const std::exception&) {
    throw ApiError(400, "bad_request",
                   std::string(key) + " must be a whole number from " + std::to_string(min) + " to " +
                       std::to_string(max));
  }
}

// The artefact named in the job's result (gcode, plan), from the file store.
HttpResponse artefact(Store& store, const std::string& id, const char* key, const char* type,
                      const std::string& suffix) {
  const Job j = job_or_404(store, id);
  if (j.state != JobState::done || !j.result)
    throw ApiError(409, "not_ready",
                   "job " + id + " is " + std::string(to_string(j.state)) + ": nothing to download yet");
  const json r = json::parse(*j.result);
  if (!r.contains(key))  // a job finished by an older salientd, before this artefact existed
    throw ApiError(404, "not_found", "job " + id + " has no " + std::string(key) + ": submit it again");
  const std::string digest = r.at(key).get<std::string>();
  const std::filesystem::path path = store.files().path_of(digest);
  std::error_code size_error;
  const std::uintmax_t size = std::filesystem::file_size(path, size_error);
  if (size_error) throw StoreError("no stored file " + digest);  // as read() says it
  // Streamed from disk: a G-code file may be hundreds of MB, and a client may read it slowly.
  HttpResponse out = HttpResponse::from_file(200, {path, 0, size}, type);
  std::string stem = j.filename.substr(0, j.filename.find_last_of('.'));
  out.headers.emplace_back("Content-Disposition", "attachment; filename=\"" + stem + suffix + "\"");
  return out;
}

// Where a job goes once sliced (the `print` field): a printer id ("sim"), or JSON
// {"printer": ID} or {"profile": P} (any idle printer with that profile). 422 when nothing
// matches: checked before the job is made, so a typo costs no slicing.
struct PrintTarget {
  std::string printer, profile;
};

PrintTarget print_target(const std::string& text, PrinterService& printers) {
  PrintTarget t;
  if (!text.empty() && text.front() == '{') {
    const json j = json::parse(text, nullptr, false);
    if (!j.is_object() || j.size() != 1 || !(j.contains("printer") || j.contains("profile")) ||
        !j.begin()->is_string())
      throw ApiError(400, "bad_request",
                     "'print' must be a printer id, {\"printer\": ID} or {\"profile\": P}");
    (j.contains("printer") ? t.printer : t.profile) = j.begin()->get<std::string>();
  } else {
    t.printer = text;
  }
  const std::string shown = (t.printer.empty() ? t.profile : t.printer).substr(0, 64);
  if (t.printer.empty() ? printers.has_profile(t.profile) : printers.has_printer(t.printer)) return t;
  if (!t.printer.empty()) throw ApiError(422, "unknown_printer", "'print': no printer '" + shown + "'");
  throw ApiError(422, "unknown_profile", "'print': no printer has the profile '" + shown + "'");
}

// The job's print, requested with it: started, queued, or why not (the job stays).
json chain_print(PrinterService& printers, const PrintTarget& t, const Job& job) {
  try {
    const PrintSubmission s = t.printer.empty() ? printers.submit_to_profile(t.profile, "job", job.id, true)
                                                : printers.submit_job_to(t.printer, job.id, true);
    if (s.queued)
      return {{"queued", true},
              {t.printer.empty() ? "profile" : "printer", t.printer.empty() ? t.profile : t.printer},
              {"entry", s.queued->id},
              {"position", s.queued->position},
              {"slicing", s.queued->slicing}};
    return {{"queued", false}, {"printer", s.printer}, {"print", s.print}};
  } catch (const DomainError& e) {
    return {{"error", e.what()}};
  }
}

}  // namespace

void add_job_routes(Router& router, Store& store, JobService& jobs, PrinterService& printers,
                    const DaemonConfig& config) {
  router.add(
      "POST", "/api/v1/jobs", Access::key,
      [&jobs, &printers, &config](const HttpRequest& r, const PathParams&) {
        std::string filename, bytes, settings;
        std::optional<std::string> print;
        const std::string type = r.header("content-type");
        if (const auto boundary = multipart_boundary(type)) {
          std::vector<FormPart> parts;
          try {
            parts = parse_multipart(r.body, *boundary);
          } catch (const std::invalid_argument& e) {
            throw ApiError(400, "bad_request", e.what());
          }
          bool have_file = false;
          for (FormPart& p : parts) {
            if (p.name == "file")
              filename = p.filename.value_or("model"), bytes = std::move(p.body), have_file = true;
            if (p.name == "settings") settings = std::move(p.body);
            if (p.name == "print") print = std::move(p.body);
          }
          if (!have_file) throw ApiError(400, "bad_request", "the multipart body has no 'file' part");
        } else {
          const auto it = r.query.find("filename");
          if (it == r.query.end() || it->second.empty())
            throw ApiError(
                400, "bad_request",
                "send multipart/form-data with a 'file' part, or the model as the body with ?filename=NAME");
          filename = it->second;
          bytes = r.body;
          if (auto s = r.query.find("settings"); s != r.query.end()) settings = s->second;
          if (auto s = r.query.find("print"); s != r.query.end()) print = s->second;
        }
        if (settings.size() > config.max_json_bytes)
          throw ApiError(413, "too_large",
                         "settings exceed " + std::to_string(config.max_json_bytes) + " bytes");
        if (print && print->size() > 1024) throw ApiError(413, "too_large", "'print' exceeds 1024 bytes");
        const std::optional<PrintTarget> target =
            print ? std::optional<PrintTarget>(print_target(*print, printers)) : std::nullopt;
        const JobService::Submitted s = jobs.submit(filename, bytes, settings);
        json body = job_json(s.job);
        if (target) body["print"] = chain_print(printers, *target, s.job);
        HttpResponse out = json_response(s.reused ? 200 : 201, body);
        out.headers.emplace_back("Location", "/api/v1/jobs/" + s.job.id);
        return out;
      });
  router.add("GET", "/api/v1/jobs", Access::key, [&store](const HttpRequest& r, const PathParams&) {
    std::optional<JobState> state;
    if (auto it = r.query.find("state"); it != r.query.end()) {
      state = job_state_from(it->second);
      if (!state)
        throw ApiError(400, "bad_request", "state must be queued, running, done, failed or cancelled");
    }
    const int limit = query_int(r, "limit", 50, 1, 1000), offset = query_int(r, "offset", 0, 0, 1 << 30);
    JobStore js(store.db());
    json list = json::array();
    for (const Job& j : js.list(state, limit, offset)) list.push_back(job_json(j));
    return json_response(200,
                         {{"jobs", list}, {"total", js.count(state)}, {"limit", limit}, {"offset", offset}});
  });
  router.add("GET", "/api/v1/jobs/{id}", Access::key, [&store](const HttpRequest&, const PathParams& p) {
    return json_response(200, job_json(job_or_404(store, p.at("id"))));
  });
  // A job that has not finished is cancelled; a finished one is removed.
  router.add("DELETE", "/api/v1/jobs/{id}", Access::key,
             [&store, &jobs, &printers](const HttpRequest&, const PathParams& p) {
               const Job j = job_or_404(store, p.at("id"));
               if (!finished(j.state)) {
                 jobs.cancel(j.id);
                 return json_response(202, job_json(job_or_404(store, j.id)));
               }
               // Its model and artefacts go too, unless another job, a print or an upload still uses them.
               std::vector<std::string> digests = {j.model_digest};
               if (j.result) {
                 const json r = json::parse(*j.result, nullptr, false);
                 for (const char* key : {"gcode", "plan", "plot", "model", "saliency"})
                   if (r.is_object() && r.contains(key) && r.at(key).is_string())
                     digests.push_back(r.at(key).get<std::string>());
               }
               JobStore(store.db()).remove(j.id);
               // Queue entries waiting to print it go with it (as those of a failed job do), in
               // every queue: listed, they would be dropped only when their turn found it gone.
               printers.job_finished(j.id);
               store.remove_unreferenced(digests);
               return HttpResponse::text(204, "");
             });
  router.add("GET", "/api/v1/jobs/{id}/gcode", Access::key,
             [&store](const HttpRequest&, const PathParams& p) {
               return artefact(store, p.at("id"), "gcode", "text/x.gcode", ".gcode");
             });
  router.add("GET", "/api/v1/jobs/{id}/plan", Access::key, [&store](const HttpRequest&, const PathParams& p) {
    return artefact(store, p.at("id"), "plan", "application/json", ".plan.json");
  });
  router.add("GET", "/api/v1/jobs/{id}/plot.svg", Access::key,
             [&store](const HttpRequest&, const PathParams& p) {
               return artefact(store, p.at("id"), "plot", "image/svg+xml", ".plot.svg");
             });
  router.add("GET", "/api/v1/jobs/{id}/model.3mf", Access::key,
             [&store](const HttpRequest&, const PathParams& p) {
               return artefact(store, p.at("id"), "model", "model/3mf", ".3mf");
             });
  router.add("GET", "/api/v1/jobs/{id}/saliency.ply", Access::key,
             [&store](const HttpRequest&, const PathParams& p) {
               return artefact(store, p.at("id"), "saliency", "application/octet-stream", ".saliency.ply");
             });
}

}  // namespace salient::server
